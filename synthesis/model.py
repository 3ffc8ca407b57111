"""``MotionModel``: the N-mode SVD motion model fitted from a corpus, saved as ``.npz``.

Fitting (:meth:`MotionModel.fit`):

1. Each captured (person, action) cell becomes one feature vector: the time-normalised cycle
   (samples × angle columns, frame-major, degrees) followed by the cycle duration times
   ``timing_weight`` (degrees per second), so timing is modelled like the angles and
   synthesised motions get a predicted duration.
2. The bases come from the **complete** people (those who performed every action). The model
   decomposes their deviations from each action's mean motion, ``D − M = Z ×_1 P ×_2 A ×_3 J``
   (:func:`synthesis.nmode.nmode_svd`, ranks per mode by count, kept energy or numerical
   rank). Centring is a deliberate departure from the raw-data N-mode SVD: the ridge below
   then shrinks an uncertain signature towards the action's mean motion (the natural baseline)
   instead of towards a motionless zero pose.
3. The signature of a complete person is their row of ``P``; an incomplete person's comes from
   the actions they have (:func:`synthesis.signature.fit_signature`), which fills their
   missing cells. A held-out or missing cell is therefore always *predicted* from other cells,
   never echoed: it takes no part in the bases.
4. With full people and action ranks, synthesis equals example-weight transfer (the notes,
   §1.3d) and can over-fit; the ridge ``λ = α · mean(σ_P²) / actions`` is chosen by
   leave-one-out over the complete people (each in turn removed from the bases and predicted,
   action by action, from their other actions) and over the incomplete people's cells.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import numpy as np

from mocap.errors import MocapError
from synthesis.nmode import NModeSVD, Rank, nmode_svd
from synthesis.signature import (action_bases, fit_signature, interpolate_signatures,
                                 posterior_scores, signature_system, solve_signature,
                                 synthesize_features)
from synthesis.tensor import MotionCorpus, check_corpus_size, normalise_cycles, read_trial_angles

#: Relative ridge strengths α tried by leave-one-out (λ = α · mean σ_P² / actions).
RIDGE_GRID = (0.0, 1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0, 3.0, 10.0)
#: α used when there are too few people for leave-one-out.
DEFAULT_RIDGE = 1e-2
#: Default weight of the cycle duration among the features, degrees per second and per
#: √sample: 0.1 s of timing error counts like 1° of error over one whole angle curve.
TIMING_DEGREES_PER_SECOND = 10.0
#: File format version written into saved models.
FORMAT_VERSION = 1


@dataclass
class _Bases:
    """Action means and the N-mode SVD of the complete people's deviations."""

    people: np.ndarray            # (K,) indices of the complete people used
    mean: np.ndarray              # (actions, features)
    decomposition: NModeSVD
    bases: np.ndarray             # (actions, r_P, r_J)
    ridge_unit: float             # λ per unit α

    @property
    def feature_factor(self) -> np.ndarray:
        return self.decomposition.factors[2]


