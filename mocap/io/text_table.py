"""Helpers shared by the text formats (CSV, TRC, MOT): numeric tables as delimited text.

Numbers are read and written by two compiled loops (numba, cached on disk), one pass
over the bytes each: reading and writing a 20 000 × 60 marker table takes tenths of a
second where a Python loop per cell took seconds (``benchmarks/io.py``).

Reading is exact: a number with at most 15 significant digits and a decimal
exponent within ±22 (every number a TRC or CSV file holds in practice) is an exact
integer divided or multiplied by an exact power of ten, one correctly rounded
operation, so it gives the same float64 as ``float(text)``; any other number is
handed to ``float`` itself. Empty cells, ``NaN`` and words read as NaN.

Writing uses a fixed number of decimal places per column; the written value is the
number rounded to that many places, so reading it back is exact to half a unit of
the last place. NaN is written as ``NaN``, which OpenSim, numpy and pandas read
(OpenSim drops empty cells at the end of a row and then rejects the row).
"""
from __future__ import annotations

import os

import numba
import numpy as np

from mocap.errors import MocapError

#: Bytes the parser treats as blank around a cell.
_SPACE, _CR, _NL = 32, 13, 10
_POW10 = np.array([10.0 ** k for k in range(23)])


def read_lines(path: str | os.PathLike, encoding: str = "utf-8") -> list[str]:
    """Lines of a text file; a missing or unreadable file is a :class:`MocapError`."""
    try:
        with open(path, "r", encoding=encoding, errors="replace", newline=None) as handle:
            return handle.read().splitlines()
    except FileNotFoundError:
        raise MocapError("no such file", path) from None
    except OSError as error:
        raise MocapError(f"cannot read file: {error.strerror or error}", path) from None


def read_text(path: str | os.PathLike, what: str = "file") -> str:
    """The whole text of a UTF-8 file; missing, unreadable or undecodable is a
    :class:`MocapError` naming the file (``what`` names its kind in the message)."""
    try:
        return open(path, encoding="utf-8").read()
    except FileNotFoundError:
        raise MocapError(f"{what} not found", path) from None
    except (OSError, UnicodeDecodeError) as error:
        raise MocapError(f"cannot read {what}: {error}", path) from None


def read_head(path: str | os.PathLike, count: int,
              encoding: str = "utf-8") -> tuple[list[str], bytes]:
    """The first ``count`` lines of a file as text and the rest as raw bytes.

    The header of a text table is small and read as text; the body goes to
    :func:`parse_table` unsplit.
    """
    try:
        with open(path, "rb") as handle:
            raw = handle.read()
    except FileNotFoundError:
        raise MocapError("no such file", path) from None
    except IsADirectoryError:
        raise MocapError("is a directory, not a file", path) from None
    except OSError as error:
        raise MocapError(f"cannot read file: {error.strerror or error}", path) from None
    if encoding == "utf-8-sig" and raw.startswith(b"\xef\xbb\xbf"):
        raw = raw[3:]
    lines = []
    position = 0
    for _ in range(count):
        end = raw.find(b"\n", position)
        if end < 0:
            lines.append(raw[position:])
            position = len(raw)
            break
        lines.append(raw[position:end])
        position = end + 1
    text = [line.decode("utf-8", errors="replace").rstrip("\r") for line in lines]
    return text, raw[position:]


