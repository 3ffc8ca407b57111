"""Recognition: the most likely person (and action) of a captured cycle, by a weighted
distance to every person's motion as a synthesis method models it
(:meth:`synthesis.model.MotionModel.recognize` calls these with its angle method).

A person's motion of an action is modelled from their *other* actions (their capture only
when they have no other), for every person alike — so the person whose cell was never
captured is not the only one compared through a model (:meth:`CellMethod.template`); the
additive prediction from each of the person's other actions alone is a template of theirs
too, and a trial's distance to the person is to the nearest (:meth:`CellMethod.templates`).
Each feature's difference is scaled by the inverse of its leave-one-person-out prediction spread
(:func:`recognition_weights`), moderated across the features as limma does
(:func:`moderated_variances`: a variance from few donors is not taken at face value), and
the distance is the **mean absolute** scaled difference (a Laplace rather than a Gaussian
likelihood, :func:`distances`): a prediction from other actions misses a few joints by far
more than the rest, and a squared distance lets those few decide. When every person was
captured doing the action, the templates are the captures themselves (a new take of a known
cell; :meth:`CellMethod.template`).

Scores and "unknown" are measured in the same weighted distance (:func:`match_scale`,
:func:`unknown_limit`): with capture templates, against half the spacing between people's
captures; with modelled templates, against the donors' held-out distances — the distance at
which a known person's capture lies from the model's view of them when it never saw it.

Chosen on the design split (docs/synthesis.md; bandai2 styles active / elderly / exhausted /
feminine): per-feature weights, top-1 92 % against 79 % for the plain distance to the
captures; the mean absolute distance, 100 % against 92 % (three takes) and 75 % against
58–67 % on walk + run + wave; a person's main effects rather than the interaction's
prediction as the template of a captured cell where they have one other action (the
prediction shrinks toward the action mean there; the 61 → 89 % it gave pairs of actions was
a hub, gone since the missing cell's template is modelled the same way: 71 % now);
moderated variances instead of a fixed shrinkage toward their mean (0.1 of it), walk + run +
wave 75 → 83 % (default) and 67 → 75 % (signature); the nearest of a person's templates
rather than the model's alone, walk + run + wave 75 → 92 % (signature; default unchanged);
each template against its own spread, its take 001 83 → 92 % (both methods); beside each
single-action view its posture (the offset averaged over the cycle), walk + run + wave
83 → 100 % and pairs of whole trials 51 → 63 % (default; docs/synthesis.md, tenth round).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.special import digamma, polygamma

from mocap.errors import MocapError
from synthesis.methods import CellMethod
from synthesis.signature import posterior_scores

@dataclass
class Recognition:
    """Result of :func:`recognize`.

    Attributes
    ----------
    person, action : str
        Most likely person and action.
    scores : dict of str to float
        Person → score in [0, 1] (summing to 1) for the recognised action, from the
        distance ``d`` (:func:`distances`, degrees) between the trial and the model's motion
        of that person: with templates modelled from other actions, ``(1 − ε) softmax(−d /
        τ) + ε / N`` fitted to the donors' own recognition problems (:func:`score_model`);
        with capture templates, a softmax of ``−½ (d / σ)²`` with ``σ`` the action's
        :func:`match_scale`.
    distances : dict of str to float
        Person → weighted mean absolute difference, degrees, for the recognised action.
    action_scores : dict of str to float
        Action → score (same softmax over each action's nearest person).
    """

    person: str
    action: str
    scores: dict
    distances: dict
    action_scores: dict

    def to_json(self) -> dict:
        """``{"person", "action", "scores", "distances_deg", "action_scores"}``."""
        return {"person": self.person, "action": self.action, "scores": self.scores,
                "distances_deg": self.distances, "action_scores": self.action_scores}


def moderated_variances(variance: np.ndarray, dof: int) -> np.ndarray:
    """Per-feature variances moderated toward a prior fitted to all the features: the
    empirical-Bayes estimate of limma (Smyth 2004, *Stat. Appl. Genet. Mol. Biol.* 3(1) 3).

    Each ``s_f²`` is taken as ``σ_f² χ²_d / d`` with ``σ_f²`` drawn from a scaled inverse
    χ² of ``d₀`` degrees of freedom and scale ``s₀²``; ``d₀`` and ``s₀²`` come from the mean
    and variance of ``log s_f²`` over the features (less the sampling spread ``ψ'(d/2)`` of a
    χ²_d's logarithm), and the posterior mean is

        s̃_f² = (d₀ s₀² + d s_f²) / (d₀ + d).

    So a variance from few donors is pulled toward the others by as much as its own
    sampling noise warrants: no constant is fitted. When the features' spread is no larger
    than sampling noise (``d₀ = ∞``) every feature gets ``s₀²``.

    Parameters
    ----------
    variance : ndarray, shape (features,)
        ``s_f²``, each a mean of ``dof`` squared held-out residuals.
    dof : int
        Degrees of freedom ``d`` (donors); below 1 the variances are returned as they are.

    Returns
    -------
    ndarray, shape (features,)

    Examples
    --------
    >>> import numpy as np
    >>> s2 = np.random.default_rng(0).chisquare(4, 5000) / 4      # one true variance, d = 4
    >>> bool(np.ptp(moderated_variances(s2, 4)) < 0.2 * np.ptp(s2))
    True
    """
    variance = np.asarray(variance, dtype=float)
    if dof < 1:
        return variance
    prior_dof, prior = variance_prior(variance, dof)
    if not np.isfinite(prior_dof):
        return np.full_like(variance, prior)
    return (prior_dof * prior + dof * variance) / (prior_dof + dof)


def variance_prior(variance: np.ndarray, dof: int) -> tuple[float, float]:
    """Degrees of freedom ``d₀`` and scale ``s₀²`` of the scaled inverse χ² that the
    features' variances are drawn from (limma's ``fitFDist``, method of moments on the
    logarithms; see :func:`moderated_variances`).

    Parameters
    ----------
    variance : ndarray, shape (features,)
        ``s_f²``; the features with (numerically) zero variance are left out.
    dof : int
        Degrees of freedom of each ``s_f²``, ≥ 1.

    Returns
    -------
    prior_dof : float
        ``d₀``; ``inf`` when the features spread no more than sampling noise would.
    prior : float
        ``s₀²``, units of ``variance``.
    """
    variance = np.asarray(variance, dtype=float)
    usable = variance > 1e-12 * variance.mean()        # an exactly predicted feature says
    if usable.sum() < 2:                               # nothing of the spread
        return float("inf"), float(variance.mean())
    half = dof / 2.0
    logs = np.log(variance[usable]) - digamma(half) + np.log(half)
    spread = logs.var(ddof=1) - float(polygamma(1, half))
    if not spread > 0:
        return float("inf"), float(np.exp(logs.mean()))
    prior_dof = 2.0 * _trigamma_inverse(spread)
    prior = np.exp(logs.mean() + digamma(prior_dof / 2.0) - np.log(prior_dof / 2.0))
    return float(prior_dof), float(prior)


def _trigamma_inverse(value: float) -> float:
    """``y`` with ``ψ'(y) = value`` (limma's Newton iteration from 1/2 + 1/x; its asymptotes
    ``ψ'(y) ≈ 1/y + 1/(2y²)`` at the extremes)."""
    if value > 1e7:
        return 1.0 / np.sqrt(value)
    if value < 1e-6:
        return 1.0 / value
    y = 0.5 + 1.0 / value
    for _ in range(50):
        trigamma = float(polygamma(1, y))
        step = trigamma * (1.0 - trigamma / value) / float(polygamma(2, y))
        y += step
        if -step / y < 1e-8:
            break
    return y


def recognition_weights(method: CellMethod, action: int) -> np.ndarray | None:
    """Per-feature weights of recognition distances for one action: the inverse of each
    feature's leave-one-person-out variance of the action's templates (their kind's own
    held-out errors, :meth:`CellMethod.template_variance`), moderated across the features
    by the number of donors it comes from (:func:`moderated_variances`); None when too few
    people give a variance.

    Returns
    -------
    ndarray, shape (features,), or None
    """
    found = method.template_variance(action)
    return None if found is None else _weights(*found)


def _weights(variance: np.ndarray, dof: int) -> np.ndarray | None:
    """``1 / s̃_f²`` of variances with ``dof`` degrees of freedom (None when all vanish)."""
    return 1.0 / moderated_variances(variance, dof) if variance.mean() > 0 else None


def distances(method: CellMethod, curve: np.ndarray,
              actions: Sequence[int] | None = None) -> np.ndarray:
    """Distance from a cycle to every person's motion of every action (module notes): to
    the nearest of the person's templates ``t`` (:meth:`CellMethod.templates`), each
    measured against its own per-feature held-out spread ``s_t`` (:func:`template_spreads`)
    as a Laplace log-likelihood, in degrees:

        d_t = ŝ [mean_f |x_f − t_f| / s_{t,f} + mean_f log(s_{t,f} / s_f)],

    ``s`` the spread of the method's template and ``ŝ = (mean_f s_f⁻²)^(−½)``. For the
    method's template this is the weighted mean absolute difference
    ``mean_f |x_f − t_f| √(w_f / mean w)`` with ``w = 1 / s²`` the
    :func:`recognition_weights`; a view predicted from a less telling action is
    measured against its wider spread and pays the log term for it. Unweighted when the
    weights are None.

    Parameters
    ----------
    method : CellMethod
        A fitted synthesis method of the angle cells.
    curve : ndarray, shape (samples, columns), degrees
        A cycle normalised like the corpus.
    actions : sequence of int, optional
        Action indices to compare with (default: all); the other columns are NaN.

    Returns
    -------
    ndarray, shape (people, actions), degrees
        NaN for people without a motion of that action.
    """
    flat = np.asarray(curve, dtype=float).ravel()
    people, count = method.data_.shape[:2]
    table = np.full((people, count), np.nan)
    for action in range(count) if actions is None else actions:
        spreads = template_spreads(method, action)
        for person in range(people):
            try:
                rows, sources = method.templates(person, action)
            except MocapError:
                continue
            table[person, action] = _nearest(rows, sources, flat, spreads)
    return table


def template_spreads(method: CellMethod, action: int) -> dict | None:
    """Per-feature held-out spread ``s̃`` (degrees) of each kind of template of an action:
    key None, the method's template (``1 / √w``, :func:`recognition_weights`); key ``a``,
    the additive prediction from action ``a`` alone (its donors' held-out errors,
    :meth:`CellMethod.view_errors`, moderated alike). None when too few people give a
    spread (distances are then unweighted).

    Returns
    -------
    dict of (int or None) to ndarray, shape (features,), or None
    """
    key = ("template_spreads", action)
    if key not in method.memo_:
        found = method.template_variance(action)
        views = method.view_errors(action)
        squares = {} if views is None else {a: e ** 2 for a, e in zip(*views)}
        method.memo_[key] = None if found is None else \
            _spreads(found[0], found[1], {a: (sq.mean(axis=0), sq.shape[0])
                                          for a, sq in squares.items()})
    return method.memo_[key]


def _spreads(variance: np.ndarray, dof: int, views: dict) -> dict | None:
    """:func:`template_spreads` from the method's variances and each view's
    ``(variances, dof)``; None when the method's variances all vanish."""
    if not variance.mean() > 0:
        return None
    spreads = {None: np.sqrt(moderated_variances(variance, dof))}
    for source, (view_variance, view_dof) in views.items():
        if view_variance.mean() > 0:
            spreads[source] = np.sqrt(moderated_variances(view_variance, view_dof))
    return spreads


def _nearest(rows: np.ndarray, sources: Sequence, flat: np.ndarray,
             spreads: dict | None) -> float:
    """:func:`distances`' measure from ``flat`` to the nearest of ``rows`` (templates whose
    kinds are ``sources``), degrees."""
    difference = np.abs(rows - flat)
    if spreads is None:
        return float(difference.mean(axis=1).min())
    own = spreads[None]
    unit = 1.0 / np.sqrt(np.mean(own ** -2.0))
    spread = np.stack([spreads.get(source, own) for source in sources])
    values = np.mean(difference / spread, axis=1) + np.mean(np.log(spread / own), axis=1)
    return float(unit * values.min())


def _feature_scale(method: CellMethod, action: int) -> np.ndarray | None:
    """``√(w_f / mean w)`` of an action's :func:`recognition_weights` (None: unweighted)."""
    return _scale(recognition_weights(method, action))


def _scale(weights: np.ndarray | None) -> np.ndarray | None:
    """``√(w_f / mean w)``: the factor of each feature's absolute difference."""
    return None if weights is None else np.sqrt(weights / weights.mean())


def _distance(motion: np.ndarray, flat: np.ndarray, scale: np.ndarray | None) -> float:
    """Weighted mean absolute difference of two flattened motions, degrees."""
    difference = np.abs(motion - flat)
    return float((difference if scale is None else difference * scale).mean())


def donor_distances(method: CellMethod, action: int) -> np.ndarray:
    """The donors' own recognition problems: the distance (the measure of
    :func:`distances`) from each donor's capture of an action to every donor's held-out
    templates of it (:meth:`CellMethod.held_out_templates` and the donor's
    :meth:`CellMethod.additive_views`: modelled as recognition models a person, by a model
    that never saw that donor's capture), with the spreads of the *other* donors' errors
    alone (:meth:`CellMethod.template_errors`, :meth:`CellMethod.view_errors`) — the
    spreads are fitted to these very errors, and a donor's own error measured by them would
    look nearer than a stranger's.

    Returns
    -------
    ndarray, shape (donors, donors), degrees
        Row k: donor k's capture against every donor's templates; the diagonal is
        :func:`held_out_distances`. Empty (0, 0) when too few people.
    """
    key = ("donor_distances", action)
    if key not in method.memo_:
        method.memo_[key] = _donor_distances(method, action)
    return method.memo_[key].copy()


def _donor_distances(method: CellMethod, action: int) -> np.ndarray:
    errors = method.template_errors(action)
    found = method.held_out_templates(action)
    if errors is None or found is None or errors.shape[0] < 3:
        return np.empty((0, 0))
    captures, templates = found
    candidates = [method.beside_views(template, q, action)
                  for q, template in zip(method.held_out_donors(action), templates)]
    found_views = method.view_errors(action)
    view_squares = {} if found_views is None else \
        {a: e ** 2 for a, e in zip(*found_views)}
    donors = captures.shape[0]
    squares = errors ** 2
    total = squares.sum(axis=0)
    view_totals = {a: sq.sum(axis=0) for a, sq in view_squares.items()}
    table = np.empty((donors, donors))
    for k in range(donors):
        others = {a: ((view_totals[a] - sq[k]) / (donors - 1), donors - 1)
                  for a, sq in view_squares.items()}
        spreads = _spreads((total - squares[k]) / (donors - 1), donors - 1, others)
        table[k] = [_nearest(rows, sources, captures[k], spreads)
                    for rows, sources in candidates]
    return table


def held_out_distances(method: CellMethod, action: int) -> np.ndarray:
    """Distance (the measure of :func:`distances`) between each donor's held-out prediction
    of an action and their capture: how far a person's capture lies from the model's view
    of them when the model never saw it (the diagonal of :func:`donor_distances`).

    Returns
    -------
    ndarray, shape (donors,), degrees; empty when too few people
    """
    return np.diagonal(donor_distances(method, action)).copy()


@dataclass
class ScoreModel:
    """How distances turn into scores for one action (:func:`score_model`).

    Scores are ``(1 − ε) softmax(−d / τ) + ε / N`` over the N people: a Laplace likelihood
    of the mean absolute distance (the distance's own measure), with the chance ε that the
    distances carry nothing (the nearest is anyone).

    Attributes
    ----------
    temperature : float
        τ, degrees: the maximum-likelihood fit to the donors' own recognition problems
        (:func:`donor_distances`). 0 when every donor problem is solved whatever τ (the
        softmax is then the nearest person alone).
    miss_chance : float
        ε = (misses + 1) / (problems + 2): Laplace's rule of succession for the chance that
        the nearest template is not the right person, from the donors' problems.
    """

    temperature: float
    miss_chance: float

    def scores(self, distances: np.ndarray) -> np.ndarray:
        """Scores summing to 1 (shape as ``distances``, 1-D)."""
        distances = np.asarray(distances, dtype=float)
        if self.temperature > 0:
            logits = -(distances - distances.min()) / self.temperature
            softmax = np.exp(logits)
        else:
            softmax = (distances == distances.min()).astype(float)
        softmax /= softmax.sum()
        return (1.0 - self.miss_chance) * softmax + self.miss_chance / distances.size


def score_model(method: CellMethod, action: int) -> ScoreModel | None:
    """Temperature and miss chance of the scores of an action whose templates are modelled
    from other actions, fitted to the donors' own recognition problems
    (:func:`donor_distances`, :func:`fit_score_model`). None when too few people."""
    return fit_score_model(donor_distances(method, action))


def fit_score_model(table: np.ndarray) -> ScoreModel | None:
    """:class:`ScoreModel` of recognition problems whose right answers are known.

    τ maximises the mean log score of the right candidate, ``log softmax(−d_k / τ)_k``;
    that log-likelihood is concave in 1/τ, and when every problem is solved with a margin
    it grows without bound as τ → 0 (τ = 0 is returned: the nearest alone, tempered by ε).

    Parameters
    ----------
    table : ndarray, shape (problems, problems)
        Row k: problem k's distance to every candidate, degrees; candidate k is the right
        one.

    Returns
    -------
    ScoreModel, or None with fewer than 3 problems (or a distance that is not finite)

    Examples
    --------
    >>> import numpy as np
    >>> fit_score_model(np.array([[1.0, 5.0, 5.0], [5.0, 1.0, 5.0], [5.0, 5.0, 1.0]]))
    ScoreModel(temperature=0.0, miss_chance=0.2)
    """
    table = np.asarray(table, dtype=float)
    problems = table.shape[0]
    if problems < 3 or not np.isfinite(table).all():
        return None
    misses = int(np.sum(np.argmin(table, axis=1) != np.arange(problems)))
    miss_chance = (misses + 1) / (problems + 2)
    right = np.diagonal(table)
    # Distance of the right donor above the nearest wrong one: all negative is separable.
    others = np.where(np.eye(problems, dtype=bool), np.inf, table)
    if np.all(right < others.min(axis=1)):
        return ScoreModel(0.0, miss_chance)
    differences = table - right[:, None]                    # ≥ 0 where the right is nearer

    def loss(inverse: float) -> float:                      # −mean log softmax of the right
        logits = -inverse * differences
        top = logits.max(axis=1, keepdims=True)
        return float(np.mean(top[:, 0] + np.log(np.exp(logits - top).sum(axis=1))))

    spread = float(np.median(np.abs(differences[~np.eye(problems, dtype=bool)])))
    if not spread > 0:
        return ScoreModel(0.0, miss_chance)
    # With a miss the loss grows linearly in 1/τ for large 1/τ, so the optimum is finite;
    # it is searched over e^±10 times the typical distance difference.
    found = minimize_scalar(lambda t: loss(np.exp(t) / spread), bounds=(-10.0, 10.0),
                            method="bounded", options={"xatol": 1e-4})
    return ScoreModel(float(spread / np.exp(found.x)), miss_chance)


def capture_spacing(method: CellMethod, action: int) -> np.ndarray:
    """Distance from each person's capture of an action to the nearest other person's
    (shape (people,), degrees; NaN without a capture or with no other)."""
    scale = _feature_scale(method, action)
    captured = np.flatnonzero(method.observed_[:, action])
    result = np.full(method.data_.shape[0], np.nan)
    for person in captured:
        others = [_distance(method.data_[other, action], method.data_[person, action], scale)
                  for other in captured if other != person]
        if others:
            result[person] = min(others)
    return result


def match_scale(method: CellMethod, action: int) -> float:
    """Typical distance (degrees, the measure of :func:`distances`) between a trial of an
    action and the right person's template of it: the scale of the recognition scores.

    With every person's capture as the template (:meth:`CellMethod.template`), half the
    median distance from a person's capture to the nearest other person's
    (:func:`capture_spacing`: a right match lies within half-way to the next person);
    otherwise the median of :func:`held_out_distances`. NaN when neither can be measured.
    """
    if method.observed_[:, action].all():
        spacing = capture_spacing(method, action)
        return 0.5 * float(np.nanmedian(spacing)) if np.isfinite(spacing).any() \
            else float("nan")
    held_out = held_out_distances(method, action)
    return float(np.median(held_out)) if held_out.size else float("nan")


def unknown_limit(method: CellMethod, action: int) -> float:
    """Distance (degrees) beyond which a trial of an action is nobody known.

    With capture templates, half the median distance between a person's capture and the
    nearest other person's (:func:`match_scale`: a trial nearer to a person than half-way to
    their neighbour is that person). With templates modelled from other actions, the
    largest of the donors' :func:`held_out_distances`: a known person's capture lies that
    far from the model's held-out view of them, and another, exchangeable with them, lies
    further than all with probability at most 1 / (donors + 1). NaN (no limit) when
    neither can be measured.
    """
    if method.observed_[:, action].all():
        return match_scale(method, action)
    held_out = held_out_distances(method, action)
    return float(np.max(held_out)) if held_out.size else float("nan")


def recognize(method: CellMethod, people: Sequence[str], actions: Sequence[str],
              curve: np.ndarray, candidates: Sequence[int]) -> Recognition:
    """Most likely person and action of a captured cycle.

    Parameters
    ----------
    method : CellMethod
        A fitted synthesis method of the angle cells.
    people, actions : sequence of str
        Names of the method's people and actions.
    curve : ndarray, shape (samples, columns), degrees
    candidates : sequence of int
        Actions the trial may be (one when it is known).

    Returns
    -------
    Recognition
        Person scores: with templates modelled from other actions, the donors' own
        recognition problems calibrate them (:func:`score_model`); with capture templates
        (or too few donors), a softmax of ``−½ (d / σ)²`` with σ the action's
        :func:`match_scale` (where it cannot be measured, the median of the action's
        distances). Action scores: the latter over each action's nearest person.
    """
    table = distances(method, curve, candidates)
    nearest = np.full(len(actions), np.inf)
    scales = np.full(len(actions), np.nan)
    for a in candidates:
        if np.isfinite(table[:, a]).any():
            nearest[a] = np.nanmin(table[:, a])
            scales[a] = match_scale(method, a)
            if not scales[a] > 0:
                scales[a] = float(np.nanmedian(table[:, a]))
    best_action = min(candidates, key=lambda a: nearest[a])
    column = table[:, best_action]
    valid = np.isfinite(column)
    names = [people[i] for i in np.flatnonzero(valid)]
    fitted = None if method.observed_[:, best_action].all() \
        else score_model(method, best_action)
    scores = fitted.scores(column[valid]) if fitted is not None \
        else posterior_scores(column[valid], scales[best_action])
    chosen = list(candidates)
    action_scores = posterior_scores(nearest[chosen] / np.where(scales[chosen] > 0,
                                                                scales[chosen], 1.0), 1.0)
    return Recognition(
        person=names[int(np.argmin(column[valid]))], action=actions[best_action],
        scores={name: float(s) for name, s in zip(names, scores)},
        distances={name: float(d) for name, d in zip(names, column[valid])},
        action_scores={actions[a]: float(s) for a, s in zip(candidates, action_scores)})
