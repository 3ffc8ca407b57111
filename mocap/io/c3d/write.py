"""Writing C3D files (with ezc3d): markers in the chosen unit, analogs, events."""
from __future__ import annotations

import os

import numpy as np

from mocap.atomic import atomic_path
from mocap.errors import MocapError
from mocap.io.c3d.read import MODELLED_KINDS, unique_labels, unit_factor
from mocap.trial import Trial


def write_c3d(trial: Trial, path: str | os.PathLike, units: str = "mm") -> None:
    """Write a trial's markers (and analogs) to a C3D file with ezc3d.

    Parameters
    ----------
    trial : Trial
        ``points`` (frames, markers, 3) in metres, NaN where missing.
    path : str or PathLike
        Written all-or-nothing (temporary file, then rename).
    units : {"mm", "cm", "m"}
        Length unit stored in the file (POINT:UNITS); points are converted.

    Missing samples are written as residual -1 with zero coordinates, the C3D
    convention; the data are stored as 32-bit floats (POINT:SCALE -1). Analogs
    (when their rate is a whole multiple of the point rate) and
    ``metadata["events"]`` are written too.
    """
    import ezc3d   # deferred: reading C3D needs no ezc3d, only writing does

    factor = unit_factor(units)
    if factor is None or units not in ("mm", "cm", "m"):
        raise MocapError(f"cannot write C3D in units {units!r} (use mm, cm or m)", path)
    labels = list(trial.labels)
    if len(set(labels)) != len(labels) or any(len(label) == 0 for label in labels):
        raise MocapError("marker labels must be unique and non-empty to write C3D", path)
    too_long = [label for label in labels if len(label.encode("utf-8")) > 255]
    if too_long:
        raise MocapError(f"C3D labels hold at most 255 bytes; {too_long[0][:40]!r}… is "
                         f"longer", path)
    if not (np.isfinite(trial.rate) and trial.rate > 0):
        raise MocapError(f"cannot write C3D with rate {trial.rate} Hz", path)
    frames, markers = trial.frames, len(labels)
    if frames == 0:
        raise MocapError("cannot write a C3D file without frames", path)
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [float(trial.rate)]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = labels
    c3d.add_parameter("POINT", "UNITS", [units])
    values = np.ones((4, markers, frames))
    coordinates = trial.points.transpose(2, 1, 0) / factor
    missing = ~np.isfinite(coordinates).all(axis=0)
    values[:3] = np.where(missing[None], 0.0, coordinates)
    for event in trial.metadata.get("events", []):
        # Written files start at frame 1, time 0: an event's time is its frame / rate.
        frame = int(event.get("frame", round(float(event.get("time", 0.0)) * trial.rate)))
        if 0 <= frame < frames:
            c3d.add_event([0, frame / trial.rate], context=str(event.get("context", "")),
                          label=str(event.get("label", "")))
    if frames > 65535:
        # The header and POINT:FRAMES are 16-bit; TRIAL:ACTUAL_*_FIELD carry the
        # frame range as two 16-bit words (low, high), as Vicon writes them.
        def words(value: int) -> list[int]:
            return [int(np.int16(np.uint16(value & 0xFFFF))),
                    int(np.int16(np.uint16(value >> 16)))]

        for name, frame in (("ACTUAL_START_FIELD", 1), ("ACTUAL_END_FIELD", frames)):
            c3d.add_parameter("TRIAL", name, words(frame))
            # ezc3d stores Python integers as floats; these are 16-bit integers.
            c3d["parameters"]["TRIAL"][name]["type"] = ezc3d.ezc3d.INT
            c3d["parameters"]["TRIAL"][name]["value"] = np.array(words(frame))
    c3d["data"]["points"] = values
    residuals = np.where(missing, -1.0, 0.0)[None]
    c3d["data"]["meta_points"]["residuals"] = residuals
    c3d["data"]["meta_points"]["camera_masks"] = np.zeros((7, markers, frames), dtype=bool)
    if trial.analogs is not None and trial.analog_rate and len(trial.analog_labels):
        per_frame = trial.analog_rate / trial.rate
        if (abs(per_frame - round(per_frame)) < 1e-9 and per_frame >= 1
                and trial.analogs.shape[0] == frames * round(per_frame)):
            c3d["parameters"]["ANALOG"]["RATE"]["value"] = [float(trial.analog_rate)]
            c3d["parameters"]["ANALOG"]["LABELS"]["value"] = list(trial.analog_labels)
            c3d["data"]["analogs"] = np.asarray(trial.analogs, dtype=float).T[None]
    with atomic_path(path) as tmp:
        # ezc3d appends ".c3d" to any other suffix (".C3D" included).
        ezc3d_name = tmp.with_suffix(".c3d")
        try:
            c3d.write(str(ezc3d_name))
            os.replace(ezc3d_name, tmp)
        except Exception as error:   # ezc3d reports write problems as RuntimeError/OSError
            ezc3d_name.unlink(missing_ok=True)
            raise MocapError(f"cannot write C3D: {error}", path) from None


__all__ = ["write_c3d"]
