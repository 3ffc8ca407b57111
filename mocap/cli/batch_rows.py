"""The rows of ``mocap batch``: one trial -> file facts, joint-angle ranges of motion and,
on request, the humanoid dynamics check (so this module lives in the command shell: it is
where mocap meets dynamics)."""
from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np

from dynamics.humanoid.check import check_motion
from mocap import io
from mocap.body.retarget import motion_from_trial
from mocap.errors import MocapError, MocapWarning
from mocap.io.discovery import find_files, parse_trial_name
from mocap.markersets import load_markerset
from mocap.pipeline import marker_file_angles

#: Marker-file suffixes a corpus folder is searched for.
TRIAL_SUFFIXES = io.suffixes("markers")
#: First columns of every row; per-segment range-of-motion columns follow.
BASE_COLUMNS = ["path", "person", "action", "status", "error", "warnings", "format", "rate_hz", "frames",
                "duration_s", "markers", "missing_pct"]
CHECK_COLUMNS = ["residual_force_rms_pct_bw", "foot_skate_mm", "penetration_mm", "floating_mm",
                 "verdict"]


def find_trials(corpus: str | os.PathLike, recursive: bool = False) -> list[Path]:
    """Marker files inside ``corpus`` (a folder; with ``recursive`` its sub-folders too) or
    the file itself, sorted."""
    return find_files([corpus], TRIAL_SUFFIXES, recursive=recursive)


def pair_statics(walks: list[Path], statics: list[Path]) -> dict[str, str]:
    """Each walk's static trial: the first (sorted) static in the walk's own folder, else in
    a sibling folder of it (``Subject/Static/`` beside ``Subject/Straight/``). Walks without
    one are left out of the result.

    Returns
    -------
    dict
        walk path -> static path (strings).
    """
    pairs = {}
    for walk in walks:
        mine = [s for s in statics if s.parent == walk.parent] or \
            [s for s in statics if s.parent.parent == walk.parent.parent]
        if mine:
            pairs[str(walk)] = str(sorted(mine)[0])
    return pairs


def _first_columns(path: str, tree: bool = False) -> dict:
    """The columns every row starts with: path, person, action, status ``ok``, no error.

    Person and action come from a corpus name ``<person>_<action>…``; otherwise, in a
    ``Subject/Condition/trial`` tree (``tree``), from the two folders above the file."""
    try:
        person, action = parse_trial_name(path)
    except MocapError:                  # not a corpus name: the trial is analysed all the same
        person, action = ("", "") if not tree else \
            (Path(path).parent.parent.name, Path(path).parent.name)
    return {"path": str(path), "person": person, "action": action, "status": "ok",
            "error": "", "warnings": ""}


def lost_trial(path: str, problem: str) -> dict:
    """The row of a trial whose worker process died (``run_batch``'s ``lost``)."""
    return {**_first_columns(path), "status": "failed", "error": problem}


def _clinical_columns(path: str, static: str | None, max_gap_seconds: float | None) -> dict:
    """Plug-in Gait clinical angles of a walk (as ``mocap angles -m plugingait-lower
    --static``): each angle's minimum and maximum over the trial, degrees, as
    ``<segment>_<axis>_min_deg`` / ``_max_deg`` (``l_knee_flexion_max_deg``)."""
    from mocap.pipeline import Cleaning, clinical_angles

    angles = clinical_angles(path, static, cleaning=Cleaning(max_gap_seconds=max_gap_seconds)
                             ).angles
    row = {"static": static or ""}
    low, high = np.nanmin(angles.values, axis=0), np.nanmax(angles.values, axis=0)
    for s, segment in enumerate(angles.segments):
        for a, axis in enumerate(angles.axes):
            row[f"{segment}_{axis}_min_deg"] = round(float(low[s, a]), 3)
            row[f"{segment}_{axis}_max_deg"] = round(float(high[s, a]), 3)
    return row


def _number(value: float, decimals: int) -> float | str:
    """``value`` rounded; a NaN (nothing to compute) is an empty cell."""
    value = float(value)
    return round(value, decimals) if np.isfinite(value) else ""