@dataclass
class Recognition:
    """Result of :meth:`MotionModel.recognize`.

    Attributes
    ----------
    person, action : str
        Most likely person and action.
    scores : dict of str to float
        Person → score in [0, 1] (summing to 1) for the recognised action: softmax of
        ``−½ (d / σ)²`` with ``d`` the RMS distance (degrees) between the trial and the model's
        motion of that person, ``σ`` the model's leave-one-out synthesis RMS.
    distances : dict of str to float
        Person → RMS distance, degrees, for the recognised action.
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


@dataclass
class MotionModel:
    """People × actions motion model (Vasilescu's motion signatures), scikit-learn style.

    Parameters
    ----------
    people_rank, action_rank, feature_rank : int, float or None
        Rank kept in each mode of the N-mode SVD: a count, a kept-energy fraction in (0, 1],
        or ``None`` for the numerical rank.
    ridge : float or "auto"
        Relative ridge α of signature fits, or ``"auto"`` to choose it by leave-one-out.
    timing_weight : float, optional
        Weight of the cycle duration among the features, degrees per second (default
        ``10 · √samples``).

    Examples
    --------
    >>> from synthesis.model import MotionModel          # doctest: +SKIP
    >>> model = MotionModel().fit(corpus)                 # doctest: +SKIP
    >>> curve, duration = model.synthesize("ana", "run")  # doctest: +SKIP
    """

    people_rank: Rank = None
    action_rank: Rank = None
    feature_rank: Rank = None
    ridge: float | str = "auto"
    timing_weight: float | None = None

    # Fitted state (set by fit or load).
    people: list = field(default_factory=list, init=False)
    actions: list = field(default_factory=list, init=False)
    segments: list = field(default_factory=list, init=False)
    parents: list = field(default_factory=list, init=False)
    columns: list = field(default_factory=list, init=False)
    sequence: str = field(default="ZXY", init=False)
    samples: int = field(default=0, init=False)
    markerset: str | None = field(default=None, init=False)
    cycles: bool = field(default=False, init=False)
    cycle_column: str | None = field(default=None, init=False)
    sources: dict = field(default_factory=dict, init=False)
    data_: np.ndarray | None = field(default=None, init=False, repr=False)
    timing_weight_: float = field(default=0.0, init=False)
    basis_people_: np.ndarray | None = field(default=None, init=False, repr=False)
    action_mean_: np.ndarray | None = field(default=None, init=False, repr=False)
    core_: np.ndarray | None = field(default=None, init=False, repr=False)
    factors_: list | None = field(default=None, init=False, repr=False)
    singular_values_: list | None = field(default=None, init=False, repr=False)
    energy_: list | None = field(default=None, init=False, repr=False)
    bases_: np.ndarray | None = field(default=None, init=False, repr=False)
    signatures_: np.ndarray | None = field(default=None, init=False, repr=False)
    ridge_alpha_: float = field(default=DEFAULT_RIDGE, init=False)
    ridge_: float = field(default=0.0, init=False)
    loo_rms_: float = field(default=float("nan"), init=False)
    loo_table_: dict = field(default_factory=dict, init=False, repr=False)
    spread_rms_: float = field(default=float("nan"), init=False)

    # ------------------------------------------------------------------ features

    @property
    def angle_size(self) -> int:
        """Number of angle features (samples × columns)."""
        return self.samples * len(self.columns)

    def features(self, curve: np.ndarray, duration: float | np.ndarray) -> np.ndarray:
        """Feature vector(s) of cycle(s).

        Parameters
        ----------
        curve : ndarray, shape (..., samples, columns), degrees
        duration : float or ndarray, shape (...), seconds

        Returns
        -------
        ndarray, shape (..., samples · columns + 1)
        """
        curve = np.asarray(curve, dtype=float)
        flat = curve.reshape(curve.shape[:-2] + (-1,))
        timing = np.asarray(duration, dtype=float)[..., None] * self.timing_weight_
        return np.concatenate([flat, timing], axis=-1)

    def split(self, features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Inverse of :meth:`features`: ``(curve (..., samples, columns), duration (...))``."""
        features = np.asarray(features)
        curve = features[..., :self.angle_size].reshape(
            features.shape[:-1] + (self.samples, len(self.columns)))
        return curve, features[..., self.angle_size] / self.timing_weight_

    def angle_rms(self, first: np.ndarray, second: np.ndarray) -> np.ndarray:
        """RMS difference over the angle features, degrees (duration excluded)."""
        difference = np.asarray(first)[..., :self.angle_size] - \
            np.asarray(second)[..., :self.angle_size]
        return np.sqrt(np.mean(difference ** 2, axis=-1))

    # ------------------------------------------------------------------ fitting

    def fit(self, corpus: MotionCorpus) -> "MotionModel":
        """Fit the model to a corpus (see the module notes for the method).

        Parameters
        ----------
        corpus : MotionCorpus
            At least 2 people and 2 actions, at least 2 people with every action.

        Returns
        -------
        self
        """
        check_corpus_size(corpus.people, corpus.actions)
        self.people, self.actions = list(corpus.people), list(corpus.actions)
        self.segments, self.parents = list(corpus.segments), list(corpus.parents)
        self.columns, self.sequence = list(corpus.columns), corpus.sequence
        self.samples, self.markerset = corpus.samples, corpus.markerset
        self.cycles, self.cycle_column = corpus.cycles, corpus.cycle_column
        self.sources = {f"{p}_{a}": list(v) for (p, a), v in corpus.sources.items()}
        self.timing_weight_ = float(self.timing_weight if self.timing_weight is not None
                                    else TIMING_DEGREES_PER_SECOND * np.sqrt(self.samples))
        observed = corpus.observed
        data = self.features(np.where(observed[..., None, None], corpus.angles, 0.0),
                             np.where(observed, corpus.durations, 0.0))
        data[~observed] = np.nan
        self.data_ = data
        complete = np.flatnonzero(observed.all(axis=1))
        if complete.size < 2:
            raise MocapError(
                "need at least 2 people who performed every action "
                f"({', '.join(self.actions)}) to build the action bases; "
                + (f"only {self.people[complete[0]]} did" if complete.size else "nobody did")
                + f"; missing cells: {_cells_text(corpus.missing_cells())}")
        bases = self._fit_bases(complete)
        self._store_bases(bases)
        if self.ridge == "auto":
            self.ridge_alpha_, self.loo_rms_, self.loo_table_ = self._choose_ridge(bases)
        else:
            alpha = float(self.ridge)
            if not np.isfinite(alpha) or alpha < 0:
                raise MocapError(f"ridge must be 'auto' or a number ≥ 0, got {self.ridge}")
            self.ridge_alpha_ = alpha
            errors = self._leave_one_out_errors(bases, (alpha,))
            self.loo_rms_ = float(np.sqrt(errors[0][0] / errors[1])) if errors[1] else float("nan")
            self.loo_table_ = {}
        self.ridge_ = self.ridge_alpha_ * bases.ridge_unit
        self.signatures_ = self._signatures(bases, self.ridge_)
        deviations = data[complete] - bases.mean
        self.spread_rms_ = float(np.sqrt(np.mean(deviations[..., :self.angle_size] ** 2)))
        return self

    def _fit_bases(self, people: np.ndarray) -> _Bases:
        """Action means and N-mode SVD of the deviations of ``people`` (all complete)."""
        block = self.data_[people]                                    # (K, A, F)
        mean = block.mean(axis=0)
        deviations = block - mean
        ranks = [self.people_rank, self.action_rank, self.feature_rank]
        decomposition = nmode_svd(deviations, ranks)
        bases = action_bases(decomposition.core, decomposition.factors[1])
        sigma = decomposition.singular_values[0]
        ridge_unit = float(np.mean(sigma ** 2) / len(self.actions)) if sigma.size else 1.0
        return _Bases(np.asarray(people), mean, decomposition, bases, max(ridge_unit, 1e-300))

    def _store_bases(self, bases: _Bases) -> None:
        self.basis_people_ = bases.people
        self.action_mean_ = bases.mean
        self.core_ = bases.decomposition.core
        self.factors_ = list(bases.decomposition.factors)
        self.singular_values_ = list(bases.decomposition.singular_values)
        self.energy_ = list(bases.decomposition.energy)
        self.bases_ = bases.bases

    def _signatures(self, bases: _Bases, ridge: float) -> np.ndarray:
        """Signature of every person: row of P for the complete, a fit for the others."""
        observed = np.isfinite(self.data_[..., 0])
        rank = bases.bases.shape[1]
        signatures = np.full((len(self.people), rank), np.nan)
        signatures[bases.people] = bases.decomposition.factors[0]
        for person in range(len(self.people)):
            if person in bases.people:
                continue
            actions = np.flatnonzero(observed[person])
            if actions.size:
                residuals = self.data_[person, actions] - bases.mean[actions]
                signatures[person] = fit_signature(bases.bases, bases.feature_factor, residuals,
                                                   actions, ridge)
        return signatures

    def _predict_cells(self, bases: _Bases, person: int, alphas: Sequence[float]
                       ) -> list[tuple[int, np.ndarray]]:
        """Each observed cell of ``person`` predicted from their other cells, per α.

        Returns ``[(action, predictions (len(alphas), features)), …]``.
        """
        observed = np.flatnonzero(np.isfinite(self.data_[person, :, 0]))
        results = []
        if observed.size < 2:
            return results
        residuals = self.data_[person, observed] - bases.mean[observed]
        coordinates = residuals @ bases.feature_factor                     # (k, r_J)
        chosen = bases.bases[observed]                                     # (k, r_P, r_J)
        grams = np.einsum("kij,klj->kil", chosen, chosen)
        sides = np.einsum("kij,kj->ki", chosen, coordinates)
        for position, action in enumerate(observed):
            others = np.arange(observed.size) != position
            gram, side = grams[others].sum(axis=0), sides[others].sum(axis=0)
            signatures = np.stack([solve_signature(gram, side, alpha * bases.ridge_unit)
                                   for alpha in alphas])
            predictions = synthesize_features(bases.bases, bases.feature_factor, bases.mean,
                                              signatures, action)
            results.append((int(action), predictions))
        return results

    def _leave_one_out_errors(self, bases: _Bases, alphas: Sequence[float]
                              ) -> tuple[np.ndarray, int]:
        """Summed squared angle errors per α over leave-one-out cells, and the value count."""
        totals = np.zeros(len(alphas))
        count = 0
        complete = list(bases.people)
        for person in range(len(self.people)):
            if person in complete:
                if len(complete) < 3:
                    continue
                fold = self._fit_bases(np.array([q for q in complete if q != person]))
            else:
                fold = bases
            for action, predictions in self._predict_cells(fold, person, alphas):
                truth = self.data_[person, action, :self.angle_size]
                totals += np.sum((predictions[:, :self.angle_size] - truth) ** 2, axis=1)
                count += self.angle_size
        return totals, count

    def _choose_ridge(self, bases: _Bases) -> tuple[float, float, dict]:
        """α with the lowest leave-one-out angle error, that error (RMS degrees), the table."""
        totals, count = self._leave_one_out_errors(bases, RIDGE_GRID)
        if count == 0:
            return DEFAULT_RIDGE, float("nan"), {}
        rms = np.sqrt(totals / count)
        best = int(np.argmin(rms))
        return float(RIDGE_GRID[best]), float(rms[best]), \
            {float(a): float(r) for a, r in zip(RIDGE_GRID, rms)}

    # ------------------------------------------------------------------ using the model

    def _check_fitted(self) -> None:
        if self.signatures_ is None:
            raise MocapError("the motion model is not fitted")

    def person_index(self, person: str) -> int:
        """Index of a person (MocapError naming the known people)."""
        self._check_fitted()
        if person not in self.people:
            raise MocapError(f"unknown person {person!r}; the model knows {', '.join(self.people)}")
        return self.people.index(person)

    def action_index(self, action: str) -> int:
        """Index of an action (MocapError naming the known actions)."""
        self._check_fitted()
        if action not in self.actions:
            raise MocapError(f"unknown action {action!r}; the model knows {', '.join(self.actions)}")
        return self.actions.index(action)

    @property
    def feature_factor(self) -> np.ndarray:
        """Orthonormal feature basis ``J``, shape (features, r_J)."""
        return self.factors_[2]

    def signature(self, person: str) -> np.ndarray:
        """Signature of a known person, shape (r_P,)."""
        return self.signatures_[self.person_index(person)]

    def signature_from(self, observations: Sequence[tuple[str, np.ndarray, float]]) -> np.ndarray:
        """Signature of a (new) person from captured cycles.

        Parameters
        ----------
        observations : sequence of (action, curve (samples, columns) degrees, duration s)

        Returns
        -------
        ndarray, shape (r_P,)
        """
        self._check_fitted()
        actions = [self.action_index(action) for action, _, _ in observations]
        features = np.stack([self.features(curve, duration) for _, curve, duration in observations])
        residuals = features - self.action_mean_[actions]
        return fit_signature(self.bases_, self.feature_factor, residuals, actions, self.ridge_)

    def interpolate(self, first: str, second: str, weight: float) -> np.ndarray:
        """Signature ``(1 − w) s_first + w s_second``."""
        return interpolate_signatures(self.signature(first), self.signature(second), weight)

    def synthesize_features(self, signature: np.ndarray, action: str) -> np.ndarray:
        """Feature vector of a signature doing an action, shape (features,)."""
        return synthesize_features(self.bases_, self.feature_factor, self.action_mean_,
                                   signature, self.action_index(action))

    def synthesize(self, person: str | None, action: str, signature: np.ndarray | None = None,
                   samples: int | None = None) -> tuple[np.ndarray, float]:
        """One cycle of a person (or a signature) doing an action.

        Parameters
        ----------
        person : str or None
            Known person (ignored when ``signature`` is given).
        action : str
        signature : ndarray, shape (r_P,), optional
        samples : int, optional
            Frames of the returned cycle (default: the model's sample count).

        Returns
        -------
        curve : ndarray, shape (samples, columns), degrees
        duration : float
            Predicted cycle duration, seconds (the action's mean duration if the prediction is
            not positive).
        """
        if signature is None:
            if person is None:
                raise MocapError("give a person or a signature to synthesise")
            signature = self.signature(person)
        features = self.synthesize_features(signature, action)
        curve, duration = self.split(features)
        duration = float(duration)
        if not duration > 0:
            duration = float(self.split(self.action_mean_[self.action_index(action)])[1])
        if samples is not None and samples != self.samples:
            if samples < 2:
                raise MocapError(f"samples must be at least 2, got {samples}")
            phase = np.linspace(0.0, 1.0, self.samples)
            curve = np.stack([np.interp(np.linspace(0.0, 1.0, samples), phase, column)
                              for column in curve.T], axis=1)
        return curve, duration

    def synthesize_angles(self, person: str | None, action: str,
                          signature: np.ndarray | None = None, samples: int | None = None):
        """:meth:`synthesize` as :class:`mocap.angles.JointAngles` whose times span the duration."""
        from mocap.angles import JointAngles

        curve, duration = self.synthesize(person, action, signature, samples)
        times = np.linspace(0.0, duration, curve.shape[0])
        return JointAngles(times=times, values=curve.reshape(curve.shape[0], -1, 3),
                           segments=list(self.segments), sequence=self.sequence,
                           parents=list(self.parents))

    def normalise(self, angles) -> tuple[np.ndarray, float]:
        """Time-normalise joint angles the way the corpus was (samples, cycles, reference).

        Parameters
        ----------
        angles : mocap.angles.JointAngles

        Returns
        -------
        curve : ndarray, shape (samples, columns), degrees
        duration : float, seconds
        """
        self._check_fitted()
        if list(angles.segments) != list(self.segments):
            raise MocapError(f"trial segments ({', '.join(angles.segments)}) differ from the "
                             f"model's ({', '.join(self.segments)})", getattr(angles, "path", None))
        if angles.sequence != self.sequence:
            raise MocapError(f"trial angles use the Euler sequence {angles.sequence}, the model "
                             f"{self.sequence}")
        values = np.asarray(angles.values, dtype=float)
        reference = self.columns.index(self.cycle_column) if self.cycle_column else None
        curve, duration, _ = normalise_cycles(np.asarray(angles.times, dtype=float),
                                              values.reshape(values.shape[0], -1), self.samples,
                                              self.cycles, reference)
        return curve, duration

    def read_trial(self, path: str | os.PathLike) -> tuple[np.ndarray, float]:
        """A trial file (marker trial with the model's marker set, angle CSV or BVH) →
        normalised ``(curve, duration)``."""
        angles = read_trial_angles(path, self.markerset, self.sequence)
        try:
            return self.normalise(angles)
        except MocapError as error:
            raise MocapError(error.problem, error.path or path) from None

    def distances(self, curve: np.ndarray, duration: float) -> np.ndarray:
        """RMS angle distance (degrees) between a cycle and every person's motion of every
        action, shape (people, actions); NaN for people without a signature."""
        self._check_fitted()
        features = self.features(curve, duration)
        table = np.full((len(self.people), len(self.actions)), np.nan)
        valid = np.isfinite(self.signatures_).all(axis=1)
        for action in range(len(self.actions)):
            predictions = synthesize_features(self.bases_, self.feature_factor, self.action_mean_,
                                              self.signatures_[valid], action)
            table[valid, action] = self.angle_rms(predictions, features)
        return table

    def recognize(self, curve: np.ndarray, duration: float, action: str | None = None
                  ) -> Recognition:
        """Most likely person (and action) of a captured cycle.

        Parameters
        ----------
        curve : ndarray, shape (samples, columns), degrees
        duration : float, seconds
        action : str, optional
            The trial's action when known; otherwise it is recognised too.

        Returns
        -------
        Recognition
        """
        table = self.distances(curve, duration)
        scale = self.loo_rms_ if np.isfinite(self.loo_rms_) else self.spread_rms_
        candidates = [self.action_index(action)] if action is not None \
            else list(range(len(self.actions)))
        nearest = np.array([np.nanmin(table[:, a]) for a in range(len(self.actions))])
        best_action = min(candidates, key=lambda a: nearest[a])
        column = table[:, best_action]
        valid = np.isfinite(column)
        people = [self.people[i] for i in np.flatnonzero(valid)]
        scores = posterior_scores(column[valid], scale)
        action_scores = posterior_scores(nearest[candidates], scale)
        return Recognition(
            person=people[int(np.argmin(column[valid]))], action=self.actions[best_action],
            scores={name: float(s) for name, s in zip(people, scores)},
            distances={name: float(d) for name, d in zip(people, column[valid])},
            action_scores={self.actions[a]: float(s) for a, s in zip(candidates, action_scores)})

    # ------------------------------------------------------------------ persistence

    def summary(self) -> dict:
        """Plain description of the fitted model (for printing and JSON)."""
        self._check_fitted()
        observed = np.isfinite(self.data_[..., 0])
        return {
            "people": list(self.people), "actions": list(self.actions),
            "segments": len(self.segments), "columns": len(self.columns),
            "sequence": self.sequence, "samples": self.samples, "markerset": self.markerset,
            "cycles": self.cycles, "cycle_column": self.cycle_column,
            "missing_cells": [f"{self.people[p]}_{self.actions[a]}"
                              for p, a in np.argwhere(~observed)],
            "basis_people": [self.people[i] for i in self.basis_people_],
            "ranks": [int(f.shape[1]) for f in self.factors_],
            "energy": [float(e) for e in self.energy_],
            "ridge_alpha": self.ridge_alpha_, "loo_rms_deg": self.loo_rms_,
            "spread_rms_deg": self.spread_rms_,
        }

    def save(self, path: str | os.PathLike) -> None:
        """Write the model to ``path`` (.npz), atomically."""
        from mocap.atomic import atomic_path

        self._check_fitted()
        meta = {
            "format": "mocap-motion-model", "version": FORMAT_VERSION,
            "people": self.people, "actions": self.actions, "segments": self.segments,
            "parents": self.parents, "columns": self.columns, "sequence": self.sequence,
            "samples": self.samples, "markerset": self.markerset, "cycles": self.cycles,
            "cycle_column": self.cycle_column, "sources": self.sources,
            "people_rank": self.people_rank, "action_rank": self.action_rank,
            "feature_rank": self.feature_rank, "ridge": self.ridge,
            "timing_weight": self.timing_weight, "timing_weight_": self.timing_weight_,
            "ridge_alpha": self.ridge_alpha_, "ridge_value": self.ridge_,
            "loo_rms": self.loo_rms_, "spread_rms": self.spread_rms_,
            "loo_table": {str(k): v for k, v in self.loo_table_.items()},
        }
        arrays = {
            "data": self.data_, "basis_people": self.basis_people_,
            "action_mean": self.action_mean_, "core": self.core_,
            "people_factor": self.factors_[0], "action_factor": self.factors_[1],
            "feature_factor": self.factors_[2], "signatures": self.signatures_,
            "people_singular_values": self.singular_values_[0],
            "action_singular_values": self.singular_values_[1],
            "feature_singular_values": self.singular_values_[2],
            "energy": np.asarray(self.energy_),
        }
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as handle:
                np.savez_compressed(handle, meta=np.array(json.dumps(meta)), **arrays)

    @classmethod
    def load(cls, path: str | os.PathLike) -> "MotionModel":
        """Read a model written by :meth:`save`."""
        path = Path(path)
        if not path.exists():
            raise MocapError("model file not found", path)
        try:
            with np.load(path, allow_pickle=False) as archive:
                meta = json.loads(str(archive["meta"]))
                arrays = {key: archive[key] for key in archive.files if key != "meta"}
        except (OSError, ValueError, KeyError, json.JSONDecodeError) as error:
            raise MocapError(f"not a motion model file (.npz from 'mocap decompose'): {error}",
                             path) from None
        if meta.get("format") != "mocap-motion-model":
            raise MocapError("not a motion model file (.npz from 'mocap decompose')", path)
        if int(meta.get("version", 0)) > FORMAT_VERSION:
            raise MocapError(f"model format version {meta['version']} is newer than this "
                             f"toolkit reads ({FORMAT_VERSION})", path)
        model = cls(people_rank=meta["people_rank"], action_rank=meta["action_rank"],
                    feature_rank=meta["feature_rank"], ridge=meta["ridge"],
                    timing_weight=meta["timing_weight"])
        for name in ("people", "actions", "segments", "parents", "columns", "sequence",
                     "samples", "markerset", "cycles", "cycle_column", "sources"):
            setattr(model, name, meta[name])
        model.timing_weight_ = float(meta["timing_weight_"])
        model.ridge_alpha_, model.ridge_ = float(meta["ridge_alpha"]), float(meta["ridge_value"])
        model.loo_rms_, model.spread_rms_ = float(meta["loo_rms"]), float(meta["spread_rms"])
        model.loo_table_ = {float(k): v for k, v in meta.get("loo_table", {}).items()}
        model.data_ = arrays["data"]
        model.basis_people_ = arrays["basis_people"].astype(int)
        model.action_mean_ = arrays["action_mean"]
        model.core_ = arrays["core"]
        model.factors_ = [arrays["people_factor"], arrays["action_factor"],
                          arrays["feature_factor"]]
        model.singular_values_ = [arrays["people_singular_values"],
                                  arrays["action_singular_values"],
                                  arrays["feature_singular_values"]]
        model.energy_ = [float(e) for e in arrays["energy"]]
        model.bases_ = action_bases(model.core_, model.factors_[1])
        model.signatures_ = arrays["signatures"]
        return model


def _cells_text(cells: Sequence[tuple[str, str]]) -> str:
    if not cells:
        return "none"
    shown = ", ".join(f"{p}_{a}" for p, a in cells[:12])
    return shown + (f" and {len(cells) - 12} more" if len(cells) > 12 else "")
