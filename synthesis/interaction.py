"""``InteractionModel``: the additive model plus the N-mode SVD of what it leaves.

Data: people × actions × features, NaN where a cell is missing. The **additive model** is the
main effects: a missing cell ``(p, b)`` is

    d̂_{p,b} = m_b + ᾱ_p,      ᾱ_p = mean_{a∈O} (d_{p,a} − m_a),

with ``m_a`` the mean of action ``a`` over the other people and ``O`` the person's other
observed actions. What it leaves, the person × action **interaction**, is decomposed with the
N-mode SVD and used to correct it. For a target action ``b`` the *donors* are the other people
who have ``b`` and all of ``O``; their offsets ``x_{q,a} = d_{q,a} − m_a`` (means without the
donor and the predicted person, so the donors' offsets are formed exactly as the predicted
person's) minus each donor's own mean offset over ``O ∪ {b}`` form the interaction tensor
``E`` (donors × actions × features). Two ways to use it, one per mode of ``E``:

* ``mode="actions"`` (the person basis, Vasilescu's ``C_p``): the action-mode matrix ``V``
  (leading ``r`` left singular vectors of ``E_(2)``, orthogonal to the all-ones vector) spans
  how a person's actions differ from one another. The person's offset and basis are fitted
  to their observed actions, per feature,

      min_{α, C} Σ_{a∈O} ‖x_{p,a} − α − C v_a‖² + λ ‖C‖²,     d̂_{p,b} = m_b + α + C v_b,

  which is a fixed weighting of the observed offsets, ``d̂ = m_b + Σ_a w_a x_{p,a}``.
* ``mode="people"`` (the signature): bases ``B_a = U_Pᵀ E_a`` from the leading ``r``
  people-mode singular vectors ``U_P``; the person's offset and signature ``s`` are fitted

      min_{α, s} Σ_{a∈O} ‖x_{p,a} − α − B_aᵀ s‖² + λ ‖s‖²,       d̂_{p,b} = m_b + α + B_bᵀ s.

In both, **rank 0 is the additive model exactly** (``α = ᾱ_p``), and the rank ``r`` and the
ridge ``λ`` are chosen by leave-one-donor-out *inside the training donors*: each donor is
predicted from a decomposition of the others, and the (rank, ridge) with the lowest total
squared error is kept, rank 0 included — so the model departs from the additive one only as
far as held-out donors reward it. ``mode="nmode"`` lets the same leave-one-donor-out choose
between the two modes — the whole N-mode SVD: the person's signature or their person basis,
whichever the donors' held-out cells reward (the signature method; twelfth round of
docs/synthesis.md: walk + run + wave 1.022 → 0.978 of the additive error on the design
styles, 1.000 → 0.946 on the report styles). ``mode="both"`` chooses the mode as well, and
adds a third candidate, the **ridge map across actions**
``d̂_{p,b} = m_b + Σ_{a∈O} w_a x_{p,a}`` (one weight per observed action, shared by the
features, fitted to the donors' offsets and shrunk toward ``1/|O|``:
:func:`synthesis.candidates.regression_candidates`), which says how much of an offset carries
from one action to another — what a wave keeps of a walk's (eleventh round of
docs/synthesis.md: walk + run + wave 0.971 → 0.949 of the additive error on the design styles,
0.946 → 0.918 on the report styles). With one observed action it replaces the action mode,
which has no person basis to fit there.

Choosing the best of many configurations on a few donors is optimistic, so the choice is
itself held out (:data:`NESTED`): each donor is predicted with the configuration the
other donors alone would have chosen, and the additive model stays unless that nested error
is :data:`MARGIN` below the additive one. With ``shrink=True`` (the signature method) the
correction is moreover scaled by the fraction κ of it that the donors' nested held-out
residuals favour (:func:`shrinkage`), each donor scored with the κ of the others. The
leave-one-donor-out residuals of the chosen configuration also give each
feature's prediction variance (used to weight recognition distances).

With one observed action the correction acts on the person's offset itself (a shrink of it
by the ridge map, its projection on the donors' offsets in the people mode), and
nothing in the person's own cells can check it: it is applied only to a person inside the
donors' range (:data:`RANGE_GUARD`, :meth:`InteractionModel.outside_donors`); a person whose
offset reaches further outside the donors' span than any donor's reaches outside the others'
gets the additive prediction. The candidates' predictions themselves are in
:mod:`synthesis.candidates`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mocap.errors import MocapError
from synthesis.candidates import (ALPHAS, MAX_PEOPLE_RANK, action_weight_grid,  # noqa: F401
                                 action_weights, map_weights, people_candidates,
                                 regression_candidates)

#: Donors needed before the interaction is decomposed (fewer: the additive model); 3 rather
#: than 4 on the design split (four-style bandai2 corpora: 0.68 against 1.00 of the additive
#: error; docs/synthesis.md).
MIN_DONORS = 3
#: Relative leave-one-donor-out gain over the additive model a non-zero rank must show to be
#: chosen (taken on the design split: bandai2 styles active/elderly/exhausted/feminine; see
#: docs/synthesis.md).
MARGIN = 0.05
#: Also require the chosen configuration to beat the additive model on most donors.
MAJORITY = True
#: Validate the selection itself: a configuration other than the additive model is kept only
#: when each donor, predicted with the configuration the *other* donors would have chosen
#: (nested leave-one-donor-out), is on average :data:`MARGIN` better predicted than by the
#: additive model (design split: three-action bandai2 corpora walk/run/wave 1.068 -> 0.982 of
#: the additive error, the whole corpus 0.631 -> 0.635; docs/synthesis.md).
NESTED = True
#: Modes of the interaction tensor a model may use: one of them, both (``"nmode"``: the whole
#: N-mode SVD), or both and the ridge map across actions (``"both"``).
MODES = ("actions", "people", "nmode", "both")
#: With one observed action, keep the additive prediction for a person who lies outside the
#: donors' range (:meth:`InteractionModel.outside_donors`): a correction learnt on the donors
#: is an extrapolation there. The limit is the donors' own: no constant is fitted.
RANGE_GUARD = True


@dataclass
class Interaction:
    """The configuration chosen for one (target action, observed actions, person) triple.

    Attributes
    ----------
    mode : str
        ``"actions"``, ``"people"``, ``"regression"`` (the ridge map across actions) or
        ``"additive"`` (rank 0).
    rank : int
        Rank of the interaction kept (0 = additive model; the number of observed actions for
        the ridge map).
    alpha : float
        Relative ridge.
    loo_rms, additive_loo_rms : float
        Leave-one-donor-out RMS error (feature units) of the chosen configuration and of the
        additive model.
    variance : ndarray, shape (features,)
        Leave-one-donor-out mean squared error of each feature, chosen configuration.
    shrinkage : float
        Fraction κ ∈ [0, 1] of the interaction's correction kept: the prediction is the
        additive one plus κ × (configuration − additive) (1 unless the model shrinks).
    residuals : ndarray, shape (donors, r), optional
        The donors' held-out residuals that give ``variance`` (kept configuration; their
        count is its degrees of freedom), in the coordinates of
        :attr:`InteractionModel.basis_`.
    """

    mode: str
    rank: int
    alpha: float
    loo_rms: float
    additive_loo_rms: float
    variance: np.ndarray
    shrinkage: float = 1.0
    residuals: np.ndarray | None = field(default=None, repr=False)


@dataclass
class InteractionModel:
    """Additive main effects + N-mode SVD of the interaction residual (see module notes).

    Parameters
    ----------
    mode : {"actions", "people", "nmode", "both"}
        Mode of the interaction tensor used to correct the additive model: one, both
        (``"nmode"``), or both and the ridge map across actions (``"both"``).
    margin : float
        Relative leave-one-donor-out gain a configuration other than the additive model must
        show to be chosen (0: the lowest error wins).
    max_rank : int, optional
        0 forces the additive model (rank 0); None lets leave-one-donor-out choose.
    shrink : bool
        Shrink the chosen correction toward the additive prediction by the fraction κ that
        the donors' held-out residuals favour (:func:`shrinkage`), and keep it only when each
        donor, predicted with the κ of the *other* donors, is :attr:`margin` better predicted
        on average than by the additive model.

    Attributes
    ----------
    data_ : ndarray, shape (people, actions, features)
    observed_ : ndarray, shape (people, actions), bool
    basis_ : ndarray, shape (features, r)
        Orthonormal basis of the span of the captured cells (r ≤ their count): every
        prediction is a linear combination of cells and every error a Euclidean norm, so the
        interaction is decomposed in these coordinates (the feature mode reduced first, as
        the N-mode SVD does) and its predictions mapped back, at a cost independent of the
        feature count.
    coords_ : ndarray, shape (people, actions, r)
        The cells in that basis (NaN where missing).
    """

    mode: str = "actions"
    margin: float = MARGIN
    max_rank: int | None = None
    shrink: bool = False
    data_: np.ndarray | None = field(default=None, repr=False)
    observed_: np.ndarray | None = field(default=None, repr=False)
    basis_: np.ndarray | None = field(default=None, repr=False)
    coords_: np.ndarray | None = field(default=None, repr=False)
    _cache: dict = field(default_factory=dict, repr=False)

    def fit(self, data: np.ndarray) -> "InteractionModel":
        """Remember the data; ranks and ridges are chosen per (target, observed set) on demand."""
        if self.mode not in MODES:
            raise MocapError(f"unknown interaction mode {self.mode!r}: "
                             f"{', '.join(MODES)}")
        data = np.asarray(data, dtype=float)
        if data.ndim != 3:
            raise MocapError("interaction data must be people × actions × features")
        self.data_ = data
        self.observed_ = np.isfinite(data).all(axis=2)
        self.basis_ = span_basis(data[self.observed_])
        self.coords_ = data @ self.basis_
        self._cache = {}
        return self

    # ------------------------------------------------------------------ main effects

    def _means(self, *excluded: int | None, coords: bool = False) -> np.ndarray:
        """Action means over the people not in ``excluded`` who have each action (NaN for an
        action nobody else has), shape (actions, features)."""
        keep = self.observed_.copy()
        for person in excluded:
            if person is not None:
                keep[person] = False
        counts = keep.sum(axis=0)
        cells = self.coords_ if coords else self.data_
        total = np.where(keep[..., None], cells, 0.0).sum(axis=0)
        return total / np.where(counts > 0, counts, np.nan)[:, None]

    def _observed_actions(self, person: int, target: int, means: np.ndarray) -> tuple:
        return tuple(int(a) for a in np.flatnonzero(self.observed_[person])
                     if a != target and np.isfinite(means[a]).all())

    def additive(self, person: int, target: int) -> np.ndarray:
        """The additive prediction ``m_b + mean_a (d_{p,a} − m_a)`` (shape (features,))."""
        means, _, offsets = self.offsets(person, target)
        if not len(offsets):
            return means[target]
        return means[target] + np.mean(offsets, axis=0)

    def offsets(self, person: int, target: int) -> tuple[np.ndarray, list[int], np.ndarray]:
        """The means without the person (actions, features), the person's other actions,
        and their offsets from the means in those (other actions, features): the additive
        prediction's parts (recognition's single-action views,
        :meth:`CellMethod.additive_views`)."""
        means = self._means(person)
        observed = list(self._observed_actions(person, target, means))
        return means, observed, self.data_[person, observed] - means[observed]

    # ------------------------------------------------------------------ the interaction

    def _donors(self, target: int, observed: tuple, exclude: int | None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Cells of the donors (Q, m + 1, F; observed actions, then the target), and the sums
        (m + 1, F) and counts (m + 1,) of the means' pool (everyone but ``exclude``)."""
        order = list(observed) + [target]
        donors = self.donor_people(target, observed, exclude)
        keep = self.observed_[:, order].copy()
        if exclude is not None:
            keep[exclude] = False
        sums = np.where(keep[..., None], self.coords_[:, order], 0.0).sum(axis=0)
        return self.coords_[donors][:, order], sums, keep.sum(axis=0).astype(float)

    def donor_people(self, target: int, observed: tuple, exclude: int | None = None
                     ) -> list[int]:
        """Indices of the donors of ``target`` from ``observed``: the people other than
        ``exclude`` who have the target and every observed action, in the order of
        :attr:`Interaction.residuals`."""
        order = list(observed) + [target]
        return [q for q in range(self.data_.shape[0]) if q != exclude
                and self.observed_[q, order].all()]

    def _candidates(self, training: np.ndarray, x: np.ndarray, people_rank: int
                    ) -> tuple[list, np.ndarray]:
        """Every configuration's prediction of one person's target offset.

        Parameters
        ----------
        training : ndarray, shape (Q, m + 1, F)
            Offsets of the training donors (observed actions, then the target).
        x : ndarray, shape (m, F) or (n, m, F)
            Offsets of the predicted person's observed actions (or of n people predicted
            from the same training donors).
        people_rank : int
            Largest people rank tried.

        Returns
        -------
        labels : list of (mode, rank, alpha); the first is the additive model
        predictions : ndarray, shape (len(labels), F) or (n, len(labels), F)
        """
        single = x.ndim == 2
        x = x[None] if single else x
        n, m, features = x.shape
        labels = [("additive", 0, float("inf"))]
        blocks = [x.mean(axis=1)[:, None]]
        if self.max_rank == 0:
            return labels, blocks[0][0] if single else blocks[0]
        centred = training - training.mean(axis=1, keepdims=True)             # E (Q, m+1, F)
        # With one observed action the action mode has no person basis to fit (its only
        # weight, 1/3, is the pseudo-inverse's minimum norm, not the data's): modes "nmode"
        # and "both" leave it out there (in "both" the ridge map takes its place).
        if self.mode == "actions" or self.mode in ("nmode", "both") and m >= 2:
            _, vectors = np.linalg.eigh(np.einsum("qaf,qbf->ab", centred, centred))
            weights = action_weight_grid(vectors[:, ::-1][:, :m])              # (m, alphas, m)
            labels += [("actions", rank + 1, alpha) for rank in range(m) for alpha in ALPHAS]
            blocks.append((weights.reshape(-1, m) @ x))                       # (n, R·A, F)
        if self.mode == "both":
            regression_labels, predictions = regression_candidates(training, x)
            labels += regression_labels
            blocks.append(predictions)
        if self.mode in ("people", "nmode", "both"):
            # One observed action cannot tell an offset from a signature: there the people
            # mode decomposes the offsets themselves (Vasilescu's uncentred signature).
            people_labels, predictions = people_candidates(
                centred if m >= 2 else training, x, people_rank, free_offset=m >= 2)
            labels += people_labels
            blocks.append(predictions)
        predictions = np.concatenate(blocks, axis=1)
        return labels, predictions[0] if single else predictions

    def interaction(self, target: int, observed: tuple, exclude: int | None = None
                    ) -> Interaction:
        """Rank and ridge for predicting ``target`` from ``observed`` (``exclude``: the person
        predicted, never a donor), chosen by leave-one-donor-out: each donor ``k`` in turn is
        predicted from the others, whose offsets are then formed without ``k`` in the means."""
        key = (target, observed, exclude)
        if key in self._cache:
            return self._cache[key]
        cells, sums, counts = self._donors(target, observed, exclude)
        features = self.data_.shape[2]
        donors = cells.shape[0]
        if donors < MIN_DONORS or not observed:
            result = Interaction("additive", 0, float("inf"), float("nan"), float("nan"),
                                 np.full(features, np.nan))
            self._cache[key] = result
            return result
        labels, folds, residuals = self._folds(cells, sums, counts, len(observed), features)
        best = self._choose(folds)
        picks = np.full(donors, best)
        if NESTED and best and donors > MIN_DONORS:
            # The selection itself held out: each donor predicted with the configuration the
            # other donors would have chosen.
            picks = self._nested(cells, sums, counts, len(observed), features, labels)
            nested = folds[np.arange(donors), picks]
            if not self.shrink and nested.mean() > (1.0 - self.margin) * folds[:, 0].mean():
                best = 0
        kappa = 1.0
        if self.shrink and best:
            # Held-out residuals of the additive model and of the (nested) choice, per donor.
            additive = np.stack([r[0] for r in residuals])                       # (Q, r)
            chosen = np.stack([r[i] for r, i in zip(residuals, picks)])
            kappa, held_out = shrinkage(additive, chosen - additive)
            if held_out.mean() / features > (1.0 - self.margin) * folds[:, 0].mean() \
                    or kappa == 0:
                best, kappa = 0, 1.0
        errors = folds.mean(axis=0)
        mode, rank, alpha = labels[best]
        kept = [r[0] + kappa * (r[best] - r[0]) for r in residuals]
        variance = np.mean([(self.basis_ @ residual) ** 2 for residual in kept], axis=0)
        loo = np.mean([residual @ residual for residual in kept]) / features
        result = Interaction(mode, rank, alpha, float(np.sqrt(loo)),
                             float(np.sqrt(errors[0])), variance, kappa,
                             residuals=np.stack(kept))
        self._cache[key] = result
        return result

    def _folds(self, cells: np.ndarray, sums: np.ndarray, counts: np.ndarray, m: int,
               features: int) -> tuple[list, np.ndarray, list]:
        """Leave-one-donor-out of every configuration: labels, mean squared errors over the
        ``features`` (Q, C) and residuals (Q of (C, r), in :attr:`basis_` coordinates)."""
        donors = cells.shape[0]
        offsets = pool_offsets(cells, sums, counts)                             # as the person's
        counts = counts[:, None]
        labels, residuals, folds = None, [], []
        for k in range(donors):
            others = np.arange(donors) != k
            offset = offsets[k]
            training = cells[others] - (sums - cells[k] - cells[others]) / (counts - 2)
            fold_labels, predictions = self._candidates(training, offset[:m], donors - 2)
            labels = labels or fold_labels
            residual = predictions - offset[m]                                   # (C, F)
            residuals.append(residual)
            folds.append(np.einsum("cf,cf->c", residual, residual) / features)
        return labels, np.asarray(folds), residuals

    def _nested(self, cells: np.ndarray, sums: np.ndarray, counts: np.ndarray, m: int,
                features: int, labels: list) -> np.ndarray:
        """Index in ``labels`` of the configuration the other donors would choose, per donor
        (Q,); its error is that donor's fold of the selection.

        The selection without donor ``k`` is a leave-one-donor-out over the others; its fold
        ``j`` trains on every donor but ``j`` and ``k`` — the same training as the fold ``k``
        of the selection without ``j`` — so each pair of donors is one batched prediction."""
        donors = cells.shape[0]
        counts = counts[:, None]
        errors, inner_labels = {}, None
        for k in range(donors):
            for j in range(k + 1, donors):
                rest = np.ones(donors, bool)
                rest[[j, k]] = False
                pool = sums - cells[j] - cells[k]
                training = cells[rest] - (pool - cells[rest]) / (counts - 3)
                pair = np.stack([cells[j], cells[k]]) - pool / (counts - 2)
                inner_labels, predictions = self._candidates(training, pair[:, :m], donors - 3)
                residual = predictions - pair[:, None, m]                        # (2, C, F)
                error = np.einsum("ncf,ncf->nc", residual, residual) / features
                errors[k, j], errors[j, k] = error          # (k out, j predicted), and back
        picks = []
        for k in range(donors):
            table = np.stack([errors[k, j] for j in range(donors) if j != k])
            picks.append(labels.index(inner_labels[self._choose(table)]))
        return np.asarray(picks)

    def _choose(self, folds: np.ndarray) -> int:
        """Index of the configuration kept: the lowest mean error, unless it is not
        :attr:`margin` better than the additive model (index 0) or (:data:`MAJORITY`) not
        better on most donors."""
        errors = folds.mean(axis=0)
        best = int(np.argmin(errors))
        if errors[best] > (1.0 - self.margin) * errors[0] or \
                MAJORITY and 2 * np.sum(folds[:, best] < folds[:, 0]) <= folds.shape[0]:
            return 0
        return best

    def predict(self, person: int, target: int, chosen: Interaction | None = None
                ) -> tuple[np.ndarray, Interaction | None]:
        """Prediction of cell ``(person, target)`` from the person's other observed actions.

        Parameters
        ----------
        person, target : int
        chosen : Interaction, optional
            Configuration to use instead of choosing one by leave-one-donor-out for this
            person (falls back to the additive model where its rank is not reached).

        Returns
        -------
        prediction : ndarray, shape (features,)
        interaction : Interaction or None
            The configuration used (None when the person has no other action: the baseline).
        """
        means = self._means(person)
        if not np.isfinite(means[target]).all():
            raise MocapError("nobody else performed this action")
        observed = self._observed_actions(person, target, means)
        if not observed:
            return means[target], None
        if chosen is None:
            chosen = self.interaction(target, observed, person)
        offset = np.mean([self.data_[person, a] - means[a] for a in observed], axis=0)
        if chosen.rank == 0:
            return means[target] + offset, chosen
        reduced = self._means(person, coords=True)
        x = np.stack([self.coords_[person, a] - reduced[a] for a in observed])   # (m, r)
        if RANGE_GUARD and len(observed) == 1 and \
                self.outside_donors(target, observed, person, x):
            return means[target] + offset, chosen
        # The additive part as it is, the interaction's correction mapped back.
        correction = self._correction(chosen, target, observed, person, x) - x.mean(axis=0)
        return means[target] + offset + chosen.shrinkage * (self.basis_ @ correction), chosen

    def outside_donors(self, target: int, observed: tuple, person: int, x: np.ndarray
                       ) -> bool:
        """Whether the person's offset lies beyond the donors', by the donors' own rule.

        The statistic is the size of the part of a person's mean offset over the observed
        actions that the donors' offsets do not span, ``n = ‖P⊥ x̄_O‖`` (offsets formed
        exactly as the person's: means without them). Each donor, compared in turn with the
        others (means without it as well), gives ``n_k`` and the ratio ``n_k / max_{j≠k}
        n_j``; the person is outside when ``n`` exceeds the largest ``n_k`` by more than every
        donor's ratio. If the person were exchangeable with the donors, that would happen by
        chance with probability at most 1 / (donors + 1); a person far beyond it (a tibia
        marker on the other side of the shank turns its frame: biomechzoo HC036A) is one the
        correction was never validated on. A person whose offset the donors span — any person
        of an exactly multilinear corpus, however far from the mean — is never outside.

        Parameters
        ----------
        target : int
        observed : tuple of int
            The person's observed actions used.
        person : int
        x : ndarray, shape (m, r)
            The person's offsets of the observed actions, in :attr:`basis_` coordinates.

        Returns
        -------
        bool
        """
        cells, sums, counts = self._donors(target, observed, person)
        donors, m = cells.shape[0], len(observed)
        if donors < 3:
            return False
        offsets = pool_offsets(cells, sums, counts)[:, :m]
        counts = counts[:, None]

        def outside(offset: np.ndarray, others: np.ndarray) -> float:
            basis, _ = np.linalg.qr(others.T)
            return float(np.linalg.norm(offset - basis @ (basis.T @ offset)))

        sizes = []
        for k in range(donors):
            rest = np.arange(donors) != k
            own = offsets[k].mean(axis=0)
            others = (cells[rest] - (sums - cells[k] - cells[rest]) / (counts - 2))[:, :m]
            sizes.append(outside(own, others.mean(axis=1)))
        sizes = np.asarray(sizes)
        mine = outside(x.mean(axis=0), offsets.mean(axis=1))
        largest = np.array([np.delete(sizes, k).max() for k in range(donors)])
        limit = float(np.max(sizes / np.maximum(largest, 1e-300)))
        return mine > limit * sizes.max() and mine > 1e-9 * float(np.linalg.norm(x.mean(axis=0)))

    def map_weights(self, target: int, observed: tuple, alpha: float,
                    exclude: int | None = None) -> np.ndarray:
        """The ridge map's weights of the observed actions (shape (m,)), fitted to every
        donor of ``target`` from ``observed`` (``exclude``: the person predicted): how much of
        a person's offset in each observed action carries into the target (1/m each is the
        additive model)."""
        return map_weights(self._donor_offsets(target, observed, exclude), [alpha])[0]

    def _donor_offsets(self, target: int, observed: tuple, exclude: int | None) -> np.ndarray:
        """Every donor's offsets (Q, m + 1, r; observed actions, then the target), each
        formed from means without that donor and ``exclude``, as a predicted person's are."""
        return pool_offsets(*self._donors(target, observed, exclude))

    def _correction(self, chosen: Interaction, target: int, observed: tuple, person: int,
                    x: np.ndarray) -> np.ndarray:
        """The predicted cell's offset ``α + C v_b``, ``α + B_bᵀ s`` or the map's
        ``Σ_a w_a x_a``, fitted to all donors."""
        if chosen.rank == 0:
            return x.mean(axis=0)
        training = self._donor_offsets(target, observed, person)
        labels, predictions = self._candidates(training, x, training.shape[0] - 2)
        # The chosen rank, or the largest of its mode and ridge these donors reach.
        reached = [i for i, (mode, rank, alpha) in enumerate(labels)
                   if mode == chosen.mode and alpha == chosen.alpha and rank <= chosen.rank]
        return predictions[max(reached, key=lambda i: labels[i][1])] if reached \
            else x.mean(axis=0)             # the rank is not reached with every donor: additive


