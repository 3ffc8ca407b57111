"""Helpers shared by the text formats (CSV, TRC): numeric tables with empty cells."""
from __future__ import annotations

import io
import os

import numpy as np

from mocap.errors import MocapError


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


def parse_numeric_rows(lines: list[str], delimiter: str, width: int) -> np.ndarray:
    """Numbers of delimited text rows, empty or unparsable cells as NaN.

    Parameters
    ----------
    lines : list of str
        Data rows (no header), already stripped of line ends.
    delimiter : str
    width : int
        Columns to keep; shorter rows are padded with NaN, longer ones cut.

    Returns
    -------
    ndarray, shape (len(lines), width), float

    Notes
    -----
    ``numpy.loadtxt`` parses the common case (every cell present) in C; rows
    with empty cells fall back to a split per row, which text formats cannot
    avoid.
    """
    if not lines:
        return np.zeros((0, width))
    try:
        table = np.loadtxt(lines, delimiter=delimiter, ndmin=2, dtype=float)
        if table.shape[1] >= width:
            return table[:, :width]
    except ValueError:
        pass
    table = np.full((len(lines), width), np.nan)
    for row, line in enumerate(lines):
        cells = line.split(delimiter)[:width]
        for column, cell in enumerate(cells):
            cell = cell.strip()
            if cell:
                try:
                    table[row, column] = float(cell)
                except ValueError:
                    pass            # a stray word in a number column: missing
    return table


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


def format_rows(columns: np.ndarray, delimiter: str) -> str:
    """Rows of numbers as delimited text, one per line.

    Each number is written as its shortest exact text (``repr``), so reading
    the file back gives the same float64; NaN is written as an empty cell.

    Parameters
    ----------
    columns : ndarray, shape (rows, cols), float
    """
    rows, cols = columns.shape
    if rows == 0:
        return ""
    cells = ["" if value != value else repr(value) for value in columns.ravel().tolist()]
    return "".join(delimiter.join(cells[r * cols:(r + 1) * cols]) + "\n"
                   for r in range(rows))


#: Largest magnitude :func:`format_fixed` writes with integer arithmetic (beyond it, and for
#: infinities, it falls back to ``%.*f`` formatting).
_FIXED_LIMIT = 1e12


def format_fixed(table: np.ndarray, decimals: int = 6, delimiter: str = ",",
                 chunk_rows: int = 16384) -> bytes:
    """Rows of numbers as fixed-point text, vectorised: ``-12.345679,0.500000\\n`` …

    The text of each cell is that of ``"%.{decimals}f"`` for the value rounded to the
    nearest ``10**-decimals`` (computed as ``rint(|x| * 10**decimals)``, so a value within
    an ulp of a rounding tie may round the other way; the written number is always within
    ``0.5 * 10**-decimals`` plus one ulp of ``x``). NaN is an empty cell.

    Parameters
    ----------
    table : ndarray, shape (rows, cols), float
    decimals : int
        Digits after the point, 1 to 9.
    delimiter : str
        One character between cells; rows end in ``\\n``.
    chunk_rows : int
        Rows formatted at once (bounds the memory to about 22 bytes per cell of a chunk).

    Returns
    -------
    bytes
        ASCII text, ``rows`` lines.
    """
    table = np.asarray(table, dtype=float)
    rows, cols = table.shape
    finite = np.isfinite(table)
    if not (np.abs(table[finite]) < _FIXED_LIMIT).all() or (~finite & ~np.isnan(table)).any():
        text = io.StringIO()
        np.savetxt(text, table, fmt=f"%.{decimals}f", delimiter=delimiter)
        return text.getvalue().replace("nan", "").encode("ascii")
    return b"".join(_fixed_chunk(table[start:start + chunk_rows], decimals, delimiter)
                    for start in range(0, rows, chunk_rows))


_DIGIT_TABLES: dict[int, np.ndarray] = {}


def _digit_table(decimals: int) -> np.ndarray:
    """ASCII digits of 0 … 10**decimals - 1, zero-padded: shape (10**decimals, decimals)."""
    if decimals not in _DIGIT_TABLES:
        numbers = np.arange(10 ** decimals, dtype=np.int32)
        table = np.empty((numbers.size, decimals), dtype=np.uint8)
        for k in range(decimals):
            numbers, digit = np.divmod(numbers, 10)
            table[:, decimals - 1 - k] = digit + 48
        _DIGIT_TABLES[decimals] = table
    return _DIGIT_TABLES[decimals]


def _fixed_chunk(table: np.ndarray, decimals: int, delimiter: str) -> bytes:
    """One block of rows: each cell right-aligned in a fixed-width byte row, the unused
    leading bytes NUL, removed at the end."""
    rows, cols = table.shape
    missing = np.isnan(table).ravel()
    values = np.where(missing, 0.0, table.ravel())
    scaled = np.rint(np.abs(values) * 10.0 ** decimals).astype(np.int64)
    whole, fraction = np.divmod(scaled, 10 ** decimals)
    most = int(whole.max()) if whole.size else 0
    digits = len(str(most))                            # integer digits of the widest cell
    if most < 2 ** 31:
        whole = whole.astype(np.int32)
    int_digits = np.ones(values.size, dtype=np.int8)
    for k in range(1, digits):
        int_digits += whole >= 10 ** k
    negative = np.signbit(values)
    width = 1 + digits + 1 + decimals + 1              # sign, digits, point, decimals, end
    chars = np.empty((values.size, width), dtype=np.uint8)
    chars[:, -1] = ord(delimiter)
    chars[cols - 1::cols, -1] = ord("\n")
    chars[:, -1 - decimals:-1] = _digit_table(decimals)[fraction]
    point = width - 2 - decimals
    chars[:, point] = ord(".")
    for k in range(digits + 1):                        # integer digits, then the sign
        whole, digit = np.divmod(whole, 10)
        chars[:, point - 1 - k] = np.where(k < int_digits, digit + 48,
                                           np.where((k == int_digits) & negative, 45, 0))
    if missing.any():
        chars[missing, :-1] = 0
    return chars.tobytes().replace(b"\0", b"")
