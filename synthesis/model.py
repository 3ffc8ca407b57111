"""``MotionModel``: the motion-signature model fitted from a corpus (arrays in, arrays out;
its files are :mod:`synthesis.model_file`).

Two :class:`synthesis.regression.SignatureModel` share the corpus' people and actions:

* the **angle model**: each captured (person, action) cell is the time-normalised cycle
  flattened frame-major (samples × angle columns, degrees);
* the **timing model**: each cell is the logarithm of the cycle duration (so a person's
  cadence, a factor on every action's duration, becomes additive), with its own signature,
  ranks and ridge, so synthesised motions get their own predicted duration.

See :mod:`synthesis.regression` for the method (bases from the complete people, centred N-mode
SVD, signatures by ridge least squares, rank and ridge chosen by leave-one-out).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from mocap.rotations.angles import JointAngles
from mocap.errors import MocapError
from synthesis.corpus import MotionCorpus, check_corpus_size
from mocap.clean.resample import resample
from synthesis.cycles import MISALIGNED_FRACTION, CycleWarning, cycle_phase_lags, mean_cycle
from synthesis.methods import CellMethod, make_method, method_name
from synthesis.nmode import Rank
from synthesis.recognition import Recognition, distances, recognize, unknown_limit
from synthesis.regression import SignatureModel
from synthesis.rotations import hierarchy_known, remove_mean_heading
from synthesis.signature import interpolate_signatures
from synthesis.skeletons import cycle_motion
from synthesis.transfer import TransferModel

#: File format version written into saved models.
FORMAT_VERSION = 2


@dataclass
class MotionModel:
    """People × actions motion model (Vasilescu's motion signatures), scikit-learn style.

    Parameters
    ----------
    people_rank, action_rank, feature_rank : int, float or None
        Ranks of the angle model's modes: a count, a kept-energy fraction in (0, 1], or
        ``None`` (people: chosen by leave-one-out; actions, features: numerical rank).
    ridge : float or "auto"
        Relative ridge α of the angle signature fits, or ``"auto"`` (leave-one-out).
    method : {"auto", "interaction", "signature", "transfer"}
        How a person's missing cell is synthesised: a name of
        :data:`synthesis.methods.METHODS` (``"auto"`` = ``"interaction"``, the additive
        model corrected by the N-mode SVD of the person × action interaction, rank 0 being
        the additive model itself). Blends and new people always use the signatures of
        :class:`synthesis.regression.SignatureModel`.

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
    method: str = "auto"

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
    cleaning: dict = field(default_factory=dict, init=False)
    angle_model_: SignatureModel | None = field(default=None, init=False, repr=False)
    timing_model_: SignatureModel | None = field(default=None, init=False, repr=False)
    spread_rms_: float = field(default=float("nan"), init=False)
    method_: str = field(default="signature", init=False)
    cells_: CellMethod | None = field(default=None, init=False, repr=False)
    timing_cells_: CellMethod | None = field(default=None, init=False, repr=False)
    timing_transfer_: TransferModel | None = field(default=None, init=False, repr=False)
    root_transfer_: TransferModel | None = field(default=None, init=False, repr=False)
    representation: str = field(default="euler", init=False)
    rotation_means: np.ndarray | None = field(default=None, init=False, repr=False)
    rig: dict | None = field(default=None, init=False, repr=False)
    heading_removed: bool = field(default=False, init=False)

    # ------------------------------------------------------------------ fitting

    def fit(self, corpus: MotionCorpus, cache: dict | None = None) -> "MotionModel":
        """Fit the model to a corpus.

        Parameters
        ----------
        corpus : MotionCorpus
            At least 2 people and 2 actions, at least 2 people with every action.
        cache : dict, optional
            Shared between fits to corpora that differ only in one person's cells (see
            :meth:`synthesis.regression.SignatureModel.fit`); used by leave-one-out.

        Returns
        -------
        self
        """
        check_corpus_size(corpus.people, corpus.actions)
        self.method_ = method_name(self.method)
        self.people, self.actions = list(corpus.people), list(corpus.actions)
        self.segments, self.parents = list(corpus.segments), list(corpus.parents)
        self.columns, self.sequence = list(corpus.columns), corpus.sequence
        self.samples, self.markerset = corpus.samples, corpus.markerset
        self.cycles, self.cycle_column = corpus.cycles, corpus.cycle_column
        self.sources = {f"{p}_{a}": list(v) for (p, a), v in corpus.sources.items()}
        self.cleaning = dict(corpus.cleaning)
        observed = corpus.observed
        complete = np.flatnonzero(observed.all(axis=1))
        angles = corpus.angles.reshape(corpus.angles.shape[:2] + (-1,)).copy()
        angles[~observed] = np.nan
        self.representation, self.rig = corpus.representation, corpus.rig
        self.rotation_means = corpus.rotation_means
        self.heading_removed = corpus.heading_removed
        with np.errstate(invalid="ignore", divide="ignore"):
            timing = np.log(np.where(corpus.durations > 0, corpus.durations, np.nan))[..., None]
        if corpus.phases is not None:
            timing = np.concatenate([timing, corpus.phases[..., None]], axis=2)
        if np.any(observed & ~np.isfinite(timing[..., 0])):
            raise MocapError("every captured cycle needs a positive duration")
        caches = (None, None) if cache is None else \
            (cache.setdefault("angles", {}), cache.setdefault("timing", {}))
        try:
            self.angle_model_ = SignatureModel(self.people_rank, self.action_rank,
                                               self.feature_rank, self.ridge).fit(angles,
                                                                                  caches[0])
            self.timing_model_ = SignatureModel().fit(timing, caches[1])
        except MocapError as error:
            raise MocapError(f"{error.problem}; missing cells: "
                             f"{_cells_text(corpus.missing_cells())} "
                             "(choose people= or actions=)") from None
        self.fit_methods(angles, timing, None if corpus.root is None else
                         corpus.root.reshape(corpus.root.shape[:2] + (-1,)))
        complete = complete if complete.size else np.arange(len(self.people))
        deviations = np.where(observed[complete][..., None], angles[complete], np.nan) \
            - self.angle_model_.mean_
        self.spread_rms_ = float(np.sqrt(np.nanmean(deviations ** 2)))
        return self

    def fit_methods(self, angles: np.ndarray, timing: np.ndarray,
                    root: np.ndarray | None = None) -> None:
        """Fit the synthesis method (:attr:`method_`) to the angle and timing cells, and the
        action transfer of the mid-cycle phase and the root motion (the signature models must
        be fitted already; :func:`synthesis.model_file.load_model` calls this too).

        Parameters
        ----------
        angles : ndarray, shape (people, actions, samples · columns), degrees, NaN if missing
        timing : ndarray, shape (people, actions, 1 or 2)
            Log duration (and the mid-cycle phase).
        root : ndarray, shape (people, actions, samples · 4), optional
        """
        self.cells_ = make_method(self.method_).fit(angles, self.angle_model_,
                                                    samples=self.samples or None)
        self.timing_cells_ = make_method(self.method_).fit(timing, self.timing_model_)
        self.timing_transfer_ = TransferModel().fit(timing)
        self.root_transfer_ = None if root is None else TransferModel().fit(root)


    # ------------------------------------------------------------------ using the model

    def _check_fitted(self) -> None:
        if self.angle_model_ is None:
            raise MocapError("the motion model is not fitted")

    def person_index(self, person: str) -> int:
        """Index of a person (MocapError naming the known people)."""
        self._check_fitted()
        if person not in self.people:
            raise MocapError(f"unknown person {person!r}; the model knows "
                             f"{', '.join(self.people)}")
        return self.people.index(person)

    def action_index(self, action: str) -> int:
        """Index of an action (MocapError naming the known actions)."""
        self._check_fitted()
        if action not in self.actions:
            raise MocapError(f"unknown action {action!r}; the model knows "
                             f"{', '.join(self.actions)}")
        return self.actions.index(action)

    @property
    def loo_rms(self) -> float:
        """Leave-one-out RMS synthesis error of the angle model, degrees (NaN if unknown)."""
        return self.angle_model_.loo_rms_

    def signature(self, person: str) -> "Signature":
        """Signature of a known person (angles and timing)."""
        index = self.person_index(person)
        return Signature(self.angle_model_.signatures_[index],
                         self.timing_model_.signatures_[index])

    def signature_from(self, observations: Sequence[tuple[str, np.ndarray, float]]
                       ) -> "Signature":
        """Signature of a (new) person from captured cycles.

        Parameters
        ----------
        observations : sequence of (action, curve (samples, columns) degrees, duration s)

        Returns
        -------
        Signature
        """
        self._check_fitted()
        actions = [self.action_index(action) for action, _, _ in observations]
        curves = np.stack([np.asarray(curve, float).ravel() for _, curve, _ in observations])
        durations = np.array([float(duration) for _, _, duration in observations])
        if curves.shape[1] != self.samples * len(self.columns):
            raise MocapError(f"cycles must have {self.samples} samples of {len(self.columns)} "
                             "angles")
        if np.any(~(durations > 0)):
            raise MocapError("cycle durations must be positive")
        return Signature(self.angle_model_.signature_from(actions, curves),
                         self.timing_model_.signature_from(actions, np.log(durations)[:, None]))

    def interpolate(self, first: str, second: str, weight: float) -> "Signature":
        """Signature ``(1 − w) s_first + w s_second`` (angles and timing)."""
        a, b = self.signature(first), self.signature(second)
        return Signature(interpolate_signatures(a.angles, b.angles, weight),
                         interpolate_signatures(a.timing, b.timing, weight))

    def synthesize(self, person: str | None, action: str, signature: "Signature | None" = None,
                   samples: int | None = None) -> tuple[np.ndarray, float]:
        """One cycle of a person (or a signature) doing an action.

        Parameters
        ----------
        person : str or None
            Known person (ignored when ``signature`` is given).
        action : str
        signature : Signature, optional
        samples : int, optional
            Frames of the returned cycle (default: the model's sample count).

        Returns
        -------
        curve : ndarray, shape (samples, columns), degrees
        duration : float
            Predicted cycle duration, seconds.
        """
        if signature is None and person is not None:
            p, index = self.person_index(person), self.action_index(action)
            curve = self._synthesised_cell(p, index).reshape(self.samples, len(self.columns))
            duration = float(np.exp(self._synthesised_cell(p, index, timing=True)[0]))
        else:
            if signature is None:
                if person is None:
                    raise MocapError("give a person or a signature to synthesise")
                signature = self.signature(person)
            index = self.action_index(action)
            curve = self.angle_model_.predict(signature.angles, index).reshape(
                self.samples, len(self.columns))
            duration = float(np.exp(self.timing_model_.predict(signature.timing, index)[0]))
        if samples is not None and samples != self.samples:
            if samples < 2:
                raise MocapError(f"samples must be at least 2, got {samples}")
            curve = resample(np.linspace(0.0, 1.0, self.samples), curve, 0.0, 1.0, samples)
        return curve, duration

    @staticmethod
    def _cell(model: TransferModel, person: int, action: int) -> np.ndarray:
        """A captured cell as it is, a missing one by action transfer."""
        if model.observed_[person, action]:
            return model.data_[person, action]
        return model.predict(person, action)[0]

    def _synthesised_cell(self, person: int, action: int, timing: bool = False) -> np.ndarray:
        """A captured cell (angles, or ``timing``) as it is, a missing one from the method."""
        return (self.timing_cells_ if timing else self.cells_).cell(person, action)

    def synthesize_root(self, person: str | None, action: str) -> np.ndarray:
        """Root motion of a cycle in the heading frame, shape (samples, 4)
        (:data:`synthesis.rotations.ROOT_FEATURES`; skeleton corpora only): the person's by
        action transfer, or (``person=None``, e.g. for a blend) the action's mean."""
        if self.root_transfer_ is None:
            raise MocapError("this model has no root motion (it was not built from skeleton "
                             "trials)")
        a = self.action_index(action)
        model = self.root_transfer_
        if person is None:
            return np.nanmean(np.where(model.observed_[:, a, None], model.data_[:, a], np.nan),
                              axis=0).reshape(self.samples, -1)
        return self._cell(model, self.person_index(person), a).reshape(self.samples, -1)

    def synthesize_motion(self, person: str | None, action: str,
                          signature: "Signature | None" = None, cycles: int = 1):
        """A synthesised cycle as a :class:`mocap.skeleton.Motion` on the corpus' rig: joint
        rotations back from their features, the root path integrated from the root motion
        (skeleton corpora only).

        Parameters
        ----------
        person, action, signature
            As :meth:`synthesize`.
        cycles : int
            Repetitions of the cycle.
        """
        if self.representation != "rotvec":
            raise MocapError("only models of skeleton corpora (BVH, ASF/AMC) know their rig")
        curve, duration = self.synthesize(person, action, signature)
        root = self.synthesize_root(person if signature is None else None, action)
        phase = None
        if self.cycles and self.timing_transfer_.data_.shape[2] > 1 and person is not None \
                and signature is None:
            phase = float(self._cell(self.timing_transfer_, self.person_index(person),
                                     self.action_index(action))[1])
        return cycle_motion(self.rig, self.rotation_means, curve, root, duration, cycles, phase)

    def synthesize_angles(self, person: str | None, action: str,
                          signature: "Signature | None" = None, samples: int | None = None):
        """:meth:`synthesize` as :class:`mocap.rotations.angles.JointAngles` whose times span the duration."""
        curve, duration = self.synthesize(person, action, signature, samples)
        times = np.linspace(0.0, duration, curve.shape[0])
        return JointAngles(times=times, values=curve.reshape(curve.shape[0], -1, 3),
                           segments=list(self.segments), sequence=self.sequence,
                           parents=list(self.parents))

    def normalise(self, angles) -> tuple[np.ndarray, float]:
        """Time-normalise joint angles the way the corpus was (samples, cycles, reference).

        Parameters
        ----------
        angles : mocap.rotations.angles.JointAngles
            Turned by its mean heading first when the corpus' trials were
            (:attr:`heading_removed`; a trial of unknown hierarchy is refused then).

        Returns
        -------
        curve : ndarray, shape (samples, columns), degrees
        duration : float, seconds
        """
        self._check_fitted()
        if list(angles.segments) != list(self.segments):
            raise MocapError(f"trial segments ({', '.join(angles.segments)}) differ from the "
                             f"model's ({', '.join(self.segments)})")
        if angles.sequence != self.sequence:
            raise MocapError(f"trial angles use the Euler sequence {angles.sequence}, the model "
                             f"{self.sequence}")
        if self.heading_removed and self.representation == "euler":
            if not hierarchy_known(angles):
                raise MocapError("the model's corpus had its heading removed, and this "
                                 "trial's segment hierarchy is unknown (an angle CSV: give "
                                 "the model's marker set)")
            angles = remove_mean_heading(angles)
        values = np.asarray(angles.values, dtype=float)
        reference = self.columns.index(self.cycle_column) if self.cycle_column else None
        curve, duration, _ = mean_cycle(np.asarray(angles.times, dtype=float),
                                        values.reshape(values.shape[0], -1), self.samples,
                                        self.cycles, reference)
        return curve, duration

    def distances(self, curve: np.ndarray, actions: Sequence[int] | None = None) -> np.ndarray:
        """Weighted mean absolute difference (degrees) between a cycle (samples, columns) and
        every person's motion of every action, shape (people, actions), NaN where unknown
        (:func:`synthesis.recognition.distances`)."""
        self._check_fitted()
        return distances(self.cells_, curve, actions)

    def unknown_limit(self, action: str) -> float:
        """Distance (degrees) beyond which a trial of ``action`` is nobody known
        (:func:`synthesis.recognition.unknown_limit`; NaN: no limit)."""
        self._check_fitted()
        return unknown_limit(self.cells_, self.action_index(action))

    def recognize(self, curve: np.ndarray, action: str | None = None) -> Recognition:
        """Most likely person (and action) of a captured cycle (samples, columns), degrees
        (:func:`synthesis.recognition.recognize`; ``action``: the trial's when known)."""
        candidates = [self.action_index(action)] if action is not None \
            else list(range(len(self.actions)))
        return recognize(self.cells_, self.people, self.actions, curve, candidates)

    def check_cycle_phase(self, curve: np.ndarray, action: str, source: str | None = None
                          ) -> float:
        """Lag (fraction of a cycle) at which a new trial's cycle best matches the model's
        captures of ``action`` (:func:`synthesis.cycles.cycle_phase_lags`); a
        :class:`~synthesis.cycles.CycleWarning` names the trial beyond
        :data:`~synthesis.cycles.MISALIGNED_FRACTION` (cut at another event of the
        movement). NaN, and no check, for a model of whole trials, an action whose
        captures were not cut into cycles (a wave in a corpus of walks), or with fewer than
        two captures of the action; the caller checks only trials it cut.

        Parameters
        ----------
        curve : ndarray, shape (samples, columns)
        action : str
        source : str, optional
            The trial's file, for the warning.
        """
        self._check_fitted()
        a = self.action_index(action)
        data, observed = self.cells_.data_, self.cells_.observed_
        cut = (self.rig or {}).get("cut_actions") if self.representation == "rotvec" \
            else self.actions
        if not self.cycles or observed[:, a].sum() < 2 or action not in (cut or ()):
            return float("nan")
        shape = np.asarray(curve).shape
        captures = data[observed[:, a], a].reshape((-1,) + shape)
        lag = float(cycle_phase_lags(np.concatenate([captures, np.asarray(curve)[None]]))[-1])
        if abs(lag) > MISALIGNED_FRACTION:
            warnings.warn(f"{source or 'trial'}: its cycle matches the model's {action!r} "
                          f"best when shifted by {100 * abs(lag):.0f} % of a cycle — cut at "
                          "another event of the movement? Its answer may be wrong",
                          CycleWarning, stacklevel=2)
        return lag

    # ------------------------------------------------------------------ persistence

    def summary(self) -> dict:
        """Plain description of the fitted model (for printing and JSON)."""
        self._check_fitted()
        angle, timing = self.angle_model_, self.timing_model_
        observed = angle.observed
        return {
            "people": list(self.people), "actions": list(self.actions),
            "segments": len(self.segments), "columns": len(self.columns),
            "sequence": self.sequence, "samples": self.samples, "markerset": self.markerset,
            "cycles": self.cycles, "cycle_column": self.cycle_column,
            "cleaning": self.cleaning, "missing_cells": [f"{self.people[p]}_{self.actions[a]}"
                              for p, a in np.argwhere(~observed)],
            "basis_people": [self.people[i] for i in angle.basis_people_],
            "imputed_people_rank": angle.imputed_rank_,
            "ranks": [int(f.shape[1]) for f in angle.factors_],
            "energy": [float(e) for e in angle.energy_],
            "ridge_alpha": angle.ridge_alpha_, "loo_rms_deg": angle.loo_rms_,
            "spread_rms_deg": self.spread_rms_,
            "method": self.method_, "representation": self.representation,
            "heading_removed": self.heading_removed,
            "interaction": self._interaction_summary(),
            "missing_cells_filled_by": {
                f"{self.people[p]}_{self.actions[a]}": self.cells_.filled_by(int(p), int(a))
                for p, a in np.argwhere(~observed)},
            "timing_rank": timing.rank, "timing_ridge_alpha": timing.ridge_alpha_,
            "timing_loo_rms_log": timing.loo_rms_,
        }

    def _interaction_summary(self) -> dict:
        """Action → the interaction configuration that predicts it from all other actions
        (with the ridge map, ``map_weights``: other action → its weight)."""
        summary = {}
        for a, chosen in self.cells_.describe().items():
            if "map_weights" in chosen:
                chosen = {**chosen, "map_weights": {self.actions[b]: w for b, w
                                                    in chosen["map_weights"].items()}}
            summary[self.actions[a]] = chosen
        return summary


@dataclass
class Signature:
    """A person's motion signature: one vector per sub-model.

    Attributes
    ----------
    angles : ndarray, shape (r_angles,)
        Coefficients of the angle model's action bases.
    timing : ndarray, shape (r_timing,)
        Coefficients of the timing (log-duration) model's action bases.
    """

    angles: np.ndarray
    timing: np.ndarray


def _cells_text(cells: Sequence[tuple[str, str]]) -> str:
    if not cells:
        return "none"
    shown = ", ".join(f"{p}_{a}" for p, a in cells[:12])
    return shown + (f" and {len(cells) - 12} more" if len(cells) > 12 else "")
