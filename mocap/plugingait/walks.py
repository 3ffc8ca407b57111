"""One walk through Plug-in Gait for a report: cycle curves, gait parameters, subject, notes.

:func:`analyse_walk` runs the model on a walk (with its static) as ``mocap angles``
does (``--upper-body`` too when the walk has those markers; the lower body's angles, foot
progression included, need none), or takes the outputs a previous Vicon run stored in the file
(``stored=True``), cuts them into gait cycles (:mod:`mocap.plugingait.curves`), computes
the gait-cycle parameters (:mod:`mocap.plugingait.parameters`) from the same events, and
keeps what the reader of a report must know: the subject's measurements and where each
came from, and every warning the model gave (as notes).
"""
from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field

import numpy as np

from mocap.errors import MocapError
from mocap.plugingait.curves import CycleCurves, angle_series, cycle_curves, stored_series
from mocap.plugingait.events import CYCLE_SAMPLES, gait_events
from mocap.trial import Trial


@dataclass
class WalkAnalysis:
    """What a report shows of one walk.

    Attributes
    ----------
    path : str
    curves : CycleCurves
        Angles (and moments, powers when there are any) per cycle.
    parameters : list of GaitParameters
        Left then right (:func:`mocap.plugingait.parameters.gait_parameters`).
    subject : list of tuple (str, str, str)
        Rows (measurement, value with unit, where it came from).
    notes : list of str
        The model's warnings and what was left out, one sentence each.
    origin : str
        ``"computed"`` (this toolkit's Plug-in Gait) or ``"stored"`` (Vicon's, in the file).
    subject_name : str
        From the C3D SUBJECTS group, else the file name.
    events : str
        ``"file"`` or ``"detected"`` (or both, ``"file, detected"``).
    """

    path: str
    curves: CycleCurves
    parameters: list
    subject: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    origin: str = "computed"
    subject_name: str = ""
    events: str = "file"


def _read(source) -> Trial:
    from mocap.io import read

    if isinstance(source, Trial):
        return source
    if not os.path.exists(source):
        raise MocapError("file not found", str(source))
    trial = read(source)
    if not isinstance(trial, Trial):
        raise MocapError("holds a skeleton motion, not marker trajectories", str(source))
    return trial


def _processing(trial: Trial | None, name: str) -> float | None:
    if trial is None:
        return None
    group = {str(k).upper(): v for k, v in (trial.parameters.get("PROCESSING") or {}).items()}
    try:
        value = float(np.ravel(group[name.upper()])[0])
    except (KeyError, TypeError, ValueError, IndexError):
        return None
    return value if np.isfinite(value) and value > 0 else None


def subject_name(trial: Trial) -> str:
    """The subject's name from the C3D SUBJECTS group, else the file's stem."""
    names = (trial.parameters.get("SUBJECTS") or {}).get("NAMES")
    if isinstance(names, (list, tuple)) and names and str(names[0]).strip():
        return str(names[0]).strip()
    return os.path.splitext(os.path.basename(trial.path or "walk"))[0]


