"""TRC marker files (OpenSim / Motion Analysis): read and write.

Layout (tab-separated; comma-separated exports such as Vicon's are read too)::

    PathFileType  4  (X/Y/Z)  walk.trc
    DataRate  CameraRate  NumFrames  NumMarkers  Units  OrigDataRate  OrigDataStartFrame  OrigNumFrames
    100       100         580        51          mm     100           1                   580
    Frame#  Time  LASI        RASI  …
                  X1  Y1  Z1  X2  Y2  Z2 …
    <blank line>
    1  0.000  12.3  …

Missing samples are empty cells (or a marker at exactly 0, 0, 0, which many
exporters write for a gap): both read as NaN, and NaN is written as empty cells.

A header whose NumFrames disagrees with the rows in the file (the pyomeca
sample announces 652 frames and holds 93 rows) is not an error: the rows that
are there are loaded, which is the only data the file has, and
``metadata["warnings"]`` says so. A row with a different number of cells is
padded with missing samples.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from mocap.atomic import atomic_path
from mocap.errors import MocapError
from mocap.io.c3d.read import infer_unit_factor, unique_labels, unit_factor
from mocap.io.text_table import format_rows, mark_missing, parse_numeric_rows, read_lines
from mocap.trial import Trial




def read_trc(path: str | os.PathLike) -> Trial:
    """Read a TRC file into a :class:`Trial` (metres, NaN for missing samples).

    Parameters
    ----------
    path : str or PathLike

    Returns
    -------
    Trial
        ``rate`` from DataRate; ``units`` from Units; ``metadata`` holds
        ``start_time`` (s, the first row's Time), ``header`` (the header fields
        as text) and ``warnings``.

    Raises
    ------
    MocapError
        Missing file, or a file that is not a TRC file.
    """
    lines = read_lines(path)
    if len(lines) < 5 or not lines[0].lower().startswith("pathfiletype"):
        raise MocapError("not a TRC file (it must start with 'PathFileType')", path)
    delimiter = "\t" if "\t" in lines[0] + lines[1] else ","
    keys = [cell.strip() for cell in lines[1].split(delimiter)]
    values = [cell.strip() for cell in lines[2].split(delimiter)]
    named_keys = [key for key in keys if key]
    filled_values = [value for value in values if value]
    if len(named_keys) == len(filled_values):
        # Some writers pad the value line with extra delimiters (OpenSim's
        # Rajagopal data): pair the non-empty cells.
        header = dict(zip(named_keys, filled_values))
    else:
        header = {key: value for key, value in zip(keys, values) if key}
    if "DataRate" not in header:
        raise MocapError("TRC header has no DataRate", path)
    try:
        rate = float(header["DataRate"])
    except ValueError:
        raise MocapError(f"TRC DataRate {header['DataRate']!r} is not a number", path) \
            from None
    if not (np.isfinite(rate) and rate > 0):
        raise MocapError(f"TRC DataRate {header['DataRate']!r} is not a positive rate", path)

    label_cells = [cell.strip() for cell in lines[3].split(delimiter)]
    if len(label_cells) < 2 or not label_cells[0].lower().startswith("frame"):
        raise MocapError("TRC line 4 must start with 'Frame#' and 'Time'", path)
    # Labels sit every third column from column 2; the blanks between them
    # belong to the Y and Z of the label before.
    raw_labels = [cell for cell in label_cells[2:] if cell]
    count = len(raw_labels)
    announced = _int_or_none(header.get("NumMarkers"))
    warnings = []
    if announced is not None and announced != count:
        warnings.append(f"header announces {announced} markers, line 4 names {count}")
    labels, notes = unique_labels(raw_labels)
    warnings += notes

    data_lines = [line for line in lines[5:] if line.strip(" \t,")]
    table = parse_numeric_rows(data_lines, delimiter, 2 + 3 * count)
    announced_frames = _int_or_none(header.get("NumFrames"))
    if announced_frames is not None and announced_frames != table.shape[0]:
        warnings.append(f"header announces {announced_frames} frames but the file holds "
                        f"{table.shape[0]} rows; the rows were loaded")
    points = mark_missing(table[:, 2:].reshape(table.shape[0], count, 3))
    units = header.get("Units", "").strip()
    factor = unit_factor(units) if units else None
    if factor is None:
        guess, factor = infer_unit_factor(points)
        warnings.append(f"Units is {units!r}; {guess} inferred from the coordinates' magnitude")
    times = table[:, 1]
    metadata = {
        "start_time": float(times[0]) if times.size and np.isfinite(times[0]) else 0.0,
        "header": header,
        "warnings": warnings,
    }
    return Trial(labels, points * factor, rate, units, os.fspath(path), "trc",
                 metadata=metadata)


def _int_or_none(text: str | None) -> int | None:
    try:
        return int(float(text)) if text not in (None, "") else None
    except ValueError:
        return None


def write_trc(trial: Trial, path: str | os.PathLike, units: str = "mm") -> None:
    """Write a trial as an OpenSim TRC file (tab-separated).

    Parameters
    ----------
    trial : Trial
        ``points`` (frames, markers, 3) in metres, NaN where missing.
    path : str or PathLike
        Written all-or-nothing.
    units : {"mm", "cm", "m"}
        Unit of the coordinates in the file (the Units field).
    """
    factor = unit_factor(units)
    if factor is None or units not in ("mm", "cm", "m"):
        raise MocapError(f"cannot write TRC in units {units!r} (use mm, cm or m)", path)
    if any("\t" in label or not label for label in trial.labels):
        raise MocapError("marker labels must be non-empty and free of tabs to write TRC",
                         path)
    frames, markers = trial.frames, len(trial.labels)
    rate = repr(float(trial.rate))
    lines = [
        f"PathFileType\t4\t(X/Y/Z)\t{Path(path).name}",
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t"
        "OrigDataStartFrame\tOrigNumFrames",
        f"{rate}\t{rate}\t{frames}\t{markers}\t{units}\t{rate}\t1\t{frames}",
        "Frame#\tTime\t" + "\t".join(f"{label}\t\t" for label in trial.labels),
        "\t\t" + "\t".join(f"X{i}\tY{i}\tZ{i}" for i in range(1, markers + 1)),
        "",
    ]
    table = np.empty((frames, 2 + 3 * markers))
    table[:, 0] = np.arange(1, frames + 1)
    table[:, 1] = trial.times
    table[:, 2:] = (trial.points / factor).reshape(frames, 3 * markers)
    text = "\n".join(lines) + "\n" + _integer_frames(format_rows(table, "\t"))
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def _integer_frames(rows: str) -> str:
    """Data rows with frame numbers written as ``1`` rather than ``1.0``."""
    out = []
    for line in rows.split("\n"):
        head, sep, rest = line.partition("\t")
        out.append(head.removesuffix(".0") + sep + rest)
    return "\n".join(out)
