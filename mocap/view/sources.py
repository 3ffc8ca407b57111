"""Files to a :class:`~mocap.view.scene.Scene`: marker trials, motions, angles, a check.

Marker files go through the one reader registry (:func:`mocap.io.read`), motions through
the one motion reader (:func:`mocap.io.motion.read_motion`), angle CSVs through
:func:`mocap.io.angles_csv.read_angles_csv`.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from mocap.errors import MocapError
from mocap.io import read, suffixes
from mocap.io.discovery import is_angle_csv
from mocap.markersets import MarkerSet
from mocap.view.page import View
from mocap.view.scene import (Layer, Scene, angle_curves, check_forces, marker_layer,
                              plate_tracks, scene_up, skeleton_layer, turn_force)

#: What ``mocap view`` shows, for messages.
KINDS = ".c3d, .trc or .csv markers, .bvh, .amc (with its .asf) or a joint-angle .csv"


def file_layers(path: str | os.PathLike, markerset: str | MarkerSet | None = "auto", asf=None,
                units: str | None = None, rate: float = 120.0, up: str = "auto"
                ) -> tuple[Layer, list, list[str]]:
    """One file's layer, its force plates (C3D) and notes.

    Parameters
    ----------
    path : path-like
        A marker trial (C3D/TRC/CSV) or a motion (BVH, AMC, joint-angle CSV).
    markerset : str, MarkerSet or None
        For marker trials: a marker set, preset name or TOML path, ``"auto"`` or None/``"none"``
        (:func:`~mocap.view.scene.marker_layer`).
    asf, units, rate
        As :func:`mocap.io.motion.read_motion` (AMC skeleton, BVH/ASF unit, AMC rate).
    up : {"auto", "z", "y"}
        Vertical axis of a marker trial.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    notes: list[str] = []
    if not path.exists():
        raise MocapError("file not found", path)
    if suffix in suffixes("markers") and not (suffix == ".csv" and is_angle_csv(path)):
        if suffix == ".csv" and _header(path).startswith("time,") and "." in _header(path):
            raise MocapError("holds joint angles without a skeleton to play them on (only "
                             "the 15-segment body's ZXY angles are): give it with angles= to "
                             "draw its curves below the scene", path)
        trial = read(path)
        if trial.frames == 0 or not trial.labels:
            raise MocapError(f"has no marker data to show ({trial.frames} frames, "
                             f"{len(trial.labels)} markers)", path)
        if not np.isfinite(trial.points).any():
            notes.append(f"{path.name}: no marker has data in any frame")
        plates = []
        if suffix == ".c3d":
            try:
                plates = plate_tracks(trial)
            except MocapError as error:            # markers still worth seeing
                notes.append(f"{path.name}: force plates not shown: {error.problem}")
        return marker_layer(trial, markerset, path.name, up), plates, notes
    if suffix in (".bvh", ".amc", ".asf", ".csv"):
        from mocap.io.motion import read_motion      # deferred: the motion readers (scipy)
        motion = read_motion(path, asf=asf, units=units, rate=rate)
        return skeleton_layer(motion, path.name), [], notes
    raise MocapError(f"cannot show this file: give {KINDS}", path)


def view_files(paths: list, angles: str | os.PathLike | None = None,
               curves: list[str] | None = None, check: str | os.PathLike | dict | None = None,
               markerset: str | MarkerSet | None = "auto", asf=None, units: str | None = None,
               rate: float = 120.0, up: str = "auto", title: str | None = None) -> View:
    """A :class:`~mocap.view.page.View` of files overlaid in one lab.

    Parameters
    ----------
    paths : list of path-like
        Marker trials and motions (:func:`file_layers`), one colour each.
    angles : path-like, optional
        Joint-angle CSV (``docs/formats/angles-csv.md``) drawn below the scene with a cursor at the frame.
    curves : list of str, optional
        Its columns to draw (default: the first six).
    check : path-like or dict, optional
        Output of ``mocap check --json``: its estimated ground reaction is drawn as an arrow.
    markerset, asf, units, rate, up
        See :func:`file_layers`.
    title : str, optional
        Default: the file names.

    Returns
    -------
    View
    """
    if not paths:
        raise MocapError("give at least one file to view")
    layers, plates, notes = [], [], []
    for path in paths:
        layer, found, said = file_layers(path, markerset, asf, units, rate, up)
        layers.append(layer)
        plates.append(found)
        notes += said
    lab = scene_up(layers)
    scene = Scene([layer.turned(lab) for layer in layers],
                  plates=[p.turned(lab, layer.up) for layer, found in zip(layers, plates)
                          for p in found],
                  notes=notes, up=lab,
                  title=title if title is not None else " + ".join(Path(p).name for p in paths))
    if angles is not None:
        from mocap.io.angles_csv import read_angles_csv
        scene.curves = angle_curves(read_angles_csv(angles), curves, angles)
    elif curves:
        raise MocapError("curves= chooses columns of angles=: give the angle CSV too")
    if check is not None:
        data = check if isinstance(check, dict) else _read_json(check)
        source = "check" if isinstance(check, dict) else os.fspath(check)
        scene.forces += [turn_force(track, lab) for track in check_forces(data, source)]
        scene.notes += check_notes(data)
    return View(scene)


def check_notes(check: dict) -> list[str]:
    """The verdict of a check's JSON in one short line (empty when it has none)."""
    if "verdict" not in check:
        return []
    residual = check.get("residual_force_rms_pct_bw")
    return [f"check: {check['verdict']}"
            + (f", residual {residual:.1f} % BW RMS" if isinstance(residual, (int, float)) else "")]


def _read_json(path) -> dict:
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MocapError("file not found", path) from None
    except (OSError, UnicodeDecodeError) as error:
        raise MocapError(f"cannot be read: {error}", path) from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as error:
        raise MocapError(f"is not JSON ({error.msg} at line {error.lineno})", path) from None


def _header(path: Path) -> str:
    """The first line of a text file (empty when unreadable: the reader says why)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as handle:
            return handle.readline(4096).strip()
    except OSError:
        return ""
