"""C3D writing (with ezc3d): markers, analogs, events, segment poses and the source's parameters.

Points are stored as 32-bit floats in the chosen unit; a missing sample is residual −1.
A trial read from a C3D file keeps its first frame, EVENT group and every parameter group
its data still match (:mod:`mocap.io.c3d.parameters`); :func:`write_c3d` returns, one
phrase each, what it could not keep.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from mocap.atomic import atomic_path
from mocap.errors import MocapError
from mocap.io import require_rate
from mocap.io.c3d.layout import inspect_c3d
from mocap.io.c3d.parameters import _set as set_parameter
from mocap.io.c3d.parameters import carry_parameters, offsets_to_keep, patch_int_parameter
from mocap.io.c3d.read import unit_factor
from mocap.trial import Trial


def _analog_gain(group: dict, channels: int) -> np.ndarray:
    """SCALE × GEN_SCALE per channel (what one stored unit is worth), shape (channels,)."""
    scale = np.ones(channels)
    value = group.get("SCALE")
    if isinstance(value, np.ndarray) and value.size:
        flat = value.reshape(-1)[:channels].astype(float)
        scale[:flat.size] = flat
    gen = group.get("GEN_SCALE")
    gen = float(gen.reshape(-1)[0]) if isinstance(gen, np.ndarray) and gen.size else 1.0
    return scale * gen


def _check_written(written: Path, markers: int, frames: int, path) -> None:
    """MocapError unless ``written`` holds all ``frames`` of ``markers`` points.

    ezc3d's writer does not report a failed write (a full disk, a file-size limit): the
    file it leaves is cut short, or empty, and was renamed into place as if complete.
    """
    try:
        layout = inspect_c3d(written)
        complete = (layout.point_count == markers and layout.frames == frames
                    and layout.file_size >= layout.data_offset + frames * layout.frame_bytes)
    except MocapError:
        complete = False
    if not complete:
        size = written.stat().st_size if written.exists() else 0
        raise MocapError(f"cannot write C3D: the file came out incomplete ({size} bytes "
                         "written: no space left on the device, or a file-size limit)", path)


#: POINT unit parameters of each kind of output, as Vicon Nexus writes them.
OUTPUT_UNITS = {"ANGLES": ("ANGLE_UNITS", "deg"), "FORCES": ("FORCE_UNITS", "N"),
                "MOMENTS": ("MOMENT_UNITS", "Nmm"), "POWERS": ("POWER_UNITS", "W"),
                "SCALARS": ("SCALAR_UNITS", "mm")}


def write_c3d(trial: Trial, path: str | os.PathLike, units: str = "mm", *,
              outputs: list | None = None, groups: dict | None = None) -> list[str]:
    """Write a trial's markers (and analogs) to a C3D file with ezc3d.

    Parameters
    ----------
    trial : Trial
        ``points`` (frames, markers, 3) in metres, NaN where missing.
    path : str or PathLike
        Written all-or-nothing (temporary file, then rename).
    units : {"mm", "cm", "m"}
        Length unit stored in the file (POINT:UNITS); points are converted.
    outputs : list of (label, kind, values), optional
        Model outputs written after the markers as points, unconverted: ``kind`` one of
        ANGLES, FORCES, MOMENTS, POWERS, SCALARS (listed in that POINT parameter, with
        its unit parameter as Vicon writes it, :data:`OUTPUT_UNITS`), ``values``
        (frames, 3) in those units, NaN where invalid (residual -1).
    groups : dict, optional
        ``{group: {name: value}}`` parameters set last (over any kept from the source),
        e.g. an ANALYSIS group.

    Returns
    -------
    list of str
        What of the source file's parameters could not be kept (see
        :mod:`mocap.io.c3d.parameters`); empty when everything was.

    Missing samples are written as residual -1 with zero coordinates, the C3D
    convention; the data are stored as 32-bit floats (POINT:SCALE -1). Analogs
    (when their rate is a whole multiple of the point rate), ``events``
    (at their times from the capture's start), the first frame
    (``first_frame``) and every parameter group of a C3D source that
    the written data still match are written too.
    """
    import ezc3d   # deferred: reading C3D needs no ezc3d, only writing does

    factor = unit_factor(units)
    if factor is None or units not in ("mm", "cm", "m"):
        raise MocapError(f"cannot write C3D in units {units!r} (use mm, cm or m)", path)
    outputs = list(outputs or [])
    for _, kind, values in outputs:
        if kind not in OUTPUT_UNITS or np.shape(values) != (trial.frames, 3):
            raise MocapError(f"an output must be {'/'.join(OUTPUT_UNITS)} with "
                             f"({trial.frames}, 3) values", path)
    labels = list(trial.labels) + [label for label, _, _ in outputs]
    if len(set(labels)) != len(labels) or any(len(label) == 0 for label in labels):
        raise MocapError("marker labels must be unique and non-empty to write C3D", path)
    too_long = [label for label in labels if len(label.encode("utf-8")) > 255]
    if too_long:
        raise MocapError(f"C3D labels hold at most 255 bytes; {too_long[0][:40]!r}… is "
                         f"longer", path)
    require_rate(trial, path, "C3D file")
    frames, markers = trial.frames, len(labels)
    if frames == 0:
        raise MocapError("cannot write a C3D file without frames", path)
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [float(trial.rate)]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = labels
    c3d.add_parameter("POINT", "UNITS", [units])
    values = np.ones((4, markers, frames))
    coordinates = trial.points.transpose(2, 1, 0) / factor
    if outputs:
        extra = np.stack([np.asarray(v, dtype=float) for _, _, v in outputs], axis=1)
        coordinates = np.concatenate([coordinates, extra.transpose(2, 1, 0)], axis=1)
    missing = ~np.isfinite(coordinates).all(axis=0)
    values[:3] = np.where(missing[None], 0.0, coordinates)
    first_frame = int(trial.time_base()[0][0])
    if not 1 <= first_frame <= 65535:
        first_frame = 1
    source = trial.parameters
    # The trial's frames are those read: its EVENT group is kept as it was (events
    # outside the stored frames included); otherwise it is built from the events.
    verbatim_events = ("EVENT" in source and trial.metadata.get("c3d_frames") == frames
                       and trial.first_frame == first_frame)
    for event in [] if verbatim_events else trial.events:
        # EVENT:TIMES count from the capture's start (frame 1 at 0 s).
        frame = int(event.get("frame", round(float(event.get("time", 0.0)) * trial.rate)))
        if 0 <= frame < frames:
            seconds = (first_frame - 1 + frame) / trial.rate
            c3d.add_event([seconds // 60, seconds - 60 * (seconds // 60)],
                          context=str(event.get("context", "")),
                          label=str(event.get("label", "")))
    c3d["header"]["points"]["first_frame"] = first_frame - 1      # ezc3d counts from 0
    last_frame = first_frame + frames - 1
    if last_frame > 65535 or "ACTUAL_START_FIELD" in source.get("TRIAL", {}):
        # The header and POINT:FRAMES are 16-bit; TRIAL:ACTUAL_*_FIELD carry the
        # frame range as two 16-bit words (low, high), as Vicon writes them.
        def words(value: int) -> list[int]:
            return [int(np.int16(np.uint16(value & 0xFFFF))),
                    int(np.int16(np.uint16(value >> 16)))]

        for name, frame in (("ACTUAL_START_FIELD", first_frame),
                            ("ACTUAL_END_FIELD", last_frame)):
            c3d.add_parameter("TRIAL", name, words(frame))
            # ezc3d stores Python integers as floats; these are 16-bit integers.
            c3d["parameters"]["TRIAL"][name]["type"] = ezc3d.ezc3d.INT
            c3d["parameters"]["TRIAL"][name]["value"] = np.array(words(frame))
    c3d["data"]["points"] = values
    residuals = np.where(missing, -1.0, 0.0)[None]
    c3d["data"]["meta_points"]["residuals"] = residuals
    c3d["data"]["meta_points"]["camera_masks"] = np.zeros((7, markers, frames), dtype=bool)
    analogs_written = False
    notes: list[str] = []
    start, kept = float(trial.time_base()[1][0]), (first_frame - 1) / trial.rate
    if abs(start - kept) > 0.5 / trial.rate:
        # C3D times follow the frame numbers (frame 1 at 0 s): a TRC or CSV whose Time
        # starts elsewhere (-0.033 s in OpenSim's Leg39) would shift without a word
        notes.append(f"the start time {start:.6g} s (C3D times follow the frame numbers: "
                     f"frame {first_frame} at {kept:.6g} s)")
    offsets = None
    if trial.analogs is not None and trial.analog_rate and len(trial.analog_labels):
        per_frame = trial.analog_rate / trial.rate
        if (abs(per_frame - round(per_frame)) < 1e-9 and per_frame >= 1
                and trial.analogs.shape[0] == frames * round(per_frame)):
            c3d["parameters"]["ANALOG"]["RATE"]["value"] = [float(trial.analog_rate)]
            c3d["parameters"]["ANALOG"]["LABELS"]["value"] = list(trial.analog_labels)
            analogs = np.asarray(trial.analogs, dtype=float)
            group = source.get("ANALOG", {})
            offsets = offsets_to_keep(group, analogs.shape[1], notes) if group else None
            gain = _analog_gain(group, analogs.shape[1])
            unusable = ~(np.isfinite(gain) & (gain != 0))
            if offsets is not None:
                offsets[unusable] = 0
                # ezc3d stores value / (SCALE · GEN_SCALE) and writes OFFSET 0: shift the
                # values by the offset's worth so the words are the offset ones, then
                # put OFFSET back after writing (patch_int_parameter)
                c3d["parameters"]["ANALOG"]["OFFSET"]["value"] = np.zeros(
                    analogs.shape[1])
                analogs = analogs + offsets * np.where(unusable, 0.0, gain)
            c3d["data"]["analogs"] = analogs.T[None]
            analogs_written = True
        else:
            notes.append(f"{len(trial.analog_labels)} analog channels (their rate is not a "
                         f"whole multiple of the point rate)")
    notes += carry_parameters(c3d, trial, analogs_written, events=verbatim_events)
    if analogs_written and unusable.any():
        # a SCALE (or GEN_SCALE) of 0 cannot store a value: such channels get scale 1
        scale = np.where(unusable, 1.0, gain)
        c3d.add_parameter("ANALOG", "SCALE", scale)
        c3d.add_parameter("ANALOG", "GEN_SCALE", np.array([1.0]))
        notes.append(f"ANALOG:SCALE of {int(unusable.sum())} channel(s) that was 0 (set to 1)")
    for kind, (unit_name, unit) in OUTPUT_UNITS.items():
        listed = [label for label, k, _ in outputs if k == kind]
        if listed:
            c3d.add_parameter("POINT", kind, listed)
            c3d.add_parameter("POINT", unit_name, [unit])
    for group, entries in (groups or {}).items():
        for name, value in entries.items():
            set_parameter(c3d, group, name, value)
    poses = trial.poses
    if poses is not None:
        notes += poses.write_to(c3d, 1.0 / factor)
    with atomic_path(path) as tmp:
        # ezc3d appends ".c3d" to any other suffix (".C3D" included).
        ezc3d_name = tmp.with_suffix(".c3d")
        try:
            str(ezc3d_name).encode("utf-8")
        except UnicodeEncodeError:
            raise MocapError("cannot write C3D into a folder whose name is not valid UTF-8 "
                             "(the C3D library takes UTF-8 paths only)", path) from None
        try:
            c3d.write(str(ezc3d_name))
            _check_written(ezc3d_name, markers, frames, path)
            if offsets is not None and not patch_int_parameter(ezc3d_name, "ANALOG",
                                                               "OFFSET", offsets):
                raise RuntimeError("ANALOG:OFFSET not found in the written file")
            os.replace(ezc3d_name, tmp)
        except MocapError:
            ezc3d_name.unlink(missing_ok=True)
            raise
        except Exception as error:   # ezc3d reports write problems as RuntimeError/OSError
            ezc3d_name.unlink(missing_ok=True)
            raise MocapError(f"cannot write C3D: {error}", path) from None
    return notes


__all__ = ["write_c3d"]
