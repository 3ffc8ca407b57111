"""Numeric tables read from delimited text (CSV, TRC, MOT, angle CSV), and the helpers the
text formats share (reading files, checking labels, coordinates and times).

Large tables are read by a compiled loop (numba, cached on disk,
:mod:`mocap.io.text_kernels`), one pass over the bytes: a 20 000 × 60 marker table takes
tenths of a second where a Python loop per cell took seconds (``benchmarks/io.py``). Small
tables (up to :data:`COMPILED_ABOVE` cells) are read in Python with the same results.

Reading is exact: a number with at most 15 significant digits and a decimal
exponent within ±22 (every number a TRC or CSV file holds in practice) is an exact
integer divided or multiplied by an exact power of ten, one correctly rounded
operation, so it gives the same float64 as ``float(text)``; any other number is
handed to ``float`` itself. Empty cells and ``NaN`` are gaps; a cell that is not a finite
number becomes a gap with a warning (``docs/formats/limits.md``).

Writing is :mod:`mocap.io.text_format`: fixed decimal places per column, ``NaN`` as a word,
which OpenSim, numpy and pandas read (OpenSim drops empty cells at the end of a row and then
rejects the row).
"""
from __future__ import annotations

import os

import numpy as np

from mocap.budget import check_table_size
from mocap.errors import MocapError, reading

#: Bytes the parser treats as blank around a cell.
_SPACE, _CR, _NL = 32, 13, 10
#: Tables of more cells than this (12 bytes each) are read by the compiled loop
#: (:mod:`mocap.io.text_kernels`); smaller ones in Python, which spares a small file the
#: ~1.5 s of loading numba.
COMPILED_ABOVE = 100_000
#: Exact powers of ten as float64.
POW10 = np.array([10.0 ** k for k in range(23)])


def read_lines(path: str | os.PathLike, encoding: str = "utf-8") -> list[str]:
    """Lines of a text file; a missing or unreadable file is a :class:`MocapError`."""
    with reading(path):
        with open(path, "r", encoding=encoding, errors="replace", newline=None) as handle:
            return handle.read().splitlines()


def read_text(path: str | os.PathLike, what: str = "file") -> str:
    """The whole text of a UTF-8 file (a leading byte-order mark dropped); missing,
    unreadable or undecodable is a :class:`MocapError` naming the file (``what`` names its
    kind in the message)."""
    with reading(path, what, missing=f"{what} not found"):
        with open(path, encoding="utf-8-sig") as handle:
            return handle.read()


def read_head(path: str | os.PathLike, count: int,
              encoding: str = "utf-8") -> tuple[list[str], bytes]:
    """The first ``count`` lines of a file as text and the rest as raw bytes.

    The header of a text table is small and read as text; the body goes to
    :func:`parse_table` unsplit (read straight from the file, not copied).
    """
    with reading(path):
        with open(path, "rb") as handle:
            chunks = [handle.read(65536)]
            found = chunks[0].count(b"\n")
            while found < count and chunks[-1]:
                # chunks joined once: a header line of many megabytes (a hostile
                # file's) took seconds when the head grew by concatenation
                chunks.append(handle.read(max(65536, sum(map(len, chunks)))))
                found += chunks[-1].count(b"\n")
            head = b"".join(chunks)
            if encoding == "utf-8-sig" and head.startswith(b"\xef\xbb\xbf"):
                head = head[3:]
                skip = 3
            else:
                skip = 0
            lines = []
            position = 0
            for _ in range(count):
                end = head.find(b"\n", position)
                if end < 0:
                    lines.append(head[position:])
                    position = len(head)
                    break
                lines.append(head[position:end])
                position = end + 1
            handle.seek(position + skip)
            body = handle.read()
    text = [line.decode("utf-8", errors="replace").rstrip("\r") for line in lines]
    return text, body