@numba.njit(cache=True, nogil=True)
def _parse_kernel(data, delimiter, width, pow10):         # pragma: no cover - compiled
    n = data.size
    lines = 1
    for i in range(n):
        if data[i] == 10:
            lines += 1
    table = np.empty((lines, width))
    slow_rows = [0]
    slow_cols = [0]
    slow_start = [0]
    slow_end = [0]
    slow = 0
    row = 0
    start = 0
    while start < n:
        end = start
        blank = True
        while end < n and data[end] != 10:
            c = data[end]
            if blank and c != delimiter and c != 32 and c != 13 and c != 9:
                blank = False
            end += 1
        if blank:
            start = end + 1
            continue
        col = 0
        i = start
        while i <= end and col < width:
            j = i
            while j < end and data[j] != delimiter:
                j += 1
            a = i
            b = j
            while a < b and (data[a] == 32 or data[a] == 13 or data[a] == 9):
                a += 1
            while b > a and (data[b - 1] == 32 or data[b - 1] == 13 or data[b - 1] == 9):
                b -= 1
            value = np.nan
            ok = True
            if b > a:
                k = a
                negative = data[k] == 45
                if negative or data[k] == 43:
                    k += 1
                mantissa = 0
                first = k
                while k < b and 48 <= data[k] <= 57:
                    mantissa = mantissa * 10 + (data[k] - 48)
                    k += 1
                count = k - first
                fraction = 0
                if k < b and data[k] == 46:
                    k += 1
                    first = k
                    while k < b and 48 <= data[k] <= 57:
                        mantissa = mantissa * 10 + (data[k] - 48)
                        k += 1
                    fraction = k - first
                    count += fraction
                exponent = 0
                if count > 0 and k < b and (data[k] == 101 or data[k] == 69):
                    k += 1
                    exp_negative = False
                    if k < b and (data[k] == 45 or data[k] == 43):
                        exp_negative = data[k] == 45
                        k += 1
                    first = k
                    while k < b and 48 <= data[k] <= 57 and k - first < 6:
                        exponent = exponent * 10 + (data[k] - 48)
                        k += 1
                    if k == first:
                        ok = False
                    if exp_negative:
                        exponent = -exponent
                if ok and count > 0 and k == b and count <= 18 \
                        and mantissa <= 9007199254740992:
                    power = exponent - fraction
                    value = float(mantissa)
                    if 0 <= power <= 22:
                        value = value * pow10[power]
                    elif -22 <= power < 0:
                        value = value / pow10[-power]
                    elif mantissa != 0:
                        ok = False
                    if negative:
                        value = -value
                elif not (b - a == 3 and (data[a] == 78 or data[a] == 110)
                          and (data[a + 1] == 65 or data[a + 1] == 97)
                          and (data[a + 2] == 78 or data[a + 2] == 110)):
                    ok = False
                if not ok:
                    value = np.nan
                    slow_rows.append(row)
                    slow_cols.append(col)
                    slow_start.append(a)
                    slow_end.append(b)
                    slow += 1
            table[row, col] = value
            col += 1
            i = j + 1
        while col < width:
            table[row, col] = np.nan
            col += 1
        row += 1
        start = end + 1
    fallback = np.empty((slow, 4), dtype=np.int64)
    for m in range(slow):
        fallback[m, 0] = slow_rows[m + 1]
        fallback[m, 1] = slow_cols[m + 1]
        fallback[m, 2] = slow_start[m + 1]
        fallback[m, 3] = slow_end[m + 1]
    return table[:row], fallback


def parse_table(data: bytes | str, delimiter: str, width: int) -> np.ndarray:
    """Numbers of delimited text rows; blank lines skipped, empty or unparsable cells NaN.

    Parameters
    ----------
    data : bytes or str
        The table's rows (no header), lines ended by ``\\n`` (``\\r\\n`` is fine).
    delimiter : str
        One character (``"\\t"`` or ``","``); spaces around a cell are ignored.
    width : int
        Columns to keep; shorter rows are padded with NaN, longer ones cut.

    Returns
    -------
    ndarray, shape (rows, width), float
    """
    if isinstance(data, str):
        data = data.encode("utf-8")
    buffer = np.frombuffer(data, dtype=np.uint8)
    table, fallback = _parse_kernel(buffer, np.uint8(ord(delimiter)), int(width), _POW10)
    for row, col, a, b in fallback:
        try:
            table[row, col] = float(data[a:b])
        except ValueError:
            pass            # a stray word in a number column: missing
    return table


def parse_numeric_rows(lines: list[str], delimiter: str, width: int) -> np.ndarray:
    """:func:`parse_table` of rows given as a list of lines (each one row, kept in order).

    Blank lines are skipped, as by :func:`parse_table`.
    """
    if not lines:
        return np.zeros((0, width))
    return parse_table("\n".join(lines) + "\n", delimiter, width)