def subject_rows(walk: Trial, static: Trial | None, used,
                 offsets_from: str = "static calibration") -> list[tuple[str, str, str]]:
    """The measurements a walk was processed with and their origin.

    ``used`` is the :class:`~mocap.plugingait.model.Subject` of the model: each value's
    origin is its ``sources`` entry ("static PROCESSING", "walk PROCESSING", "static
    medial markers", "estimated from the walk" …; a value without one is the walk's
    PROCESSING).  Body mass and height come from the static's PROCESSING group, else the
    walk's (as the kinetics take the body mass); ``offsets_from`` says where calibrated
    offsets came from.
    """
    rows = []
    for label, name, unit, scale in (("Body mass", "Bodymass", "kg", 1.0),
                                     ("Height", "Height", "m", 1e-3)):
        for trial, origin in ((static, "static PROCESSING"), (walk, "walk PROCESSING")):
            value = _processing(trial, name)
            if value is not None:
                rows.append((label, f"{value * scale:.3g} {unit}", origin))
                break
    if used is None:
        return rows

    def origin(key: str, side: str | None = None) -> str:
        return used.sources.get((key, side), "walk PROCESSING")

    if used.marker_diameter is not None:
        rows.append(("Marker diameter", f"{used.marker_diameter * 1000:.0f} mm",
                     origin("marker_diameter")))
    if used.inter_asis is not None:
        rows.append(("Inter-ASIS distance", f"{used.inter_asis * 1000:.0f} mm",
                     origin("inter_asis")))
    for label, key in (("Leg length", "leg_length"), ("Knee width", "knee_width"),
                       ("Ankle width", "ankle_width")):
        for side, side_name in (("l", "left"), ("r", "right")):
            value = getattr(used, key)[side]
            if value is not None:
                rows.append((f"{label}, {side_name}", f"{value * 1000:.0f} mm",
                             origin(key, side)))
    if used.calibrated:
        for label, key in (("Static plantar flexion offset", "static_plantar_flexion"),
                           ("Static rotation offset", "static_rotation_offset"),
                           ("Tibial torsion", "tibial_torsion")):
            for side, side_name in (("l", "left"), ("r", "right")):
                value = getattr(used, key)[side]
                measured = key == "tibial_torsion" and (key, side) in used.sources
                if value is not None:
                    rows.append((f"{label}, {side_name}", f"{np.degrees(value):.1f} deg",
                                 origin(key, side) if measured else offsets_from))
    elif offsets_from == "static calibration":      # computed without a static
        rows.append(("Foot offsets", "0 (uncorrected)", "no static trial"))
    return rows


def _has_upper_markers(trial: Trial) -> bool:
    from mocap.plugingait.model import markers_from_trial
    from mocap.plugingait.upper import UPPER_MARKERS

    return bool(markers_from_trial(trial, UPPER_MARKERS)[0])


def analyse_walk(source, static=None, *, stored: bool = False, flat_foot: bool | str = "auto",
                 body_mass: float | None = None, fill_gaps_s: float | None = None,
                 samples: int = CYCLE_SAMPLES) -> WalkAnalysis:
    """A walk's cycle curves, gait parameters, subject and notes.

    Parameters
    ----------
    source : path-like or Trial
        The walk (C3D for ``stored``; any marker file otherwise).
    static : path-like or Trial, optional
        Its static trial (calibration and measurements), as ``mocap angles --static``.
    stored : bool
        Take the outputs Vicon stored in the file (angles, moments, powers) instead of
        computing them; MocapError when the file has none.
    flat_foot : bool or "auto"
    body_mass : float, optional
        kg, for the kinetics (default the files' PROCESSING Bodymass).
    fill_gaps_s : float, optional
        Fill marker gaps up to this long, seconds, inside each rigid segment, as
        ``mocap angles --fill-gaps`` (:func:`mocap.pipeline.clinical_angles`); the kinetics
        use the filled markers too.
    samples : int
        Points per cycle.

    Returns
    -------
    WalkAnalysis
        MocapError when neither side has a complete cycle.
    """
    from mocap.plugingait.parameters import gait_parameters

    walk = _read(source)
    static_trial = _read(static) if static is not None else None
    path = walk.path or str(source)
    notes: list[str] = []
    used = None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if stored:
            series = stored_series(walk)
            if not any(name.endswith("Angles") for _, name in series):
                raise MocapError("holds no Plug-in Gait angles stored by Vicon (LHipAngles, "
                                 "…): run without --stored to compute them", path)
            origin = "stored"
        else:
            series, used = _computed_series(walk, static_trial, flat_foot, body_mass,
                                            fill_gaps_s, notes)
            origin = "computed"
        events = gait_events(walk)
        curves = cycle_curves(series, events, walk.frames, path, samples)
        parameters = gait_parameters(walk, events)
    if not curves.side:
        raise MocapError("no complete gait cycle: fewer than two foot strikes on each side "
                         "(the file has no EVENT group and the heel markers gave none)", path)
    for warning in caught:
        text = str(warning.message)
        if isinstance(warning.message, Warning) and issubclass(warning.category, UserWarning) \
                and text not in notes:
            notes.append(text)
    sources = sorted({e.source for e in events})
    if "detected" in sources:
        notes.append(f"{path}: gait events detected from the heel and toe markers (Zeni et "
                     f"al. 2008) where the file has fewer than two foot strikes a side; "
                     f"their foot off reads several % of the cycle later than a lab's "
                     f"labelled events (about 6 % on the real walks with both)")
    if stored and not any(name.endswith(("Moment", "Power")) for name in curves.values):
        notes.append(f"{path}: no joint moments or powers stored in the file")
    offsets_from = "static calibration"
    if stored:
        from mocap.plugingait.model import subject_from_trial

        used = subject_from_trial(walk, offsets=True, source="walk PROCESSING")
        offsets_from = "PROCESSING (Vicon's calibration)"
    rows = subject_rows(walk, static_trial, used, offsets_from)
    return WalkAnalysis(path, curves, parameters, rows, notes, origin, subject_name(walk),
                        ", ".join(sources))