def check_times_increase(times: np.ndarray, body: bytes, path, first_line: int,
                         delimiter: str = ",", missing_ok: bool = False) -> None:
    """MocapError naming the file line of the first row whose time is missing or not after
    the previous row's (a time column that stalls or runs backwards has no rate).

    Parameters
    ----------
    times : ndarray, shape (rows,), s
        The time column as :func:`parse_table` read it from ``body``.
    body : bytes
        The table's text, whose first line is line ``first_line`` of the file.
    missing_ok : bool
        A column with missing times is not checked (for a format with another source of
        time); only a complete one must increase.
    """
    finite = np.isfinite(times)
    if missing_ok and not finite.all():
        return
    later = np.concatenate([[True], np.diff(times) > 0])
    bad = np.flatnonzero(~(finite & later))
    if not bad.size:
        return
    row = int(bad[0])
    line = _line_of_row(body, row, first_line, delimiter)
    if not finite[row]:
        raise MocapError(f"line {line}: the time is missing or not a number", path)
    raise MocapError(f"line {line}: time {times[row]:.9g} s does not come after the previous "
                     f"row's {times[row - 1]:.9g} s (the time column must increase)", path)


def _line_of_row(body: bytes, row: int, first_line: int, delimiter: str) -> int:
    """The file line of data row ``row`` (blank lines skipped, as :func:`parse_table` does)."""
    blank = b" \t\r" + delimiter.encode()
    number = first_line
    for number, line in enumerate(body.split(b"\n"), start=first_line):
        if line.strip(blank):
            if row == 0:
                return number
            row -= 1
    return number


def parse_table(data: bytes | str, delimiter: str, width: int, notes: list[str] | None = None,
                first_line: int = 1, path: str | os.PathLike | None = None,
                ends_file: bool = False, lines: int | None = None,
                strict: bool = False) -> np.ndarray:
    """Numbers of delimited text rows; blank lines skipped, empty or unusable cells NaN.

    The one numeric-cell rule of the text readers: a cell is a finite number, a gap (empty,
    or ``NaN`` in any spelling) or unusable (``inf``, ``1e309``, a word, ``--3``): an
    unusable cell reads as a gap too, and ``notes`` gets one warning saying how many there
    were and the line and text of the first. Before anything is allocated the table's size
    is checked (:func:`check_table_size`).

    Parameters
    ----------
    data : bytes or str
        The table's rows (no header), lines ended by ``\\n`` (``\\r\\n`` is fine).
    delimiter : str
        One character (``"\\t"`` or ``","``); spaces around a cell are ignored.
    width : int
        Columns to keep (the header's); shorter rows are padded with NaN, longer ones cut.
    notes : list of str, optional
        Receives a warning for rows of fewer cells than ``width``, one for rows with
        cells beyond it that are not blank (blank cells at the end of a row, such as a
        trailing tab, are not counted), one for unusable cells, and (with ``ends_file``)
        one when the text ends inside a row (no final line break: the file may have been
        cut in its last number).
    first_line : int
        The file line of ``data``'s first line, for the warnings.
    path : str or PathLike, optional
        The file, named by the refusal of a table too large for memory.
    ends_file : bool
        ``data`` runs to the end of the file, so a missing final line break is noted.
    strict : bool
        Refuse (MocapError naming the first line) ragged rows and unusable cells instead
        of reading them as gaps with a warning: for a format written only by programs
        (the joint-angle CSV).
    lines : int, optional
        ``data.count(b"\\n") + 1`` when the caller has counted them already (a pass over
        the bytes: 12 ms for 40 MB).

    Returns
    -------
    ndarray, shape (rows, width), float
        Finite numbers and NaN only.

    Raises
    ------
    MocapError
        A table beyond the memory budget, or one the bytes present cannot hold
        (:func:`check_table_size`); with ``strict``, a ragged row or an unusable cell.

    Examples
    --------
    >>> notes = []
    >>> parse_table("1,2,3\\n4,5\\n6,inf,8,\\n", ",", 3, notes, first_line=2)
    array([[ 1.,  2.,  3.],
           [ 4.,  5., nan],
           [ 6., nan,  8.]])
    >>> notes  # doctest: +NORMALIZE_WHITESPACE
    ['1 row has 2 cells where the header names 3 (first at line 3); the missing cells read
     as gaps', "1 cell is not a finite number (first at line 4: 'inf'); read as a missing
     sample"]
    """
    if isinstance(data, str):
        data = data.encode("utf-8")
    check_table_size(data.count(b"\n") + 1 if lines is None else lines, len(data), width,
                     path)
    bad: list = []
    if len(data) < 12 * COMPILED_ABOVE:
        table, cells = _parse_python(data.decode("utf-8", errors="replace"), delimiter, width,
                                     bad)
    else:
        table, cells = _parse_compiled(data, delimiter, width, bad)
    if notes is not None or strict:
        problems = []                   # (what, what it became)
        for ragged, effect in ((cells < width, "the missing cells read as gaps"),
                               (cells > width, "the cells beyond the header's were ignored")):
            rows = np.flatnonzero(ragged)
            if rows.size:
                low, high = int(cells[rows].min()), int(cells[rows].max())
                count = f"{low}" if low == high else f"{low} to {high}"
                line = _line_of_row(data, int(rows[0]), first_line, delimiter)
                problems.append((f"{rows.size} row{' has' if rows.size == 1 else 's have'} "
                                 f"{count} cells where the header names {width} (first at "
                                 f"line {line})", effect))
        if bad:
            count, row, text, _ = bad
            line = _line_of_row(data, row, first_line, delimiter)
            problems.append((f"{count} cell{' is' if count == 1 else 's are'} not a finite "
                             f"number (first at line {line}: {_shown(text)})", "read as "
                             f"{'a missing sample' if count == 1 else 'missing samples'}"))
        if strict and problems:
            raise MocapError(f"{problems[0][0]}: every row must have a number or an empty "
                             f"cell in each column", path)
        notes = [] if notes is None else notes
        notes += [f"{what}; {effect}" for what, effect in problems]
        tail = data.rstrip(b" \t")
        if ends_file and tail and not tail.endswith(b"\n") and table.shape[0]:
            line = _line_of_row(data, table.shape[0] - 1, first_line, delimiter)
            notes.append(f"the file ends inside line {line}, without a line break: if it was "
                         f"cut short, the last number of that row may be incomplete")
    return table


