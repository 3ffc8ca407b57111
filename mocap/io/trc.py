"""TRC marker files (OpenSim / Motion Analysis): read and write.

Layout (tab-separated; comma-separated exports such as Vicon's are read too)::

    PathFileType  4  (X/Y/Z)  walk.trc
    DataRate  CameraRate  NumFrames  NumMarkers  Units  OrigDataRate  OrigDataStartFrame  OrigNumFrames
    100       100         580        51          mm     100           1                   580
    Frame#  Time  LASI        RASI  …
                  X1  Y1  Z1  X2  Y2  Z2 …
    <blank line>
    1  0.000  12.3  …

Missing samples are empty cells, ``NaN`` (or a marker at exactly 0, 0, 0, which
many exporters write for a gap): all read as NaN, and NaN is written as ``NaN``
(OpenSim 4.6 rejects a row whose last cells are empty). Coordinates are written
with a fixed number of decimals, 1 nm by default; Frame# and Time are written as
the trial was read. Columns without a label on line 4 are named after their column
(``M004``) with a warning, never dropped.

A header whose NumFrames disagrees with the rows in the file (the pyomeca
sample announces 652 frames and holds 93 rows) is not an error: the rows that
are there are loaded, which is the only data the file has, and
``metadata["warnings"]`` says so. A row of fewer cells than line 4 names is read
with missing samples for the cells it lacks, and cells beyond them are ignored, each
with a warning naming the first such line (blank cells at the end of a row, such as
a trailing tab, are not counted).
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from mocap.atomic import atomic_path
from mocap.budget import check_table_size
from mocap.errors import MocapError
from mocap.io import require_rate
from mocap.io.c3d.read import infer_unit_factor, unique_labels, unit_disagreement, unit_factor
from mocap.io.text_table import (check_label, coordinate_decimals, mark_missing, parse_table,
                                 read_head)
from mocap.io.text_format import format_table
from mocap.trial import Trial


def read_trc(path: str | os.PathLike) -> Trial:
    """Read a TRC file into a :class:`Trial` (metres, NaN for missing samples).

    Parameters
    ----------
    path : str or PathLike
        The ``.trc`` file (OpenSim / Motion Analysis layout).

    Returns
    -------
    Trial
        ``rate`` from DataRate; ``units`` from Units; ``metadata`` holds
        ``frame_numbers`` and ``frame_times`` (the Frame# and Time columns as read,
        kept when the trial is written again), ``first_frame``, ``start_time`` (s,
        the first row's Time), ``header`` (the header fields as text) and
        ``warnings``.

    Raises
    ------
    MocapError
        Missing file, a file that is not a TRC file, or one without marker columns.
    """
    lines, body = read_head(path, 5, "utf-8-sig")       # a byte-order mark is allowed
    if len(lines) < 5 or not lines[0].strip().lower().startswith("pathfiletype"):
        raise MocapError("not a TRC file (it must start with 'PathFileType')", path)
    delimiter = "\t" if "\t" in lines[0] + lines[1] else ","
    # the columns lines 4 and 5 declare, against the budget before they are split
    rows = body.count(b"\n") + 1
    check_table_size(rows, len(body),
                     max(lines[3].rstrip(" \t,").count(delimiter),
                         lines[4].rstrip(" \t,").count(delimiter)) + 1, path)
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
    warnings: list[str] = []
    first_line = 6
    if _is_data_row(lines[4], delimiter):
        # no axis line: line 5 is the first row (else it would be lost as a header line)
        warnings.append("line 5 holds numbers where the axis line (X1 Y1 Z1 …) belongs; "
                        "it was read as the first row")
        body = lines[4].encode("utf-8") + b"\n" + body
        lines[4] = ""
        rows += 1
        first_line = 5
    elif not any(cell.strip()[:1].upper() == "X" for cell in lines[4].split(delimiter)):
        warnings.append("line 5 does not name the axes (X1 Y1 Z1 …); the columns after "
                        "Frame# and Time were read as X, Y, Z per marker")
    for key in ("NumFrames", "NumMarkers"):
        if header.get(key, "") != "" and _int_or_none(header[key]) is None:
            warnings.append(f"header {key} {header[key][:20]!r} is not a whole number; "
                            f"it was ignored")
    raw_labels = _marker_labels(label_cells[2:])
    axis_cells = [cell.strip() for cell in lines[4].split(delimiter)]
    axis_markers = sum(1 for cell in axis_cells if cell[:1].upper() == "X")
    width = _first_row_width(body, delimiter)
    data_markers = max(width - 2, 0) // 3
    # before any list of that length is made: what line 4, 5 and the first row declare
    check_table_size(rows, len(body), 2 + 3 * max(len(raw_labels), axis_markers, data_markers),
                     path)
    count = len(raw_labels)
    if count < max(axis_markers, data_markers) and (count == 0 or axis_markers > count):
        # Columns without a label on line 4: named after their column, never dropped.
        extra = max(axis_markers, data_markers if count == 0 else 0) - count
        warnings.append(f"{extra} marker column(s) have no label on line 4; named "
                        f"M{count + 1:03d}… after their column")
        raw_labels += [""] * extra
        count = len(raw_labels)
    if count == 0:
        raise MocapError("TRC file has no marker columns (line 4 names no markers and "
                         "the rows hold only Frame# and Time)", path)
    announced = _int_or_none(header.get("NumMarkers"))
    if announced is not None and announced != count:
        warnings.append(f"header announces {announced} markers, line 4 names {count}")
    labels, notes = unique_labels(raw_labels)
    warnings += notes

    table = parse_table(body, delimiter, 2 + 3 * count, warnings, first_line, path,
                        ends_file=True, lines=rows)
    announced_frames = _int_or_none(header.get("NumFrames"))
    if announced_frames is not None and announced_frames != table.shape[0]:
        warnings.append(f"header announces {announced_frames} frames but the file holds "
                        f"{table.shape[0]} rows; the rows were loaded")
    units = header.get("Units", "").strip()
    factor = unit_factor(units) if units else None
    if factor is None:
        guess, factor = infer_unit_factor(mark_missing(
            table[:, 2:].reshape(table.shape[0], count, 3)))
        warnings.append(f"Units is {units!r}; {guess} inferred from the coordinates' magnitude")
    else:
        disagreement = unit_disagreement(table[:, 2:].reshape(table.shape[0], count, 3),
                                         factor, units)
        if disagreement:
            warnings.append(f"Units: {disagreement}")
    # scaled in one pass into a contiguous array, then gaps marked
    points = mark_missing(np.multiply(table[:, 2:], factor).reshape(table.shape[0], count, 3),
                          warnings)
    frames, times = table[:, 0], table[:, 1]
    metadata: dict = {"header": header, "warnings": warnings}
    clock: dict = {}
    problem = _time_column_problem(times, rate)
    if problem:
        warnings.append(problem)
    elif times.size:
        clock.update(frame_times=times.copy(), start_time=float(times[0]))
    if frames.size and np.isfinite(frames).all() and (frames == np.round(frames)).all():
        clock.update(frame_numbers=frames.astype(np.int64), first_frame=int(frames[0]))
    return Trial(labels, points, rate, units, os.fspath(path), "trc", metadata=metadata,
                 **clock)


def _time_column_problem(times: np.ndarray, rate: float) -> str | None:
    """Why the Time column cannot be the frames' times, or None when it can.

    Parameters
    ----------
    times : ndarray, shape (frames,)
        The Time column as read, seconds.
    rate : float
        DataRate, Hz.

    A column with missing cells, one that stands still or runs backwards, or one whose
    span is not ``(frames - 1) / rate`` (within 1 % and 1 ms, as times are often
    written to the millisecond) is not kept: the frames are then
    timed by DataRate, and the returned message (a warning) says so.

    >>> _time_column_problem(np.array([0.0, 0.01, 0.02]), 100.0) is None
    True
    >>> _time_column_problem(np.array([0.0, 0.02, 0.01]), 100.0)  # doctest: +ELLIPSIS
    'the Time column runs backwards or stands still at row 3 (0.01 s after 0.02 s); the ...'
    """
    if times.size == 0:
        return None
    instead = f"the frames are timed by DataRate ({rate:g} Hz) instead"
    bad = np.flatnonzero(~np.isfinite(times))
    if bad.size:
        return f"the Time column has {bad.size} empty or non-numeric cell(s) (first at row " \
               f"{bad[0] + 1}); {instead}"
    if times.size < 2:
        return None
    steps = np.diff(times)
    back = np.flatnonzero(steps <= 0)
    if back.size:
        row = back[0] + 2
        return (f"the Time column runs backwards or stands still at row {row} "
                f"({times[row - 1]:g} s after {times[row - 2]:g} s); {instead}")
    span, expected = float(times[-1] - times[0]), (times.size - 1) / rate
    if abs(span - expected) > 0.01 * expected + 0.001:       # 1 %, and times rounded to ms
        return (f"the Time column spans {span:g} s but DataRate ({rate:g} Hz) gives "
                f"{expected:g} s for {times.size} frames; {instead}")
    return None


def _marker_labels(cells: list[str]) -> list[str]:
    """Labels of line 4 after Frame# and Time: one per marker, "" where unlabelled.

    Labels sit every third column (the two blanks after one belong to its Y and Z);
    when a file does not keep to that, its non-empty cells are the labels.
    """
    while cells and not cells[-1]:
        cells = cells[:-1]
    filled = [i for i, cell in enumerate(cells) if cell]
    if all(i % 3 == 0 for i in filled):
        return [cells[i] if i < len(cells) else "" for i in range(0, len(cells), 3)]
    return [cell for cell in cells if cell]


def _first_row_width(body: bytes, delimiter: str) -> int:
    """Cells in the first non-blank data row (0 when there is none)."""
    start = 0
    for _ in range(64):
        end = body.find(b"\n", start)
        line = body[start:] if end < 0 else body[start:end]
        start = end + 1
        text = line.decode("utf-8", errors="replace").strip(" \r\t" + delimiter)
        if text:
            cells = line.decode("utf-8", errors="replace").rstrip("\r").split(delimiter)
            while cells and not cells[-1].strip():
                cells.pop()
            return len(cells)
        if end < 0:
            break
    return 0


def _int_or_none(text: str | None) -> int | None:
    """A header count as an int; None when empty, not a number or not whole."""
    try:
        value = float(text) if text not in (None, "") else None
    except ValueError:
        return None
    return int(value) if value is not None and value.is_integer() else None


def _is_data_row(line: str, delimiter: str) -> bool:
    """Whether a line is a row of numbers (its first two cells, Frame# and Time, are)."""
    cells = line.split(delimiter)
    if len(cells) < 2:
        return False
    try:
        float(cells[0])
        float(cells[1])
    except ValueError:
        return False
    return True


#: Decimal places of the Time column (1 ns).
TIME_DECIMALS = 9


def write_trc(trial: Trial, path: str | os.PathLike, units: str = "mm",
              precision: int | None = None) -> None:
    """Write a trial as an OpenSim TRC file (tab-separated).

    Parameters
    ----------
    trial : Trial
        ``points`` (frames, markers, 3) in metres, NaN where missing.
    path : str or PathLike
        Written all-or-nothing.
    units : {"mm", "cm", "m"}
        Unit of the coordinates in the file (the Units field).
    precision : int, optional
        Decimal places of the coordinates in ``units``; default 1 nm (6 in mm, 9 in
        m); coarser than 1 µm is refused.

    Notes
    -----
    Missing samples are written ``NaN``, which OpenSim reads (it drops empty cells
    at the end of a row and then rejects the file). Frame# and Time are the
    trial's own (:meth:`Trial.time_base`): a TRC read and written again keeps its
    frame numbers and times, a C3D keeps its first frame.
    """
    factor = unit_factor(units)
    if factor is None or units not in ("mm", "cm", "m"):
        raise MocapError(f"cannot write TRC in units {units!r} (use mm, cm or m)", path)
    decimals = coordinate_decimals(units, precision, path)
    require_rate(trial, path, "TRC file (DataRate)")
    if not len(trial.labels):
        # a TRC without marker columns is one no reader takes (read_trc refuses it too)
        raise MocapError("no markers to write: a TRC file holds marker trajectories", path)
    for label in trial.labels:
        check_label(label, "\t", "marker", path)
    frames, markers = trial.frames, len(trial.labels)
    numbers, times = trial.time_base()
    rate = _number(trial.rate)
    lines = [
        f"PathFileType\t4\t(X/Y/Z)\t{Path(path).name}",
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t"
        "OrigDataStartFrame\tOrigNumFrames",
        f"{rate}\t{rate}\t{frames}\t{markers}\t{units}\t{rate}\t"
        f"{int(numbers[0]) if frames else 1}\t{frames}",
        "Frame#\tTime\t" + "\t".join(f"{label}\t\t" for label in trial.labels),
        "\t\t" + "\t".join(f"X{i}\tY{i}\tZ{i}" for i in range(1, markers + 1)),
        "",
    ]
    table = np.empty((frames, 2 + 3 * markers))
    table[:, 0] = numbers
    table[:, 1] = times
    table[:, 2:] = (trial.points / factor).reshape(frames, 3 * markers)
    places = np.full(table.shape[1], decimals)
    places[:2] = (0, TIME_DECIMALS)
    # surrogateescape: a file name that is not valid UTF-8 (a Latin-1 name from an old
    # archive) goes into the header as the very bytes of the name
    head = ("\n".join(lines) + "\n").encode("utf-8", "surrogateescape")
    rows = format_table(table, places, "\t", as_bytes=True)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            handle.write(head)
            handle.write(rows)


def _number(value: float) -> str:
    """A rate as short text: ``100`` rather than ``100.0``, else the exact repr."""
    value = float(value)
    return str(int(value)) if value.is_integer() else repr(value)