def gait_columns(path: str, static: str | None, max_gap_seconds: float | None,
                 normative) -> dict:
    """A walk's gait-cycle parameters per side and its Gait Profile Score, as ``mocap
    report`` computes them (:func:`mocap.plugingait.walks.analyse_walk`,
    :func:`mocap.plugingait.scores.gait_scores`).

    Columns: ``Left Cycles``, ``Left Cadence (steps/min)`` … Vicon's names and units
    (:data:`mocap.plugingait.parameters.VICON_NAMES`, as ``mocap angles --parameters``)
    per side; ``GPS (deg)``, ``Left GPS (deg)``, ``Right GPS (deg)`` and ``Left GVS Hip
    flexion (deg)`` … against ``normative``
    (:class:`~mocap.plugingait.normative.Normative`); ``events`` (``file`` or
    ``detected``); ``notes``: the model's notes, ``"; "``-separated. A walk without a
    complete gait cycle keeps the parameters its events allow (NaN: empty), no scores,
    and says why in ``notes``.
    """
    from dataclasses import asdict

    from mocap.plugingait.parameters import VICON_NAMES, gait_parameters
    from mocap.plugingait.scores import gait_scores
    from mocap.plugingait.walks import analyse_walk

    row: dict = {}
    scores = None
    try:
        analysis = analyse_walk(path, static, fill_gaps_s=max_gap_seconds)
    except MocapError as error:         # no complete cycle: what the events still give
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            parameters, notes, events = gait_parameters(io.read(path)), [str(error)], ""
    else:
        parameters, notes, events = analysis.parameters, list(analysis.notes), analysis.events
        try:
            scores = gait_scores(analysis.curves, normative)
        except MocapError as error:
            notes.append(f"no Gait Profile Score: {error}")
        else:
            if scores.missing:
                notes.append(f"{path}: Gait Profile Score without "
                             f"{', '.join(scores.missing)} (no cycle has them)")
    row["events"] = events
    for p in parameters:
        context = {"l": "Left", "r": "Right"}[p.side]
        values = asdict(p)
        row[f"{context} Cycles"] = p.cycles
        for key, (name, unit) in VICON_NAMES.items():
            row[f"{context} {name} ({unit})"] = _number(values[key], 4)
    if scores is not None:
        row["GPS (deg)"] = _number(scores.overall, 3)
        for side, context in (("l", "Left"), ("r", "Right")):
            row[f"{context} GPS (deg)"] = _number(scores.gps[side], 3)
        for side, context in (("l", "Left"), ("r", "Right")):
            for title, value in zip(scores.titles, scores.gvs[side]):
                row[f"{context} GVS {title} (deg)"] = _number(value, 3)
    row["notes"] = "; ".join(notes)
    return row


def analyse_trial(path: str, markerset: str | None = None, sequence: str = "ZXY",
                  check: bool = False, mass_kg: float = 75.0,
                  lowpass: float | None = 6.0, tree: bool = False, clinical: bool = False,
                  statics: dict | None = None, max_gap_seconds: float | None = None,
                  gait: bool = False, normative=None) -> dict:
    """One row of the batch table for the trial at ``path``; never raises for bad input.

    Parameters
    ----------
    path : str
        Marker file.
    markerset : str, optional
        Preset name or TOML path; with it, joint-angle ranges of motion are added
        as ``<segment>_rom_deg`` (largest range of the three angles, degrees).
    sequence : str
        Euler sequence for the angles.
    check : bool
        Also run the humanoid dynamics check (needs a full-body marker set).
    mass_kg : float
        Body mass for the check.
    lowpass : float or None, Hz
        Low-pass of the motion before the check's inverse dynamics (None or 0: off).
    tree : bool
        Person and action from the ``Subject/Condition/`` folders when the file's name is
        not ``<person>_<action>``.
    clinical : bool
        Plug-in Gait clinical angles (:func:`_clinical_columns`), calibrated with the
        trial's static from ``statics`` (path -> static path; none: uncalibrated, said in
        ``warnings``).
    max_gap_seconds : float, optional
        Gap filling before the clinical angles.
    gait : bool
        With ``clinical``: also the gait-cycle parameters and scores
        (:func:`gait_columns`) against ``normative``
        (:class:`~mocap.plugingait.normative.Normative`).

    Returns
    -------
    dict
        Column → value; ``status`` is ``"ok"`` or ``"failed"`` with ``error`` set;
        ``warnings`` holds the reader's warnings, ``"; "``-separated.
    """
    row = _first_columns(path, tree)
    try:
        # the reader's warnings travel in the row (workers' warnings would be lost), and
        # ``mocap batch`` prints them
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", MocapWarning)
            trial = io.read(path)
        row["warnings"] = "; ".join(str(w.message) for w in caught
                                    if issubclass(w.category, MocapWarning))
        missing = np.isnan(trial.points).any(axis=2).mean() if trial.points.size else 0.0
        row.update(format=trial.format, rate_hz=round(trial.rate, 6), frames=trial.frames,
                   duration_s=round(trial.duration, 6) if trial.rate > 0 or trial.frames <= 1 else "", markers=len(trial.labels),
                   missing_pct=round(100.0 * float(missing), 3))
        if clinical:
            static = (statics or {}).get(str(path))
            row.update(_clinical_columns(path, static, max_gap_seconds))
            if static is None:
                row["warnings"] = "; ".join(filter(None, [
                    row["warnings"], "no static trial beside it: uncalibrated clinical angles "
                    "(give --static, or put it in a Static folder beside the walk's)"]))
            if gait:
                row.update(gait_columns(path, static, max_gap_seconds, normative))
        if markerset:
            chosen = load_markerset(markerset)
            angles = marker_file_angles(trial, chosen, sequence).angles
            ranges = np.nanmax(angles.values, axis=0) - np.nanmin(angles.values, axis=0)
            for segment, span in zip(angles.segments, np.nanmax(ranges, axis=1)):
                row[f"{segment}_rom_deg"] = round(float(span), 3)
            if check:
                report = check_motion(motion_from_trial(trial, chosen), body_mass=mass_kg,
                                      lowpass=lowpass or None).summary()
                for key in CHECK_COLUMNS:
                    value = report[key]
                    row[key] = round(value, 3) if isinstance(value, float) else value
    except MocapError as error:
        row.update(status="failed", error=str(error))
    except Exception as error:  # a bug of ours or a file no reader anticipated: report, go on
        row.update(status="failed", error=f"{path}: {type(error).__name__}: {error}")
    return row