def _shown(text: str | bytes, most: int = 20) -> str:
    """A cell's text for a message: quoted, at most ``most`` characters."""
    if isinstance(text, bytes):
        text = text.decode("utf-8", errors="replace")
    return repr(text if len(text) <= most else text[:most] + "…")


def _note_bad(bad: list, row: int, text, col: int) -> None:
    """Count one unusable cell in ``bad`` ([count, first row, first text, first column])."""
    if bad:
        bad[0] += 1
    else:
        bad[:] = [1, row, text, col]


def _parse_compiled(data: bytes, delimiter: str, width: int,
                    bad: list | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`parse_table` of a large table by the compiled loop; and each row's count of
    cells. ``bad`` receives ``[count, first row, first text, first column]`` of the unusable
    cells."""
    from mocap.io.text_kernels import parse_kernel

    buffer = np.frombuffer(data, dtype=np.uint8)
    table, fallback, cells = parse_kernel(buffer, np.uint8(ord(delimiter)), int(width), POW10)
    bad = [] if bad is None else bad
    for row, col, a, b in fallback.tolist():
        try:
            value = float(data[a:b])
        except ValueError:          # a stray word in a number column: missing
            _note_bad(bad, row, data[a:b], col)
            continue
        if value - value == 0:
            table[row, col] = value
        elif value == value:        # infinite (inf, 1e309): missing
            _note_bad(bad, row, data[a:b], col)
    return table, cells


def _parse_python(text: str, delimiter: str, width: int,
                  bad: list | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`parse_table` of a small table, one ``float`` per cell; and each row's count
    of cells (as the compiled loop counts them). ``bad`` receives ``[count, first row,
    first text, first column]`` of the unusable cells."""
    blank = " \t\r" + delimiter
    rows = [line for line in text.split("\n") if line.strip(blank)]
    table = np.full((len(rows), width), np.nan)
    counts = np.empty(len(rows), dtype=np.int64)
    bad = [] if bad is None else bad
    for r, line in enumerate(rows):
        cells = line.split(delimiter)
        counts[r] = len(cells)
        if len(cells) > width:
            counts[r] = width
            for c in range(len(cells) - 1, width - 1, -1):
                if cells[c].strip(" \t\r"):
                    counts[r] = c + 1
                    break
        for c, cell in enumerate(cells[:width]):
            cell = cell.strip(" \t\r")
            if cell:
                try:
                    table[r, c] = float(cell)
                except ValueError:      # a stray word in a number column: missing
                    _note_bad(bad, r, cell, c)
    infinite = np.isinf(table)          # inf, 1e309: missing too, counted with the words
    if infinite.any():
        where = np.argwhere(infinite)
        table[infinite] = np.nan
        row, col = (int(k) for k in where[0])
        count = int(where.shape[0]) + (bad[0] if bad else 0)
        if not bad or (row, col) < (bad[1], bad[3]):   # the first in file order is named
            bad[:] = [count, row, rows[row].split(delimiter)[col].strip(" \t\r"), col]
        else:
            bad[0] = count
    return table, counts


def parse_numeric_rows(lines: list[str], delimiter: str, width: int,
                       notes: list[str] | None = None, first_line: int = 1,
                       path: str | os.PathLike | None = None) -> np.ndarray:
    """:func:`parse_table` of rows given as a list of lines (each one row, kept in order).

    Blank lines are skipped, as by :func:`parse_table`.
    """
    if not lines:
        return np.zeros((0, width))
    return parse_table("\n".join(lines) + "\n", delimiter, width, notes, first_line, path)


#: Largest coordinate magnitude a text reader takes (file units or metres): 1000 km in
#: millimetres. Beyond it a value is corrupt (1e300 mm read from a CSV in metres became inf
#: when a TRC in millimetres was written).
MAX_COORDINATE = 1e9


def mark_missing(points: np.ndarray, notes: list[str] | None = None) -> np.ndarray:
    """Set to NaN every sample with a non-finite coordinate, one beyond
    :data:`MAX_COORDINATE`, or exactly at (0, 0, 0).

    Parameters
    ----------
    points : ndarray, shape (frames, markers, 3)
        Modified in place and returned.
    notes : list of str, optional
        Receives a warning when samples beyond :data:`MAX_COORDINATE` were set missing
        (non-finite and (0, 0, 0) samples are the formats' ways of writing a gap).

    >>> p = np.array([[[1.0, 2.0, 3.0], [0.0, 0.0, 0.0], [1e300, 0.0, 0.0]]])
    >>> notes = []
    >>> mark_missing(p, notes)[0, :, 0], notes
    (array([ 1., nan, nan]), ['1 sample(s) with a coordinate beyond ±1e+09 read as missing'])
    """
    # one pass each: a NaN or infinite coordinate makes the sum non-finite
    missing = ~np.isfinite(points.sum(axis=2)) | ~points.any(axis=2)
    huge = (np.abs(points) > MAX_COORDINATE).any(axis=2) & ~missing
    if huge.any():
        missing |= huge
        if notes is not None:
            notes.append(f"{int(huge.sum())} sample(s) with a coordinate beyond "
                         f"±{MAX_COORDINATE:g} read as missing")
    points[missing] = np.nan
    return points


def check_label(label: str, forbidden: str, what: str, path) -> None:
    """Refuse a label that would corrupt a text file (line breaks, delimiters, empty).

    Raises
    ------
    MocapError
        Naming the label and the character.
    """
    if not label:
        raise MocapError(f"an empty {what} label cannot be written", path)
    for character in "\r\n" + forbidden:
        if character in label:
            name = {"\r": "a carriage return", "\n": "a line break", "\t": "a tab",
                    ",": "a comma", '"': "a quote", " ": "a space"}.get(character,
                                                                      repr(character))
            raise MocapError(f"{what} label {label!r} holds {name}, which would corrupt "
                             f"the file; rename it first", path)


#: Decimal places per unit for 1 nm resolution (the default) and for 1 µm (the coarsest).
_NM_PLACES = {"mm": 6, "cm": 7, "m": 9}
_UM_PLACES = {"mm": 3, "cm": 4, "m": 6}


def coordinate_decimals(units: str, precision: int | None, path=None) -> int:
    """Decimal places of coordinates written in ``units``.

    Default: 1 nm (6 places in mm, 7 in cm, 9 in m), which is at least 6 places in any
    unit. ``precision`` asks for another number of places; coarser than 1 µm (fewer
    than 3 in mm, 4 in cm, 6 in m) or more than 15 is refused.
    """
    if precision is None:
        return _NM_PLACES[units]
    if not isinstance(precision, (int, np.integer)) or isinstance(precision, bool):
        raise MocapError(f"precision must be a whole number of decimal places, not "
                         f"{precision!r}", path)
    if precision < _UM_PLACES[units] or precision > 15:
        raise MocapError(f"precision {precision} decimal places in {units} is "
                         f"{'coarser than 1 µm' if precision < _UM_PLACES[units] else 'more than 15'}"
                         f" (use {_UM_PLACES[units]} to 15)", path)
    return int(precision)
