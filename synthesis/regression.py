"""``SignatureModel``: N-mode SVD regression of one feature block of a people × actions tensor.

Given ``data`` (people × actions × features, NaN where a cell is missing):

1. **Bases from the complete people** (those with every action): the action means ``M`` and
   the N-mode SVD of their deviations ``D − M = Z ×_1 P ×_2 A ×_3 J``
   (:func:`synthesis.nmode.nmode_svd`). Centring is a deliberate departure from the raw-data
   N-mode SVD of Vasilescu 2002: a regularised signature then shrinks towards the action's
   mean motion (the natural baseline) instead of towards a motionless zero pose.
2. **Signatures**: a complete person's is their row of ``P``; an incomplete person's is fitted
   to the actions they have (:func:`synthesis.signature.fit_signature`), which fills their
   missing cells. A missing or held-out cell takes no part in the bases, so it is always
   predicted, never echoed back.
   If fewer than two people are complete, the missing cells are first imputed
   (:func:`synthesis.imputation.impute_cells`: alternating N-mode SVD and signature
   regression from each person's observed cells, with a people rank below the number of
   people chosen by cross-validation,
   since at full rank an imputed guess reproduces itself), and the bases come from everyone.
3. **Rank and ridge by leave-one-out.** With full people and action ranks, synthesis equals
   example-weight transfer and can over-fit (``nmode-svd-notes.md`` §1.3d). Every complete
   person is removed from the bases in turn and each of their cells predicted from their
   other cells (incomplete people's cells are predicted with the full bases); the people rank
   ``r`` (leading signature dimensions; a slice of the HOSVD core, no refit) and the ridge
   ``λ = α · mean(σ_P²) / actions`` with the lowest total squared error are kept.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from synthesis.imputation import additive_errors, held_out_by_action, impute_cells, rank_grid
from synthesis.nmode import Rank, nmode_svd
from synthesis.signature import action_bases, fit_signature, synthesize_features

#: Relative ridge strengths α tried by leave-one-out (λ = α · mean σ_P² / actions).
RIDGE_GRID = (0.0, 1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0, 3.0, 10.0)
#: α used when there are too few people for leave-one-out.
DEFAULT_RIDGE = 1e-2


@dataclass
class _Fold:
    """Action means and action bases fitted to some complete people."""

    people: np.ndarray            # (K,) indices of the people used
    mean: np.ndarray              # (actions, features)
    core: np.ndarray              # (r_P, r_A, r_J)
    factors: list                 # [P (K, r_P), A (actions, r_A), J (features, r_J)]
    singular_values: list
    energy: list
    bases: np.ndarray             # (actions, r_P, r_J)
    ridge_unit: float             # λ per unit α


@dataclass
class SignatureModel:
    """Multilinear (N-mode SVD) model of one feature block with signature regression.

    Parameters
    ----------
    people_rank : int, float or None
        Signature dimensions: a count, a kept-energy fraction, or ``None`` to choose the count
        by leave-one-out.
    action_rank, feature_rank : int, float or None
        Ranks of the action and feature modes (``None``: numerical rank).
    ridge : float or "auto"
        Relative ridge α, or ``"auto"`` to choose it by leave-one-out.
    """

    people_rank: Rank = None
    action_rank: Rank = None
    feature_rank: Rank = None
    ridge: float | str = "auto"

    data_: np.ndarray | None = field(default=None, init=False, repr=False)
    basis_people_: np.ndarray | None = field(default=None, init=False, repr=False)
    mean_: np.ndarray | None = field(default=None, init=False, repr=False)
    core_: np.ndarray | None = field(default=None, init=False, repr=False)
    factors_: list | None = field(default=None, init=False, repr=False)
    singular_values_: list | None = field(default=None, init=False, repr=False)
    energy_: list | None = field(default=None, init=False, repr=False)
    bases_: np.ndarray | None = field(default=None, init=False, repr=False)
    signatures_: np.ndarray | None = field(default=None, init=False, repr=False)
    ridge_alpha_: float = field(default=DEFAULT_RIDGE, init=False)
    ridge_: float = field(default=0.0, init=False)
    loo_rms_: float = field(default=float("nan"), init=False)
    loo_cells_: int = field(default=0, init=False)
    imputed_rank_: int = field(default=0, init=False)
    #: Per action (shape (4, actions), :func:`held_out_by_action`): held-out RMS error of
    #: this model's predictions, of the additive model's on the same cells, the fraction of
    #: those cells this model predicts better, and their number — on the leave-one-out
    #: cells, or with imputed cells on the imputation's cross-validation (NaN for an action
    #: with no held-out cell).
    held_out_: np.ndarray | None = field(default=None, init=False, repr=False)

    # ------------------------------------------------------------------ fitting

    def fit(self, data: np.ndarray, cache: dict | None = None) -> "SignatureModel":
        """Fit to ``data`` (people, actions, features); NaN rows mark missing cells.

        Parameters
        ----------
        data : ndarray, shape (people, actions, features)
        cache : dict, optional
            Bases already fitted to sets of complete people, reused and filled in (keyed by
            the people's indices). Only valid across fits whose data agree on those people —
            as in leave-one-cell-out, where only the held-out person's cells change.

        Raises
        ------
        MocapError
            Fewer than 2 people with every action and too few people to impute the missing
            cells (see :func:`impute_cells`).
        """
        self._cache = cache
        self.data_ = np.asarray(data, dtype=float)
        self._basis_data = self.data_
        self.imputed_rank_ = 0
        observed = self.observed
        complete = np.flatnonzero(observed.all(axis=1))
        if complete.size < 2:
            # Too few complete people: impute the missing cells with a low-rank model first.
            self._cache = None
            self._basis_data, self.imputed_rank_, held_out = impute_cells(
                self.data_, self.action_rank, self.feature_rank, self.people_rank)
            complete = np.arange(self.data_.shape[0])
        full = self._fold(complete)
        alphas = RIDGE_GRID if self.ridge == "auto" else (float(self.ridge),)
        if self.imputed_rank_:
            ranks = [min(self.imputed_rank_, full.bases.shape[1])]
        elif self.people_rank is None:
            ranks = rank_grid(full.bases.shape[1])
        else:
            ranks = [full.bases.shape[1]]
        errors, cells, per_cell = self._leave_one_out_errors(full, ranks, alphas)
        if cells:
            best_rank, best_alpha = np.unravel_index(int(np.argmin(errors)), errors.shape)
            rank, alpha = ranks[best_rank], alphas[best_alpha]
            self.loo_rms_ = float(np.sqrt(errors[best_rank, best_alpha] /
                                          (cells * self.data_.shape[2])))
        else:
            rank, alpha = ranks[-1], (DEFAULT_RIDGE if self.ridge == "auto" else alphas[0])
            self.loo_rms_ = float("nan")
        self.loo_cells_ = int(cells)
        if self.imputed_rank_:
            # The imputation saw every cell: its cross-validation is what was held out.
            self.held_out_ = held_out
        elif cells:
            actions, own, baseline = per_cell
            self.held_out_ = held_out_by_action(actions, own[:, best_rank, best_alpha],
                                                baseline, self.data_.shape[1])
        else:
            self.held_out_ = np.full((4, self.data_.shape[1]), np.nan)
        self._store(full, rank)
        self.ridge_alpha_ = float(alpha)
        self.ridge_ = float(alpha) * full.ridge_unit
        self.signatures_ = self._signatures()
        self._cache = None
        return self

    @property
    def observed(self) -> np.ndarray:
        """(people, actions) bool: captured cells."""
        return np.isfinite(self.data_).all(axis=2)

    def _fold(self, people: np.ndarray) -> _Fold:
        """Means and N-mode SVD of the deviations of ``people`` (all complete)."""
        cache = getattr(self, "_cache", None)
        key = (tuple(int(i) for i in people), self.people_rank, self.action_rank,
               self.feature_rank)
        if cache is not None and key in cache:
            return cache[key]
        fold = self._fit_fold(people)
        if cache is not None:
            cache[key] = fold
        return fold

    def _fit_fold(self, people: np.ndarray) -> _Fold:
        block = self._basis_data[people]                              # (K, A, F)
        mean = block.mean(axis=0)
        decomposition = nmode_svd(block - mean,
                                  [self.people_rank, self.action_rank, self.feature_rank])
        bases = action_bases(decomposition.core, decomposition.factors[1])
        sigma = decomposition.singular_values[0]
        unit = float(np.mean(sigma ** 2) / self.data_.shape[1]) if sigma.size else 0.0
        return _Fold(np.asarray(people), mean, decomposition.core, decomposition.factors,
                     decomposition.singular_values, decomposition.energy, bases,
                     unit if unit > 0 else 1.0)

    def _store(self, fold: _Fold, rank: int) -> None:
        """Keep ``fold`` truncated to its leading ``rank`` signature dimensions."""
        self.basis_people_ = fold.people
        self.mean_ = fold.mean
        self.core_ = fold.core[:rank]
        self.factors_ = [fold.factors[0][:, :rank], fold.factors[1], fold.factors[2]]
        self.singular_values_ = [fold.singular_values[0][:rank], fold.singular_values[1],
                                 fold.singular_values[2]]
        total = float(np.sum(fold.singular_values[0] ** 2) / max(fold.energy[0], 1e-300))
        kept = float(np.sum(self.singular_values_[0] ** 2))
        self.energy_ = [kept / total if total > 0 else 1.0, fold.energy[1], fold.energy[2]]
        self.bases_ = fold.bases[:, :rank]

    def _cell_errors(self, fold: _Fold, person: int, ranks: Sequence[int],
                     alphas: Sequence[float]) -> np.ndarray:
        """Squared errors of each captured cell of ``person`` predicted from their other cells.

        Returns
        -------
        ndarray, shape (cells, ranks, alphas)
            ``‖prediction − capture‖²`` summed over features.
        """
        observed = np.flatnonzero(self.observed[person])
        if observed.size < 2:
            return np.zeros((0, len(ranks), len(alphas)))
        residuals = self.data_[person, observed] - fold.mean[observed]          # (k, F)
        coordinates = residuals @ fold.factors[2]                               # (k, r_J)
        # The part of a capture outside the feature basis is an error of every prediction.
        outside = np.maximum(np.sum(residuals ** 2, axis=1) - np.sum(coordinates ** 2, axis=1),
                             0.0)
        chosen = fold.bases[observed]                                           # (k, r_P, r_J)
        grams = np.einsum("kij,klj->kil", chosen, chosen)                       # (k, r_P, r_P)
        sides = np.einsum("kij,kj->ki", chosen, coordinates)                    # (k, r_P)
        lambdas = np.asarray(alphas) * fold.ridge_unit
        # Leave one action out: the normal equations of the others, for every cell at once.
        grams = grams.sum(axis=0) - grams                                       # (k, r_P, r_P)
        sides = sides.sum(axis=0) - sides                                       # (k, r_P)
        errors = np.empty((observed.size, len(ranks), len(alphas)))
        for i, rank in enumerate(ranks):
            r = min(rank, grams.shape[1])
            # Ridge solutions for every λ from one (batched) eigen-decomposition per cell.
            values, vectors = np.linalg.eigh(grams[:, :r, :r])                 # (k, r), (k, r, r)
            projected = np.einsum("kji,kj->ki", vectors, sides[:, :r])          # (k, r)
            scale = values[:, None, :] + lambdas[None, :, None]                 # (k, alphas, r)
            tiny = 1e-12 * np.maximum(values.max(axis=1, initial=0.0), 1e-300)
            inverse = np.where(np.abs(scale) > tiny[:, None, None],
                               1.0 / np.where(scale == 0, 1.0, scale), 0.0)
            signatures = np.einsum("kar,kir->kai", inverse * projected[:, None, :], vectors)
            predicted = np.einsum("kai,kij->kaj", signatures, chosen[:, :r])    # (k, alphas, r_J)
            errors[:, i] = np.sum((predicted - coordinates[:, None, :]) ** 2, axis=2) \
                + outside[:, None]
        return errors

    def _leave_one_out_errors(self, full: _Fold, ranks: Sequence[int], alphas: Sequence[float]
                              ) -> tuple[np.ndarray, int, tuple]:
        """Summed squared errors (ranks, alphas) over the leave-one-out cells, their count,
        and per cell: its action, its squared errors (cells, ranks, alphas) and the additive
        model's (cells,)."""
        totals = np.zeros((len(ranks), len(alphas)))
        cells = 0
        scored, blocks = [], []
        complete = list(full.people)
        for person in range(self.data_.shape[0]):
            if person in complete:
                if len(complete) < 3:
                    continue
                fold = self._fold(np.array([q for q in complete if q != person]))
            else:
                fold = full
            errors = self._cell_errors(fold, person, ranks, alphas)
            totals += errors.sum(axis=0)
            cells += errors.shape[0]
            if errors.shape[0]:
                scored += [(person, a) for a in np.flatnonzero(self.observed[person])]
                blocks.append(errors)
        additive = additive_errors(self.data_, self.observed, scored)
        own = np.concatenate(blocks) if blocks else np.zeros((0, len(ranks), len(alphas)))
        return totals, cells, (np.array([a for _, a in scored], dtype=int), own, additive)

    def _signatures(self) -> np.ndarray:
        """Signature of every person: row of P for the complete, a fit for the others."""
        signatures = np.full((self.data_.shape[0], self.bases_.shape[1]), np.nan)
        observed = self.observed
        complete = observed.all(axis=1)
        signatures[self.basis_people_] = self.factors_[0]
        for person in range(self.data_.shape[0]):
            if complete[person] or not observed[person].any():
                continue
            actions = np.flatnonzero(observed[person])
            signatures[person] = self.signature_from(actions, self.data_[person, actions])
        return signatures

    # ------------------------------------------------------------------ using the model

    @property
    def rank(self) -> int:
        """Signature dimensions kept."""
        return int(self.bases_.shape[1])

    def signature_from(self, actions: Sequence[int], features: np.ndarray) -> np.ndarray:
        """Ridge least-squares signature from captured cells.

        Parameters
        ----------
        actions : sequence of int
            Action of each cell.
        features : ndarray, shape (cells, features)

        Returns
        -------
        ndarray, shape (rank,)
        """
        actions = np.asarray(actions, dtype=int)
        residuals = np.asarray(features, dtype=float) - self.mean_[actions]
        return fit_signature(self.bases_, self.factors_[2], residuals, actions, self.ridge_)

    def predict(self, signature: np.ndarray, action: int) -> np.ndarray:
        """Features of signature(s) doing an action: ``m_a + J G_aᵀ s``.

        Parameters
        ----------
        signature : ndarray, shape (rank,) or (n, rank)
        action : int

        Returns
        -------
        ndarray, shape (features,) or (n, features)
        """
        return synthesize_features(self.bases_, self.factors_[2], self.mean_, signature, action)

    # ------------------------------------------------------------------ persistence

    def to_arrays(self, prefix: str) -> tuple[dict, dict]:
        """``(arrays, meta)`` to store this model under ``prefix``."""
        arrays = {
            "data": self.data_, "basis_people": self.basis_people_, "mean": self.mean_,
            "core": self.core_, "people_factor": self.factors_[0],
            "action_factor": self.factors_[1], "feature_factor": self.factors_[2],
            "people_singular_values": self.singular_values_[0],
            "action_singular_values": self.singular_values_[1],
            "feature_singular_values": self.singular_values_[2],
            "energy": np.asarray(self.energy_), "signatures": self.signatures_,
            "held_out": self.held_out_,
        }
        meta = {"people_rank": self.people_rank, "action_rank": self.action_rank,
                "feature_rank": self.feature_rank, "ridge": self.ridge,
                "ridge_alpha": self.ridge_alpha_, "ridge_value": self.ridge_,
                "loo_rms": self.loo_rms_, "loo_cells": self.loo_cells_,
                "imputed_rank": self.imputed_rank_}
        return {f"{prefix}_{key}": value for key, value in arrays.items()}, meta

    @classmethod
    def from_arrays(cls, prefix: str, arrays: dict, meta: dict) -> "SignatureModel":
        """Inverse of :meth:`to_arrays`."""
        get = lambda key: arrays[f"{prefix}_{key}"]          # noqa: E731
        model = cls(people_rank=meta["people_rank"], action_rank=meta["action_rank"],
                    feature_rank=meta["feature_rank"], ridge=meta["ridge"])
        model.data_ = get("data")
        model.basis_people_ = get("basis_people").astype(int)
        model.mean_ = get("mean")
        model.core_ = get("core")
        model.factors_ = [get("people_factor"), get("action_factor"), get("feature_factor")]
        model.singular_values_ = [get("people_singular_values"), get("action_singular_values"),
                                  get("feature_singular_values")]
        model.energy_ = [float(e) for e in get("energy")]
        model.bases_ = action_bases(model.core_, model.factors_[1])
        model.signatures_ = get("signatures")
        model.ridge_alpha_, model.ridge_ = float(meta["ridge_alpha"]), float(meta["ridge_value"])
        model.loo_rms_, model.loo_cells_ = float(meta["loo_rms"]), int(meta["loo_cells"])
        model.imputed_rank_ = int(meta.get("imputed_rank", 0))
        # Files written before the held-out comparison: nothing says the model beat the
        # additive one anywhere.
        key = f"{prefix}_held_out"
        model.held_out_ = np.asarray(arrays[key], dtype=float) if key in arrays \
            else np.full((4, model.data_.shape[1]), np.nan)
        return model
