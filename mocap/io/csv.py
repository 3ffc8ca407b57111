"""Marker CSV files: this project's layout (read/write) and Vicon Nexus exports (read).

This project's layout, one row per frame::

    time,LASI_x,LASI_y,LASI_z,RASI_x,RASI_y,RASI_z
    0.0,0.1234,0.5,0.93,,,
    0.01,0.1236,0.5,0.93,0.12,-0.11,0.94

- ``time`` in seconds, increasing from row to row (a missing time, or one not after the
  previous row's, is refused, naming the line); the rate is (rows − 1) / (last time −
  first time), so a one-row file has no rate (read as 0 Hz, with a warning);
- coordinates in **metres**, three columns per marker named ``<label>_x``,
  ``_y``, ``_z`` (``.x``, ``:x`` or `` x`` and upper case are read too);
- a missing sample is an empty cell (``NaN`` is read too); a marker at exactly
  (0, 0, 0) is read as missing, as in the other formats; a row of fewer cells than the
  header names is read with gaps for the cells it lacks, and cells beyond them are
  ignored, each with a warning.

Vicon Nexus "Trajectories" exports are recognised by their section line and read
with their own rate and units::

    Trajectories
    100
    ,,Subject:LASI,,,Subject:RASI,,,
    Frame,Sub Frame,X,Y,Z,X,Y,Z
    ,,mm,mm,mm,mm,mm,mm
    1,0,44.16,-276.8,675.6,32.5,-243.1,676.5
"""
from __future__ import annotations

import os
import re

import numpy as np

from mocap.atomic import atomic_path
from mocap.budget import check_table_size
from mocap.errors import MocapError
from mocap.io.c3d.read import infer_unit_factor, unique_labels, unit_factor
from mocap.io.text_table import (check_label, check_times_increase, coordinate_decimals,
                                 mark_missing, parse_numeric_rows, parse_table, read_head)
from mocap.io.text_format import format_table
from mocap.trial import Trial

_AXIS_COLUMN = re.compile(r"^(?P<label>.+?)[_.: ](?P<axis>[xyzXYZ])$")
#: Section names of Vicon Nexus CSV exports.
_VICON_SECTIONS = {"trajectories", "devices", "model outputs", "joints", "segments",
                   "global angle", "events"}




def read_csv(path: str | os.PathLike) -> Trial:
    """Read a marker CSV file (this project's layout or a Vicon Nexus export).

    Parameters
    ----------
    path : str or PathLike
        The ``.csv`` file (``time,<label>_x,<label>_y,<label>_z…`` or Nexus sections).

    Returns
    -------
    Trial
        Points (frames, markers, 3) in metres, NaN where missing.

    Raises
    ------
    MocapError
        Missing file, empty file, or a header that fits neither layout.
    """
    head, body = read_head(path, 1, "utf-8-sig")
    if not head or not head[0].strip():
        raise MocapError("empty CSV file", path)
    if head[0].split(",")[0].strip().lower() in _VICON_SECTIONS:
        lines = head + body.decode("utf-8", errors="replace").splitlines()
        return _read_vicon(lines, path)
    return _read_plain(head[0], body, path)


