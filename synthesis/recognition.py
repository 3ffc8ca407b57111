"""Recognition: the most likely person (and action) of a captured cycle, by a weighted
distance to every person's motion as a synthesis method models it
(:meth:`synthesis.model.MotionModel.recognize` calls these with its angle method).

A person's motion of an action is modelled from their *other* actions (their capture only
when they have no other), for every person alike — so the person whose cell was never
captured is not the only one compared through a model (:meth:`CellMethod.template`). Each
feature's difference is scaled by the inverse of its leave-one-person-out prediction spread
(:func:`recognition_weights`), moderated across the features as limma does
(:func:`moderated_variances`: a variance from few donors is not taken at face value), and
the distance is the **mean absolute** scaled difference (a Laplace rather than a Gaussian
likelihood, :func:`distances`): a prediction from other actions misses a few joints by far
more than the rest, and a squared distance lets those few decide.

Chosen on the design split (docs/synthesis.md; bandai2 styles active / elderly / exhausted /
feminine): per-feature weights, top-1 92 % against 79 % for the plain distance to the
captures; the mean absolute distance, 100 % against 92 % (three takes) and 75 % against
58–67 % on walk + run + wave; a person's main effects rather than the interaction's
prediction as the template of a captured cell where they have one other action (the
prediction shrinks toward the action mean there), pairs of actions 61 → 89 % on average;
moderated variances instead of a fixed shrinkage toward their mean (0.1 of it), walk + run +
wave 75 → 83 % (default) and 67 → 75 % (signature).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.special import digamma, polygamma

from mocap.errors import MocapError
from synthesis.methods import CellMethod
from synthesis.signature import posterior_scores

#: Mean absolute value of a normal error per unit of its RMS, √(2/π).
MEAN_ABSOLUTE_PER_RMS = float(np.sqrt(2.0 / np.pi))


@dataclass
class Recognition:
    """Result of :func:`recognize`.

    Attributes
    ----------
    person, action : str
        Most likely person and action.
    scores : dict of str to float
        Person → score in [0, 1] (summing to 1) for the recognised action: softmax of
        ``−½ (d / σ)²`` with ``d`` the distance (:func:`distances`, degrees) between the
        trial and the model's motion of that person, ``σ`` the mean absolute difference
        that the model's leave-one-out synthesis RMS gives for normal errors (× √(2/π)).
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
    feature's leave-one-person-out prediction variance, moderated across the features by
    the number of donors it comes from (:func:`moderated_variances`); None when too few
    people give a variance.

    Returns
    -------
    ndarray, shape (features,), or None
    """
    found = method.feature_variance(action)
    if found is None:
        return None
    variance, donors = found
    if not variance.mean() > 0:
        return None
    return 1.0 / moderated_variances(variance, donors)


def distances(method: CellMethod, curve: np.ndarray,
              actions: Sequence[int] | None = None) -> np.ndarray:
    """Weighted mean absolute difference between a cycle and every person's motion of every
    action (module notes): ``mean_f |x_f − t_f| √(w_f / mean w)``, with ``w`` the
    :func:`recognition_weights` (unweighted when they are None).

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
        weights = recognition_weights(method, action)
        for person in range(people):
            try:
                motion = method.template(person, action)
            except MocapError:
                continue
            difference = np.abs(motion - flat)
            if weights is not None:
                difference = difference * np.sqrt(weights / weights.mean())
            table[person, action] = difference.mean()
    return table


def recognize(method: CellMethod, people: Sequence[str], actions: Sequence[str],
              curve: np.ndarray, candidates: Sequence[int], scale: float) -> Recognition:
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
    scale : float
        Typical synthesis error (RMS), degrees, for the scores (:func:`posterior_scores`,
        which get the mean absolute difference it gives for normal errors, × √(2/π)).

    Returns
    -------
    Recognition
    """
    table = distances(method, curve, candidates)
    nearest = np.full(len(actions), np.inf)
    for a in candidates:
        if np.isfinite(table[:, a]).any():
            nearest[a] = np.nanmin(table[:, a])
    best_action = min(candidates, key=lambda a: nearest[a])
    column = table[:, best_action]
    valid = np.isfinite(column)
    names = [people[i] for i in np.flatnonzero(valid)]
    # The distances are mean absolute differences: compare them with the mean absolute
    # difference of normal errors of RMS ``scale``.
    scale = scale * MEAN_ABSOLUTE_PER_RMS
    scores = posterior_scores(column[valid], scale)
    action_scores = posterior_scores(nearest[list(candidates)], scale)
    return Recognition(
        person=names[int(np.argmin(column[valid]))], action=actions[best_action],
        scores={name: float(s) for name, s in zip(names, scores)},
        distances={name: float(d) for name, d in zip(names, column[valid])},
        action_scores={actions[a]: float(s) for a, s in zip(candidates, action_scores)})