def _computed_series(walk: Trial, static: Trial | None, flat_foot, body_mass, fill_gaps_s,
                     notes: list) -> tuple:
    """The walk's Plug-in Gait angles (and kinetics, on force plates) as series, and the
    subject the model used; kinetics that cannot be computed are a note."""
    from mocap.pipeline import Cleaning, clinical_angles
    from mocap.plugingait.clinical import plugingait_labels, prepare_subject
    from mocap.plugingait.kinetics import plugingait_kinetics

    upper = _has_upper_markers(walk)
    if not upper:
        notes.append(f"{walk.path}: no upper-body markers: no trunk, head or arm angles")
    result = clinical_angles(walk, static, cleaning=Cleaning(max_gap_seconds=fill_gaps_s),
                             flat_foot=flat_foot, upper_body=upper)
    if result.gaps is not None and result.gaps.unfilled:
        notes.append(f"{walk.path}: gaps left unfilled: "
                     + "; ".join(result.gaps.summary().splitlines()[:6]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # said once already, by clinical_angles
        used = prepare_subject(walk.select(plugingait_labels(walk)), static=static,
                               flat_foot=flat_foot, warn=False)
    series = angle_series(result.angles)
    try:
        kinetics = plugingait_kinetics(result.trial if result.gaps is not None else walk,
                                       used, static=static, body_mass=body_mass,
                                       flat_foot=flat_foot)
    except MocapError as error:
        notes.append(f"no joint moments or powers: {error}")
        return series, used
    series.update(kinetic_series(kinetics))
    return series, used


def kinetic_series(kinetics) -> dict:
    """A :class:`~mocap.plugingait.kinetics.JointKinetics` as series: ``(side,
    "HipMoment")`` -> (frames, 3) N·m/kg (its N·mm/kg / 1000), ``(side, "HipPower")`` ->
    (frames, 3) W/kg with the total power in Z (X, Y NaN), as Vicon stores them."""
    out = {}
    for k, segment in enumerate(kinetics.segments):
        side, _, joint = segment.partition("_")
        power = np.full(kinetics.moments[:, k].shape, np.nan)
        power[:, 2] = kinetics.powers[:, k]
        out[(side, f"{joint.capitalize()}Moment")] = kinetics.moments[:, k] / 1000.0
        out[(side, f"{joint.capitalize()}Power")] = power
    return out


__all__ = ["WalkAnalysis", "analyse_walk", "kinetic_series", "subject_name", "subject_rows"]