def pool_offsets(cells: np.ndarray, sums: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Each donor's offsets from means of the pool without it, as a predicted person's are
    formed (:meth:`InteractionModel._donors`' cells (Q, m + 1, r), the pool's sums
    (m + 1, r) and counts (m + 1,)); shape (Q, m + 1, r)."""
    return cells - (sums - cells) / (counts[:, None] - 1)


def shrinkage(additive: np.ndarray, correction: np.ndarray) -> tuple[float, np.ndarray]:
    """Fraction κ of a correction to keep, and each donor's error with the κ of the others.

    κ minimises ``Σ_k ‖r_k + κ c_k‖²`` over [0, 1] (``r_k``: donor k's held-out residual of
    the additive model, ``c_k``: the correction of the configuration chosen without k), so
    κ = 0 is the additive model and κ = 1 the configuration as it is. The κ of each donor's
    own error is fitted to the other donors alone, which holds the shrinkage itself out.

    Parameters
    ----------
    additive, correction : ndarray, shape (donors, r)

    Returns
    -------
    kappa : float
        From all donors.
    held_out : ndarray, shape (donors,)
        Squared error (summed over the r coordinates) of each donor with the κ of the others.

    Examples
    --------
    >>> import numpy as np
    >>> r = np.array([[1.0], [1.0], [1.0]])
    >>> kappa, held_out = shrinkage(r, -0.5 * r)            # half the residual removed: κ = 1
    >>> round(kappa, 6), held_out.round(6).tolist()
    (1.0, [0.25, 0.25, 0.25])
    >>> shrinkage(r, r)[0]                                  # a correction that only hurts
    0.0
    """
    products = np.einsum("kf,kf->k", additive, correction)
    norms = np.einsum("kf,kf->k", correction, correction)

    def best(numerator: np.ndarray, denominator: np.ndarray) -> np.ndarray:
        ratio = -numerator / np.where(denominator > 0, denominator, 1.0)
        return np.clip(np.where(denominator > 0, ratio, 0.0), 0.0, 1.0)

    kappa = float(best(products.sum(), norms.sum()))
    others = best(products.sum() - products, norms.sum() - norms)              # (donors,)
    residual = additive + others[:, None] * correction
    return kappa, np.einsum("kf,kf->k", residual, residual)


def span_basis(cells: np.ndarray) -> np.ndarray:
    """Orthonormal basis of the span of a few long vectors, from their Gram matrix.

    Parameters
    ----------
    cells : ndarray, shape (n, F)

    Returns
    -------
    ndarray, shape (F, r)
        r ≤ n columns; directions whose singular value is below 1e-6 of the largest are
        left out (they hold less than 1e-12 of the energy). Orthonormalised twice (the
        second pass on an r × r Gram), so ``basisᵀ basis`` is the identity to ~1e-12.

    Examples
    --------
    >>> import numpy as np
    >>> basis = span_basis(np.array([[3.0, 0.0, 4.0], [6.0, 0.0, 8.0]]))
    >>> basis.shape, bool(np.allclose(np.abs(basis[:, 0]), [0.6, 0.0, 0.8]))
    ((3, 1), True)
    """
    if cells.shape[0] == 0:
        return np.eye(cells.shape[1])
    # einsum, not BLAS: small products that threaded BLAS makes slower on a busy machine.
    values, vectors = np.linalg.eigh(np.einsum("if,jf->ij", cells, cells))
    keep = values > 1e-12 * max(float(values.max()), 1e-300)
    basis = np.einsum("if,ik->fk", cells, vectors[:, keep] / np.sqrt(values[keep]))
    values, vectors = np.linalg.eigh(np.einsum("fk,fl->kl", basis, basis))
    return np.einsum("fk,kl->fl", basis, vectors / np.sqrt(values) @ vectors.T)
