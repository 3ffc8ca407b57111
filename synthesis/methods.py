"""The synthesis methods of a person's cells, behind one interface, and their registry.

A *method* predicts the cells of a people × actions × features corpus from each person's
other cells. :class:`synthesis.model.MotionModel` holds one for the joint angles and one for
the cycle timing and asks only this interface (:class:`CellMethod`); ``mocap decompose |
evaluate --method NAME`` picks one from :data:`METHODS`:

``interaction`` (default, also ``auto``)
    The additive model (action mean + the person's offset) corrected by the N-mode SVD of the
    person × action interaction or by a ridge map across actions, mode (action basis, people
    signature or map), rank and ridge chosen by leave-one-donor-out inside the training
    people; rank 0 is the additive model (:class:`synthesis.interaction.InteractionModel`,
    ``mode="both"``).
``signature``
    The N-mode SVD model alone: the interaction's people mode (the person's signature) or its
    action mode (their person basis), without the ridge map, shrunk toward the additive
    prediction (``mode="nmode"``).
``transfer``
    The older action transfer (:class:`synthesis.transfer.TransferModel`).

Every method takes arrays (never files); the fitted data are the method's whole state, so a
saved model stores the data and refits the method on loading.
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np

from mocap.errors import MocapError
from synthesis.interaction import MAJORITY, MARGIN, MIN_DONORS, InteractionModel
from synthesis.regression import SignatureModel
from synthesis.transfer import TransferModel


#: Held-out cells of an action needed before the signature model may fill its cells where
#: the interaction has too few donors: two, the fewest for which "better on most of them"
#: means more than one cell (a definition, not a fitted constant; docs/synthesis.md,
#: "Missing cells").
VOUCHING_CELLS = 2
#: What each mode of a chosen configuration is (:func:`configuration_name`).
MODE_NAMES = {"people": "people mode (the signature)",
              "actions": "action mode (the person basis)",
              "regression": "the ridge map across actions"}


def configuration_name(mode: str, rank: int) -> str:
    """How ``decompose`` and ``filled_by`` name a chosen configuration other than the additive
    model: its mode (:data:`MODE_NAMES`) and, but for the ridge map, its rank.

    Examples
    --------
    >>> configuration_name("people", 4)
    'people mode (the signature), rank 4'
    >>> configuration_name("regression", 2)
    'the ridge map across actions'
    """
    return MODE_NAMES[mode] if mode == "regression" else f"{MODE_NAMES[mode]}, rank {rank}"


class CellMethod:
    """Interface of a synthesis method (subclasses fill in the hooks below).

    Attributes
    ----------
    name : str
        Registry name (:data:`METHODS`).
    data_ : ndarray, shape (people, actions, features)
        The fitted cells, NaN where missing.
    observed_ : ndarray, shape (people, actions), bool
    memo_ : dict
        Quantities derived from the fit, kept until the next fit (the donors' recognition
        problems of each action, :func:`synthesis.recognition.donor_distances`).
    """

    name: ClassVar[str] = ""

    def __init__(self) -> None:
        self.data_: np.ndarray | None = None
        self.observed_: np.ndarray | None = None
        self.samples_: int | None = None
        self.signatures_: SignatureModel | None = None
        self.memo_: dict = {}

    def fit(self, data: np.ndarray, signatures: SignatureModel | None = None,
            samples: int | None = None) -> "CellMethod":
        """Fit to the cells.

        Parameters
        ----------
        data : ndarray, shape (people, actions, features)
            NaN where a cell is missing.
        signatures : SignatureModel, optional
            The motion model's signature fit of the same data; a method may fall back on it
            where its own predictor has too few people.
        samples : int, optional
            Samples per cell where each cell is a curve flattened frame-major (features =
            samples × columns): recognition then also compares a trial with the person's
            posture in each other action (:meth:`additive_views`).

        Returns
        -------
        self
        """
        data = np.asarray(data, dtype=float)
        if data.ndim != 3:
            raise MocapError("method data must be people × actions × features")
        if samples is not None and (samples < 2 or data.shape[2] % samples):
            raise MocapError(f"{data.shape[2]} features are not curves of {samples} samples")
        self.samples_ = samples
        self.data_, self.observed_ = data, np.isfinite(data).all(axis=2)
        self.signatures_ = signatures
        self.memo_ = {}
        self._fit(data)
        return self

    # ------------------------------------------------------------------ the interface

    def cell(self, person: int, action: int) -> np.ndarray:
        """A captured cell as it is, a missing one predicted from the person's other cells.

        Returns
        -------
        ndarray, shape (features,)
        """
        if self.observed_[person, action]:
            return self.data_[person, action]
        return self._missing(person, action)

    def template(self, person: int, action: int) -> np.ndarray:
        """The person's motion of an action as recognition compares it with a trial.

        When every person's cell of the action is captured, the captures themselves: a new
        take of a known cell is compared with what was captured (bandai2, model of takes
        002 and 003, its take 001 trials: 28 of 28 named against 14 of 28 through
        predictions). When someone's cell is missing (the held-out cell of a leave-one-out),
        everyone alike through a model, so the person never captured is not the only one
        seen through a prediction: a captured cell modelled from the person's other cells
        (their capture when they have no other; see the methods' ``_held_out``), a missing
        one by the same kind of model (``_missing_template``: where the others are seen
        through their main effects, so is the missing person — a synthesis shrunk toward the
        action mean beside them drew 41–79 % of the other people's captures of pairs of
        bandai2 actions; docs/synthesis.md, tenth round).

        Returns
        -------
        ndarray, shape (features,)
        """
        if not self.observed_[person, action]:
            return self._missing_template(person, action)
        if self.observed_[:, action].all():
            return self.data_[person, action]
        if self.observed_[person].sum() > 1:
            return self._held_out(person, action)
        return self.data_[person, action]

    def templates(self, person: int, action: int) -> tuple[np.ndarray, list[int | None]]:
        """Every motion of the person recognition compares a trial of ``action`` with: the
        :meth:`template`, and where it is modelled from the person's other actions, the
        additive prediction from each of those actions alone (:meth:`additive_views`); a
        trial's distance to the person is its distance to the nearest of them, each measured
        against its own held-out spread (:func:`synthesis.recognition.distances`).

        A person's style shows most in the action most like the trial's, and a template
        averaged over unlike actions (a wave's offset from walks and runs) lies nearer the
        action mean, so nearer everyone. With the model's template among them, a corpus the
        model predicts exactly is still recognised exactly. Chosen on the design split
        (docs/synthesis.md, ninth round).

        Returns
        -------
        templates : ndarray, shape (templates, features)
        sources : list
            None for the :meth:`template`, then the action each view is predicted from
            (``("posture", a)`` for a posture view, :meth:`additive_views`).
        """
        template = self.template(person, action)[None]
        modelled = not self.observed_[:, action].all() and \
            (not self.observed_[person, action] or self.observed_[person].sum() > 1)
        if not modelled:
            return template, [None]
        return self.beside_views(template[0], person, action)

    def beside_views(self, template: np.ndarray, person: int, action: int
                     ) -> tuple[np.ndarray, list[int | None]]:
        """``template`` (features,) and, after it, the person's :meth:`additive_views` of
        ``action`` that differ from it (a view that is the template itself — the main
        effects of a person with one other action — is not a second template), with the
        sources of :meth:`templates`."""
        views, sources = self.additive_views(person, action)
        distinct = ~np.all(views == template, axis=1)
        return np.concatenate([template[None], views[distinct]]), \
            [None] + [a for a, kept in zip(sources, distinct) if kept]

    def additive_views(self, person: int, action: int) -> tuple[np.ndarray, list]:
        """The additive prediction of cell (person, action) from each of the person's other
        actions alone, ``m_b + d_{p,a} − m_a`` (means over the other people; an action
        nobody else has gives none), and those actions; where the cells are curves
        (``samples``), then each one's **posture view** ``m_b + mean_t (d_{p,a} − m_a)``:
        the person's offset in that action averaged over the cycle, the part of a style
        that carries from one action to an unlike one (a stoop shows in a walk and in a
        wave alike; the time course of a walk says nothing about a wave's). Chosen on the
        design split (docs/synthesis.md, tenth round).

        Returns
        -------
        views : ndarray, shape (views, features)
        sources : list
            The action each view is predicted from; ``("posture", a)`` for a posture view.
        """
        means, sources, offsets = self._additive_model.offsets(person, action)
        views = means[action] + offsets
        keep = np.isfinite(views).all(axis=1)
        views, offsets = views[keep], offsets[keep]
        sources = [a for a, kept in zip(sources, keep) if kept]
        if self.samples_ is None or not len(sources):
            return views, sources
        curves = offsets.reshape(len(sources), self.samples_, -1)
        postures = means[action] + np.broadcast_to(curves.mean(axis=1, keepdims=True),
                                                   curves.shape).reshape(len(sources), -1)
        return np.concatenate([views, postures]), \
            sources + [("posture", a) for a in sources]

    def view_errors(self, action: int) -> tuple[list, np.ndarray] | None:
        """Held-out errors of the single-action views of the donors of
        :meth:`held_out_errors` (view − capture; each view formed without the donor, so held
        out exactly): the actions they are predicted from and the errors, shape (those
        actions, donors, features); None when too few people. Computed once per fit
        (recognition's spreads and the donors' problems both ask)."""
        key = ("view_errors", action)
        if key not in self.memo_:
            self.memo_[key] = self._view_errors(action)
        return self.memo_[key]

    def _view_errors(self, action: int) -> tuple[list, np.ndarray] | None:
        if self.held_out_errors(action) is None:
            return None
        donors = self.held_out_donors(action)
        found = [self.additive_views(q, action) for q in donors]
        sources = found[0][1]
        if any(views_sources != sources for _, views_sources in found):
            return None
        views = np.stack([views for views, _ in found], axis=1)
        return sources, views - self.data_[donors, action][None]

    def additive(self, person: int, action: int) -> np.ndarray:
        """The additive prediction ``m_b + mean_a (d_{p,a} − m_a)`` of cell (person, action),
        means over the other people (shape (features,))."""
        return self._additive_model.additive(person, action)

    def feature_variance(self, action: int) -> tuple[np.ndarray, int] | None:
        """Leave-one-person-out mean squared error of each feature when ``action`` is
        predicted from all the others (shape (features,)), and the number of people it is
        averaged over (its degrees of freedom); None when too few people."""
        chosen = self._chosen(action)
        if not np.isfinite(chosen.variance).all():
            return None
        return chosen.variance, chosen.residuals.shape[0]

    def template_errors(self, action: int) -> np.ndarray | None:
        """Held-out errors of the templates :meth:`template` models a captured cell of
        ``action`` with (template − capture of each donor of :meth:`held_out_templates`, by a
        model that never saw that donor): :meth:`held_out_errors` where the templates are
        the method's predictions, the main effects' own errors where they are the person's
        main effects — a template is measured against the spread of its own kind (docs/
        synthesis.md, tenth round). Shape (donors, features); None when too few people."""
        if not self._templates_are_main_effects(action):
            return self.held_out_errors(action)
        found = self.held_out_templates(action)
        return None if found is None else found[1] - found[0]

    def template_variance(self, action: int) -> tuple[np.ndarray, int] | None:
        """Mean squared :meth:`template_errors` of each feature (shape (features,)) and the
        number of donors it is averaged over (its degrees of freedom); None when too few
        people. :meth:`feature_variance` where the templates are the method's predictions."""
        if not self._templates_are_main_effects(action):
            return self.feature_variance(action)
        errors = self.template_errors(action)
        if errors is None:
            return None
        return (errors ** 2).mean(axis=0), errors.shape[0]

    def held_out_errors(self, action: int) -> np.ndarray | None:
        """The leave-one-person-out errors behind :meth:`feature_variance`: each donor's
        held-out prediction of ``action`` minus their capture, shape (donors, features);
        None when too few people."""
        chosen = self._chosen(action)
        if chosen.residuals is None or not np.isfinite(chosen.variance).all():
            return None
        return self._prediction_errors(chosen)

    def held_out_templates(self, action: int) -> tuple[np.ndarray, np.ndarray] | None:
        """The donors of :meth:`held_out_errors`: their captures of ``action`` and their
        templates of it as :meth:`template` would model them from their other actions, by a
        model that never saw that donor; both shape (donors, features); None when too few
        people."""
        errors = self.held_out_errors(action)
        if errors is None:
            return None
        donors = self.held_out_donors(action)
        captures = self.data_[donors, action]
        if self._templates_are_main_effects(action):
            # Held out exactly: the means without the donor, the offset from their others.
            return captures, np.stack([self._additive_model.additive(q, action)
                                       for q in donors])
        return captures, captures + errors

    def held_out_donors(self, action: int) -> list[int]:
        """The people of :meth:`held_out_templates`, in its order."""
        return self._additive_model.donor_people(action, self._others(action))

    def _templates_are_main_effects(self, action: int) -> bool:
        """Whether :meth:`template` models a captured cell of ``action`` by the person's
        main effects (:meth:`additive`) rather than the method's prediction."""
        return False

    def describe(self) -> dict:
        """Action → what predicts it from all the other actions (empty when nothing to say)."""
        return {}

    def filled_by(self, person: int, action: int) -> str:
        """In words, what predicts a missing cell (the method's name by default)."""
        return self.name

    # ------------------------------------------------------------------ hooks

    _additive_model: TransferModel | InteractionModel

    def _fit(self, data: np.ndarray) -> None:
        raise NotImplementedError

    def _missing(self, person: int, action: int) -> np.ndarray:
        raise NotImplementedError

    def _held_out(self, person: int, action: int) -> np.ndarray:
        raise NotImplementedError

    def _missing_template(self, person: int, action: int) -> np.ndarray:
        """A missing cell as :meth:`template` shows it: modelled like the captured ones."""
        return self._missing(person, action)

    def _chosen(self, action: int):
        """What the method chose to predict ``action`` from all the other actions (an
        :class:`~synthesis.interaction.Interaction` or a
        :class:`~synthesis.transfer.Transfer`: its ``variance`` and ``residuals``)."""
        raise NotImplementedError

    def _prediction_errors(self, chosen) -> np.ndarray:
        """``chosen``'s held-out residuals as prediction − capture, (donors, features)."""
        raise NotImplementedError

    def _others(self, action: int) -> tuple[int, ...]:
        return tuple(a for a in range(self.data_.shape[1]) if a != action)


class InteractionMethod(CellMethod):
    """Additive model + N-mode SVD of the interaction, both modes
    (:class:`synthesis.interaction.InteractionModel`)."""

    name = "interaction"
    mode = "both"
    shrink = False

    def _fit(self, data: np.ndarray) -> None:
        self.model_ = InteractionModel(self.mode, shrink=self.shrink).fit(data)
        self._additive_model = self.model_

    def _missing(self, person: int, action: int) -> np.ndarray:
        prediction, chosen = self.model_.predict(person, action)
        if self._signatures_fill(person, action, chosen):
            return self.signatures_.predict(self.signatures_.signatures_[person], action)
        return prediction

    def _signatures_fill(self, person: int, action: int, chosen) -> bool:
        """Whether the signatures fill a missing cell: too few donors although the corpus
        has enough people (its missing cells stand in the way), and the signatures' own
        held-out cells of the action vouch for them; otherwise the additive prediction
        stands."""
        signatures = self.signatures_
        return signatures is not None \
            and (chosen is None or not np.isfinite(chosen.loo_rms)) \
            and self.data_.shape[0] > MIN_DONORS \
            and np.isfinite(signatures.signatures_[person]).all() \
            and self._signatures_beat_the_additive_model(action)

    def filled_by(self, person: int, action: int) -> str:
        _, chosen = self.model_.predict(person, action)
        if self._signatures_fill(person, action, chosen):
            return "the N-mode signatures (too few donors; their held-out cells vouch)"
        if chosen is None:
            return "the action's mean (the person has no other action)"
        if not np.isfinite(chosen.loo_rms):
            return "the additive model (too few donors)"
        if not chosen.rank:
            return "the additive model"
        return configuration_name(chosen.mode, chosen.rank)

    def _signatures_beat_the_additive_model(self, action: int) -> bool:
        """Whether the signature model passes, on its own held-out cells of ``action``, the
        rule a rank of the interaction must pass to be kept (:data:`MARGIN`,
        :data:`MAJORITY`): an RMS :data:`MARGIN` below the additive model's on the same
        cells (:attr:`SignatureModel.held_out_`: its leave-one-out, or with imputed cells
        the imputation's cross-validation), better on most of them, and at least
        :data:`VOUCHING_CELLS` of them. An action with fewer held-out cells is not vouched
        for."""
        own, additive, wins, cells = self.signatures_.held_out_[:, action]
        return bool(np.isfinite(own) and cells >= VOUCHING_CELLS
                    and own <= (1.0 - MARGIN) * additive and (not MAJORITY or wins > 0.5))

    def _held_out(self, person: int, action: int) -> np.ndarray:
        # With one other action the interaction's correction acts on the person's offset
        # itself (a shrink of it toward the action mean by the ridge map, or its projection on the
        # donors' offsets) and pulls people's templates together: their main effects there
        # (m_a + the offset). Pairs of bandai2 actions 61 → 71 % top-1 on average, 79 %
        # against the main effects' own spread (docs/synthesis.md, sixth and tenth rounds;
        # the 89 % the sixth round saw was a hub). With more, the configuration chosen for the
        # action from all the others (the one whose variances weight the distance).
        if self.observed_[person].sum() <= 2:
            return self.model_.additive(person, action)
        return self.model_.predict(person, action, self._chosen(action))[0]

    def _missing_template(self, person: int, action: int) -> np.ndarray:
        # As _held_out: a person with one other action is seen through their main effects.
        if self.observed_[person].sum() <= 1:
            return self.model_.additive(person, action)
        return self._missing(person, action)

    def _chosen(self, action: int):
        return self.model_.interaction(action, self._others(action))

    def _prediction_errors(self, chosen) -> np.ndarray:
        return chosen.residuals @ self.model_.basis_.T     # in the captured cells' basis

    def _templates_are_main_effects(self, action: int) -> bool:
        return self.data_.shape[1] <= 2          # a donor's one other action: see _held_out

    def describe(self) -> dict:
        result = {}
        for a in range(self.data_.shape[1]):
            chosen = self._chosen(a)
            if np.isfinite(chosen.loo_rms):
                result[a] = {"mode": chosen.mode, "rank": chosen.rank, "alpha": chosen.alpha,
                             "loo_rms": chosen.loo_rms,
                             "additive_loo_rms": chosen.additive_loo_rms}
                if chosen.mode == "regression":
                    others = self._others(a)
                    weights = self.model_.map_weights(a, others, chosen.alpha)
                    result[a]["map_weights"] = dict(zip(others, weights.tolist()))
        return result


class SignatureMethod(InteractionMethod):
    """The N-mode SVD signature model: the interaction's two modes — the person's signature
    (people mode, Vasilescu's action-specific bases ``B_a``) or their person basis (action
    mode, ``C_p``), whichever the donors' held-out cells choose, never the ridge map — its
    correction shrunk toward the additive prediction by the fraction its donors' held-out
    residuals favour (``InteractionModel("nmode", shrink=True)``). The people mode alone lost
    to the additive model on walk + run + wave (1.022 of its error on the design styles, 1.000
    on the report styles; with both modes 0.978 and 0.946: docs/synthesis.md, twelfth round).

    Recognition compares a trial with each person's main effects (the additive part of the
    model, ``m_a`` + the person's mean offset over their other actions), weighted by the
    signature model's per-feature prediction variance: the signature's correction is shared
    by the donors and pulls people's templates together (design styles of bandai2, top-1
    83 % → 88 % with three takes and with take 001; docs/synthesis.md).
    """

    name = "signature"
    mode = "nmode"
    shrink = True

    def _held_out(self, person: int, action: int) -> np.ndarray:
        return self.model_.additive(person, action)

    _missing_template = _held_out

    def _templates_are_main_effects(self, action: int) -> bool:
        return True


class TransferMethod(CellMethod):
    """Action transfer (:class:`synthesis.transfer.TransferModel`)."""

    name = "transfer"

    def _fit(self, data: np.ndarray) -> None:
        self.model_ = TransferModel().fit(data)
        self._additive_model = self.model_

    def _missing(self, person: int, action: int) -> np.ndarray:
        return self.model_.predict(person, action)[0]

    _held_out = _missing

    def _chosen(self, action: int):
        return self.model_.transfer(action, self._others(action))

    def _prediction_errors(self, chosen) -> np.ndarray:
        return -chosen.residuals                            # theirs: capture − prediction


#: Synthesis methods by name (``--method``).
METHODS: dict[str, type[CellMethod]] = {
    method.name: method for method in (InteractionMethod, SignatureMethod, TransferMethod)}
#: The method ``auto`` stands for.
DEFAULT_METHOD = "interaction"


def method_name(name: str) -> str:
    """The registered name of a method (``auto`` → :data:`DEFAULT_METHOD`); MocapError
    listing the methods for an unknown one."""
    if name == "auto":
        return DEFAULT_METHOD
    if name not in METHODS:
        raise MocapError(f"unknown synthesis method {name!r}: "
                         f"{', '.join(('auto',) + tuple(METHODS))}")
    return name


def make_method(name: str) -> CellMethod:
    """A new, unfitted method by name (``auto`` included)."""
    return METHODS[method_name(name)]()
