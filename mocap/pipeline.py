"""The recipes from a marker file to joint angles.

- :func:`marker_file_angles`: read, keep what the marker set uses, fill gaps, low-pass,
  segment frames, relative rotations, Euler angles;
- :func:`clinical_angles`: Plug-in Gait's clinical angles of a walk (with its static):
  subject values, gap filling inside each rigid segment, low-pass, the model.

``mocap angles``, ``mocap batch``, the corpus reader of :mod:`synthesis` and the demo all
call these, with the same defaults, so a trial gives the same angles whichever way it is
analysed, from Python or from the command line.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

from mocap.rotations.angles import DEFAULT_SEQUENCE, JointAngles, joint_angles
from mocap.errors import MocapError
from mocap.clean.filtering import lowpass
from mocap.clean.gapfill import GapReport, fill_gaps
from mocap.io import read
from mocap.markersets import MarkerSet
from mocap.trial import Trial


@dataclass(frozen=True)
class Cleaning:
    """How markers are cleaned before the angles.

    Attributes
    ----------
    max_gap_seconds, max_gap_frames : float, int, optional
        Fill marker gaps up to this long (:func:`mocap.clean.gapfill.fill_gaps`, rigid with the
        segment's other markers, else a cubic spline); give one or neither.
    lowpass_hz : float, optional
        Zero-lag Butterworth low-pass cut-off of the markers, Hz (after gap filling).
    order : int
        Butterworth order (run forward and backward: the response is squared).
    short_runs : str
        With ``lowpass_hz``, valid runs too short to filter: ``"error"``, ``"keep"`` or
        ``"drop"`` (see :func:`mocap.clean.filtering.lowpass`).
    """

    max_gap_seconds: float | None = None
    max_gap_frames: int | None = None
    lowpass_hz: float | None = None
    order: int = 4
    short_runs: str = "error"

    def __post_init__(self) -> None:
        if self.max_gap_seconds is not None and not self.max_gap_seconds >= 0:
            raise MocapError(f"max_gap_seconds must be >= 0 seconds, not {self.max_gap_seconds}")
        if self.max_gap_frames is not None and not self.max_gap_frames >= 0:
            raise MocapError(f"max_gap_frames must be >= 0 frames, not {self.max_gap_frames}")
        if self.lowpass_hz is not None and not (self.lowpass_hz > 0 and self.lowpass_hz < float("inf")):
            raise MocapError(f"lowpass_hz must be a positive frequency in Hz, not {self.lowpass_hz}")
        if self.order < 1:
            raise MocapError(f"order must be a positive whole number, not {self.order}")

    @property
    def fills(self) -> bool:
        """True when gap filling was asked for."""
        return bool(self.max_gap_seconds is not None or self.max_gap_frames)


@dataclass
class AnglesResult:
    """What :func:`marker_file_angles` produced.

    Attributes
    ----------
    trial : Trial
        The cleaned trial (only the markers the marker set reads).
    angles : JointAngles
        ``values`` (frames, segments, 3) degrees.
    gaps : GapReport or None
        The gap-filling report, when gaps were filled.
    """

    trial: Trial
    angles: JointAngles
    gaps: GapReport | None = field(default=None)


def used_markers(trial: Trial, markerset: MarkerSet) -> Trial:
    """``trial`` restricted to the labels ``markerset`` reads (Plug-in Gait files carry
    hundreds of model outputs stored as "markers"; cleaning them is wasted work)."""
    used = markerset.used_labels(trial.labels)
    if list(used) == list(trial.labels):        # all of them: share the array, no copy
        return trial
    return trial.select(used)


def clean_trial(trial: Trial, markerset: MarkerSet, cleaning: Cleaning = Cleaning()
                ) -> tuple[Trial, GapReport | None]:
    """Gap filling then low-pass, as ``cleaning`` asks; returns the trial and the gap report."""
    report = None
    if cleaning.fills:
        trial, report = fill_gaps(trial, max_gap_frames=cleaning.max_gap_frames or None,
                                  max_gap_seconds=cleaning.max_gap_seconds,
                                  donors=markerset.donors(trial.labels))
    if cleaning.lowpass_hz is not None:
        trial = lowpass(trial, cleaning.lowpass_hz, order=cleaning.order,
                        short_runs=cleaning.short_runs)
    return trial, report


def marker_file_angles(source: str | os.PathLike | Trial, markerset: MarkerSet,
                       sequence: str = DEFAULT_SEQUENCE, cleaning: Cleaning = Cleaning()
                       ) -> AnglesResult:
    """Joint angles of a marker trial (a file path or a :class:`Trial` already read).

    Parameters
    ----------
    source : path-like or Trial
        ``.c3d``, ``.trc`` or ``.csv`` marker file, or a trial.
    markerset : MarkerSet
        Segments (three markers each) and virtual markers.
    sequence : str
        Euler sequence, scipy convention (upper case intrinsic).
    cleaning : Cleaning
        Gap filling and low-pass before the angles.

    Returns
    -------
    AnglesResult
    """
    trial = source if isinstance(source, Trial) else read(source)
    markerset.check_trial(trial)
    trial, report = clean_trial(used_markers(trial, markerset), markerset, cleaning)
    return AnglesResult(trial, joint_angles(trial, markerset, sequence), report)


def clinical_angles(source: str | os.PathLike | Trial, static: str | os.PathLike | Trial | None = None,
                    *, cleaning: Cleaning = Cleaning(), flat_foot: bool | str = "auto",
                    subject=None, upper_body: bool = False) -> AnglesResult:
    """Plug-in Gait clinical angles of a walk, as ``mocap angles -m plugingait-lower`` gives them.

    The subject comes first (from the walk's recorded, never gap-filled, frames, its
    PROCESSING group and the static), then gap filling inside each rigid segment of the
    model, then the low-pass, then the model
    (:func:`mocap.plugingait.clinical.plugingait_angles`).

    Parameters
    ----------
    source : path-like or Trial
        The walk (``.c3d``, ``.trc`` or ``.csv``), points in metres once read.
    static : path-like or Trial, optional
        Standing trial of the same subject: calibrates the foot offsets, the tibial
        torsion, a knee alignment device and missing measurements.
    cleaning : Cleaning
        Gap filling (``max_gap_seconds`` or ``max_gap_frames``) and low-pass; none by
        default, as on the command line.
    flat_foot : bool or "auto"
        Plug-in Gait's foot-flat static option; ``"auto"`` (the command line's default)
        takes the choice a previous Plug-in Gait run stored in the files, else off.
    subject : mocap.plugingait.model.Subject, optional
        Measurements to use instead of the files' (see
        :func:`mocap.plugingait.clinical.prepare_subject`).
    upper_body : bool
        Also the upper body's angles (segments ``l_thorax … r_wrist`` after the lower
        body's, :mod:`mocap.plugingait.upper`),
        with the measurements of the walk's PROCESSING group, else the static's.
        Its thorax and head markers are gap-filled from their groups, the arms' by
        their splines (:func:`mocap.plugingait.clinical.fill_plugingait`).

    Returns
    -------
    AnglesResult
        ``angles`` with segments ``l_pelvis, l_hip, l_knee, l_ankle, l_foot_progress,
        r_…`` (then ``l_thorax … r_wrist`` with ``upper_body``) and axes ``flexion,
        adduction, rotation`` (degrees, Vicon's X, Y, Z of ``<Side><Joint>Angles``;
        ``<Side>FootProgressAngles``); ``trial``
        the cleaned Plug-in Gait markers; ``gaps`` the gap report when gaps were filled.
    """
    import numpy as np

    from mocap.plugingait.clinical import (fill_plugingait, plugingait_angles,
                                           plugingait_labels, prepare_subject)

    trial = source if isinstance(source, Trial) else read(source)
    if static is not None and not isinstance(static, Trial):
        static = read(static)
    upper_subject = None
    if upper_body:
        from mocap.plugingait.upper import upper_subject_from_trial

        upper_subject = upper_subject_from_trial(static, trial)
    trial = trial.select(plugingait_labels(trial, upper_body))
    subject = prepare_subject(trial, subject, static=static, flat_foot=flat_foot)
    report = None
    if cleaning.fills:
        limit = (cleaning.max_gap_frames if cleaning.max_gap_seconds is None
                 else int(np.floor(cleaning.max_gap_seconds * trial.rate + 1e-9)))
        trial, report = fill_plugingait(trial, subject, limit)
    if cleaning.lowpass_hz is not None:
        trial = lowpass(trial, cleaning.lowpass_hz, order=cleaning.order,
                        short_runs=cleaning.short_runs)
    return AnglesResult(trial, plugingait_angles(trial, subject=subject, upper_body=upper_body,
                                                 upper_subject=upper_subject), report)