def _read_plain(first_line: str, body: bytes, path) -> Trial:
    # what the header declares against the budget, before its cells are split
    rows = body.count(b"\n") + 1
    check_table_size(rows, len(body), first_line.rstrip(", \t\r").count(",") + 1, path)
    header = [cell.strip() for cell in first_line.split(",")]
    if header[0].lower() not in ("time", "time_s", "time (s)", "t"):
        raise MocapError("not a marker CSV: the first column must be 'time' (seconds) "
                         "or the file a Vicon Nexus 'Trajectories' export", path)
    columns = header[1:]
    while columns and not columns[-1]:
        columns.pop()
    if len(columns) % 3:
        raise MocapError(f"{len(columns)} coordinate columns is not a multiple of 3 "
                         f"(x, y, z per marker)", path)
    labels = []
    for i in range(0, len(columns), 3):
        matches = [_AXIS_COLUMN.match(name) for name in columns[i:i + 3]]
        axes = [m.group("axis").lower() if m else None for m in matches]
        names = {m.group("label") for m in matches if m}
        if axes != ["x", "y", "z"] or len(names) != 1:
            raise MocapError(f"columns {i + 2}-{i + 4} ({', '.join(columns[i:i + 3])}) must "
                             f"be <label>_x, <label>_y, <label>_z", path)
        labels.append(names.pop())
    labels, warnings = unique_labels(labels)
    table = parse_table(body, ",", 1 + len(columns), warnings, first_line=2, path=path,
                        ends_file=True, lines=rows)
    times = table[:, 0]
    check_times_increase(times, body, path, first_line=2)
    points = mark_missing(table[:, 1:].reshape(table.shape[0], len(labels), 3), warnings)
    rate = 0.0
    if len(times) > 1:
        rate = (len(times) - 1) / (times[-1] - times[0])
        steps = np.diff(times)
        if np.abs(steps - 1.0 / rate).max() > 1e-3 / rate:
            warnings.append("time column is not evenly spaced; the mean rate was used")
    else:
        rows = f"{len(times)} row" + ("" if len(times) == 1 else "s")
        warnings.append(f"no rate: {rows}, and the rate is read from two or more times")
    # the unit check looks at up to ~100 000 coordinates spread over the trial
    sample = points[::max(1, points.shape[0] * max(points.shape[1], 1) // 33000)]
    if np.isfinite(sample).any() and infer_unit_factor(sample)[0] == "mm":
        warnings.append("coordinates look like millimetres, but this CSV layout is in "
                        "metres: check the file")
    return Trial(labels, points, rate, "m", os.fspath(path), "csv",
                 metadata={"warnings": warnings},
                 start_time=float(times[0]) if times.size else 0.0)


def _read_vicon(lines: list[str], path) -> Trial:
    start = next((i for i, line in enumerate(lines)
                  if line.split(",")[0].strip().lower() == "trajectories"), None)
    if start is None or start + 5 > len(lines):
        raise MocapError("Vicon CSV export without a complete 'Trajectories' section", path)
    try:
        rate = float(lines[start + 1].split(",")[0])
    except ValueError:
        raise MocapError(f"Vicon CSV: rate line {start + 2} is not a number", path) from None
    label_cells = [cell.strip() for cell in lines[start + 2].split(",")]
    raw_labels = [cell for cell in label_cells[2:] if cell]
    rows = lines[start + 5:]
    check_table_size(len(rows), sum(map(len, rows)) + len(rows), 2 + 3 * len(raw_labels), path)
    unit_cells = [cell.strip() for cell in lines[start + 4].split(",")[2:] if cell.strip()]
    units = unit_cells[0] if unit_cells else ""
    end = start + 5
    while end < len(lines) and lines[end].strip(" ,"):
        end += 1
    labels, warnings = unique_labels(raw_labels)
    table = parse_numeric_rows(lines[start + 5:end], ",", 2 + 3 * len(labels), warnings,
                               first_line=start + 6, path=path)
    points = mark_missing(table[:, 2:].reshape(table.shape[0], len(labels), 3), warnings)
    factor = unit_factor(units) if units else None
    if factor is None:
        guess, factor = infer_unit_factor(points)
        warnings.append(f"units {units!r}; {guess} inferred from the coordinates' magnitude")
    first = int(table[0, 0]) if len(table) and np.isfinite(table[0, 0]) else 1
    return Trial(labels, points * factor, rate, units, os.fspath(path), "csv",
                 metadata={"warnings": warnings, "layout": "vicon-nexus"}, first_frame=first)


def write_csv(trial: Trial, path: str | os.PathLike, precision: int | None = None) -> None:
    """Write a trial in this project's CSV layout (metres, empty cells for NaN).

    Parameters
    ----------
    trial : Trial
    path : str or PathLike
        Written all-or-nothing.
    precision : int, optional
        Decimal places of the coordinates (metres); default 9 (1 nm), at least 6
        (1 µm).

    The time column is the trial's own (:meth:`Trial.time_base`), to 1 ps.
    """
    decimals = coordinate_decimals("m", precision, path)
    for label in trial.labels:
        check_label(label, ',"', "marker", path)
    header = ",".join(["time"] + [f"{label}_{axis}" for label in trial.labels
                                  for axis in "xyz"])
    table = np.empty((trial.frames, 1 + 3 * len(trial.labels)))
    table[:, 0] = trial.time_base()[1]
    table[:, 1:] = trial.points.reshape(trial.frames, -1)
    places = np.full(table.shape[1], decimals)
    # 1 ps: the rate is read back from the times (12 places fit the fast writer up to
    # 9000 s; longer trials get 9)
    places[0] = 12 if not trial.frames or np.nanmax(np.abs(table[:, 0])) < 9000 else 9
    rows = format_table(table, places, ",", nan="", as_bytes=True)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            handle.write((header + "\n").encode("utf-8"))
            handle.write(rows)