@numba.njit(cache=True, nogil=True)
def _format_kernel(table, decimals, delimiter, pow10, nan_cells):   # pragma: no cover
    rows, cols = table.shape
    max_decimals = 0
    for c in range(cols):
        if decimals[c] > max_decimals:
            max_decimals = decimals[c]
    out = np.empty(rows * cols * (23 + max_decimals) + 1, dtype=np.uint8)
    digits = np.empty(40, dtype=np.uint8)
    position = 0
    for r in range(rows):
        for c in range(cols):
            x = table[r, c]
            if x != x:
                if nan_cells:
                    out[position] = 78
                    out[position + 1] = 97
                    out[position + 2] = 78
                    position += 3
            else:
                places = decimals[c]
                negative = x < 0
                magnitude = -x if negative else x
                if magnitude >= 9.0e15 / pow10[places] or not magnitude < np.inf:
                    return out[:0], False
                scaled = np.int64(np.floor(magnitude * pow10[places] + 0.5))
                if scaled == 0:
                    negative = False
                if negative:
                    out[position] = 45
                    position += 1
                count = 0
                while scaled > 0 or count <= places:
                    digits[count] = 48 + scaled % 10
                    scaled //= 10
                    count += 1
                for k in range(count - 1, -1, -1):
                    out[position] = digits[k]
                    position += 1
                    if k == places and places > 0:
                        out[position] = 46
                        position += 1
            out[position] = delimiter if c < cols - 1 else 10
            position += 1
    return out[:position], True


def format_table(table: np.ndarray, decimals, delimiter: str, nan: str = "NaN",
                 as_bytes: bool = False) -> str | bytes:
    """Rows of numbers as delimited text with fixed decimal places, one row per line.

    Parameters
    ----------
    table : ndarray, shape (rows, cols), float
    decimals : int or sequence of int, one per column
        Decimal places (0 writes integers such as frame numbers).
    delimiter : str
        One character.
    nan : {"NaN", ""}
        Text of a missing value: ``NaN`` or an empty cell.
    as_bytes : bool
        Return ASCII bytes (ready to write) instead of str.

    Returns
    -------
    str or bytes
        Every row ends with ``\\n``.
    """
    if nan not in ("NaN", ""):
        raise ValueError("nan must be 'NaN' or ''")
    table = np.ascontiguousarray(table, dtype=float)
    if table.ndim != 2:
        raise ValueError(f"table must be 2-D, got shape {table.shape}")
    places = np.broadcast_to(np.asarray(decimals, dtype=np.int64), (table.shape[1],)).copy()
    if places.size and (places.min() < 0 or places.max() > 15):
        raise ValueError("decimal places must be 0 to 15")
    if table.size == 0:
        return b"" if as_bytes else ""
    raw, ok = _format_kernel(table, places, np.uint8(ord(delimiter)), _POW10, nan == "NaN")
    if ok:
        return raw.tobytes() if as_bytes else raw.tobytes().decode("ascii")
    # a number too large for the compiled loop (or infinite): Python's own formatting
    text = "".join(delimiter.join(nan if value != value else f"{value:.{p}f}"
                                  for value, p in zip(row, places.tolist())) + "\n"
                   for row in table.tolist())
    return text.encode("ascii") if as_bytes else text


def format_fixed(table: np.ndarray, decimals: int = 6, delimiter: str = ",") -> bytes:
    """Rows of numbers as fixed-point text, NaN as an empty cell: ``-12.345679,,0.5\\n``.

    :func:`format_table` with one number of decimals for every column (the angle CSV's
    writer); ASCII bytes, ready to write.
    """
    return format_table(table, decimals, delimiter, nan="", as_bytes=True)


def mark_missing(points: np.ndarray) -> np.ndarray:
    """Set to NaN every sample with a non-finite coordinate or exactly at (0, 0, 0).

    Parameters
    ----------
    points : ndarray, shape (frames, markers, 3)
        Modified in place and returned.
    """
    missing = ~np.isfinite(points).all(axis=2) | (points == 0).all(axis=2)
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
