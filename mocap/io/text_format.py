"""Numeric tables written as delimited text (CSV, TRC, MOT, angle CSV): fixed decimal places
per column, NaN as a word, every cell's digits at once in whole-array numpy.

Writing needs no numba, whose loading (~0.5 s per process) cost more than the whole
100 000 × 46 angle table takes to write. The written value is the number rounded to that many
places (``floor(|x| 10^p + 0.5)`` units of the last place, a tie away from zero, for every
table: a table too large for the fast writer's limit goes cell by cell in Python with the
same rule, :func:`_fixed`), so reading it back (:mod:`mocap.io.text_table`) is exact to half
a unit of the last place.
"""
from __future__ import annotations

import math

import numpy as np

from mocap.io.text_table import POW10

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
    blocks = [_format_block(table[start:start + WRITE_BLOCK_ROWS], places, delimiter,
                            nan == "NaN")
              for start in range(0, table.shape[0], WRITE_BLOCK_ROWS)]
    if all(block is not None for block in blocks):
        raw = b"".join(blocks)
        return raw if as_bytes else raw.decode("ascii")
    # a number too large for the whole-array writer: Python, cell by cell, same rounding
    text = "".join(delimiter.join(nan if value != value else _fixed(value, p)
                                  for value, p in zip(row, places.tolist())) + "\n"
                   for row in table.tolist())
    return text.encode("ascii") if as_bytes else text


#: Rows per call of :func:`_format_block`: its temporaries stay in the CPU cache (1.5 to 2
#: times faster than 4096 rows), and :func:`write_table` holds a block's text, not a second
#: copy of the whole file.
WRITE_BLOCK_ROWS = 1024


def write_table(handle, parts, decimals, delimiter: str, nan: str = "NaN") -> None:
    """Write :func:`format_table`'s text of columns given side by side, block by block.

    The same bytes as ``handle.write(format_table(np.column_stack(parts), decimals,
    delimiter, nan, as_bytes=True))``, without building the whole table or its whole
    text in memory (for 100 000 rows × 46 columns, 37 MB and 55 MB fewer fresh pages).

    Parameters
    ----------
    handle : binary file
        Open for writing.
    parts : sequence of ndarray, each shape (rows,) or (rows, k), float
        The table's columns in order; a 1-D part is one column.
    decimals, delimiter, nan
        As for :func:`format_table`.
    """
    parts = [np.asarray(part, dtype=float) for part in parts]
    parts = [part[:, None] if part.ndim == 1 else part for part in parts]
    rows = parts[0].shape[0] if parts else 0
    width = sum(part.shape[1] for part in parts)
    places = np.broadcast_to(np.asarray(decimals, dtype=np.int64), (width,)).copy()
    if rows <= WRITE_BLOCK_ROWS or not _compiled_can_write(parts, places):
        handle.write(format_table(np.column_stack(parts) if parts else np.zeros((0, 0)),
                                  places, delimiter, nan, as_bytes=True))
        return
    for start in range(0, rows, WRITE_BLOCK_ROWS):
        block = np.hstack([part[start:start + WRITE_BLOCK_ROWS] for part in parts])
        raw = _format_block(block, places, delimiter, nan == "NaN")
        assert raw is not None, "checked by _compiled_can_write"
        handle.write(raw)


#: Powers of ten as integers, and the bytes of eight ASCII zeros as one word.
_UNITS = 10 ** np.arange(16, dtype=np.uint64)
_ASCII_ZEROS = np.uint64(0x3030303030303030)
_ALL_BITS = np.uint64(0xFFFFFFFFFFFFFFFF)


def _format_block(table: np.ndarray, places: np.ndarray, delimiter: str,
                  nan_cells: bool) -> bytes | None:
    """Rows of :func:`format_table`'s large-table text, whole-array numpy.

    Each cell is rounded to ``u = floor(|x| 10^p + 0.5)`` units of its last place and
    written as ``[-]whole[.fraction]`` (no sign when ``u`` is 0); every cell gets a record
    of the same width, right-aligned with NUL bytes in front, and one ``bytes.translate``
    drops the NULs.

    Parameters
    ----------
    table : ndarray, shape (rows, cols), float
    places : ndarray of int, shape (cols,)
        Decimal places, 0 to 15.
    delimiter : str
        One character, after every cell but the last of a row (which gets ``\n``).
    nan_cells : bool
        Write NaN as ``NaN`` (else as an empty cell).

    Returns
    -------
    bytes, or None when a cell is infinite or ``|x| >= 9e15 / 10^p``.
    """
    rows, cols = table.shape
    scale = POW10[places]
    with np.errstate(invalid="ignore"):
        magnitude = np.abs(table)
        if (magnitude >= 9.0e15 / scale).any():           # inf too; NaN not
            return None
        missing = np.isnan(table)
        magnitude *= scale
        magnitude += 0.5
        np.floor(magnitude, out=magnitude)
    magnitude[missing] = 0.0
    units = magnitude.astype(np.uint64)
    negative = (table < 0) & (units != 0)
    groups = [(int(p), np.flatnonzero(places == p)) for p in np.unique(places)]
    parts = []
    for p, columns in groups:           # columns of the same places together
        value = units.ravel() if len(groups) == 1 else units[:, columns].ravel()
        whole = value // _UNITS[p]
        parts.append((p, columns, whole, value - whole * _UNITS[p]))
    digits = max(len(str(int(whole.max()))) for _, _, whole, _ in parts)
    most = int(places.max())
    width = max(digits + 2 + (most + 1 if most else 0), 4)       # sign ... delimiter
    record = np.zeros((rows, cols, width), dtype=np.uint8)
    for p, columns, whole, fraction in parts:
        alone = len(columns) == cols
        field = record.reshape(-1, width) if alone else \
            np.zeros((whole.size, width), dtype=np.uint8)
        end = width - 1
        if p:
            _put_ascii(field[:, :end], fraction, p)
            field[:, end - p - 1] = 46                         # "."
            end -= p + 1
        sign = negative.ravel() if alone else negative[:, columns].ravel()
        _put_whole(field[:, end - digits - 1:end], whole, sign, digits)
        if not alone:
            record[:, columns] = field.reshape(rows, len(columns), width)
    if missing.any():
        cell = np.zeros(width, dtype=np.uint8)
        if nan_cells:
            cell[width - 4:width - 1] = (78, 97, 78)           # "NaN"
        record[missing] = cell
    record[..., width - 1] = ord(delimiter)
    record[:, -1, width - 1] = 10
    return record.tobytes().translate(None, b"\0")


def _ascii8(value: np.ndarray) -> np.ndarray:
    """Eight zero-padded ASCII digits of each ``value`` (uint64, < 10^8) as the bytes of
    one uint64 (most significant first in memory, little-endian): the two halves of four
    digits, then two digits, then one, split by multiply-and-shift in lanes of one word."""
    high = value // np.uint64(10000)
    x = value - high * np.uint64(10000)
    x <<= np.uint64(32)
    x |= high                                   # 32-bit lanes: digits 1-4, digits 5-8
    q = x * np.uint64(10486)
    q >>= np.uint64(20)
    q &= np.uint64(0x0000007F0000007F)          # lane // 100 (exact below 10^4)
    x -= q * np.uint64(100)
    x <<= np.uint64(16)
    x |= q                                      # 16-bit lanes of two digits
    q = x * np.uint64(103)
    q >>= np.uint64(10)
    q &= np.uint64(0x000F000F000F000F)          # lane // 10 (exact below 100)
    x -= q * np.uint64(10)
    x <<= np.uint64(8)
    x |= q                                      # one digit per byte
    x += _ASCII_ZEROS
    return x


def _put_ascii(field: np.ndarray, value: np.ndarray, count: int) -> None:
    """Write ``count`` (at most 16) zero-padded digits of ``value`` (uint64, shape (n,))
    into the last ``count`` columns of ``field`` (n, >= count) uint8."""
    if count > 8:
        high = value // _UNITS[8]
        field[:, -8:] = _ascii8(value - high * _UNITS[8]).view(np.uint8).reshape(-1, 8)
        field[:, -count:-8] = _ascii8(high).view(np.uint8).reshape(-1, 8)[:, 16 - count:]
    else:
        field[:, -count:] = _ascii8(value).view(np.uint8).reshape(-1, 8)[:, 8 - count:]


def _put_whole(field: np.ndarray, whole: np.ndarray, negative: np.ndarray,
               digits: int) -> None:
    """The integer parts right-aligned in ``field`` (n, digits + 1) uint8: significant
    digits only (at least one), a ``-`` just before them where ``negative``."""
    count = np.ones(whole.size, dtype=np.uint64)               # significant digits
    for k in range(1, digits):
        count += whole >= _UNITS[k]
    if digits < 8:                      # one word: blank the leading zeros, add the sign
        word = _ascii8(whole)
        shift = (np.uint64(8) - count) * np.uint64(8)
        word &= np.left_shift(_ALL_BITS, shift)
        word |= np.left_shift(negative.astype(np.uint64) * np.uint64(45), shift - np.uint64(8))
        field[:] = word.view(np.uint8).reshape(-1, 8)[:, 7 - digits:]
        return
    _put_ascii(field, whole, digits)
    lead = np.arange(digits + 1)[None, :] < (digits + 1 - count.astype(np.int64))[:, None]
    field[lead] = 0
    where = np.flatnonzero(negative)
    field[where, digits - count[where].astype(np.int64)] = 45


def _compiled_can_write(parts: list[np.ndarray], places: np.ndarray) -> bool:
    """Whether :func:`_format_block` accepts every cell: finite or NaN, and below its limit
    (``9e15`` units of the last decimal place), as it checks."""
    if places.min() < 0 or places.max() > 15:
        return True             # format_table raises the error
    limit = 9.0e15 / POW10[places]
    first = 0
    for part in parts:
        if part.shape[0]:
            with np.errstate(invalid="ignore"):
                largest = np.fmax(np.fmax.reduce(part, axis=0), -np.fmin.reduce(part, axis=0))
            if (largest >= limit[first:first + part.shape[1]]).any():  # inf too; NaN not
                return False
        first += part.shape[1]
    return True


def _fixed(value: float, places: int) -> str:
    """``value`` with ``places`` decimals, rounded as :func:`_format_block` rounds
    (``floor(|x| 10^p + 0.5)`` units, so a tie goes away from zero); no sign on a value
    that rounds to zero. Beyond that writer's limit (``|x| >= 9e15 / 10^p``, where every
    float is a whole number of units), Python's exact formatting.

    >>> _fixed(0.125, 2), _fixed(-2.5, 0), _fixed(-0.0004, 3)
    ('0.13', '-3', '0.000')
    """
    scale = 10.0 ** places
    if abs(value) < 9.0e15 / scale:
        units = math.floor(abs(value) * scale + 0.5)
        whole, fraction = divmod(units, 10 ** places)
        sign = "-" if value < 0 and units else ""
        return f"{sign}{whole}.{fraction:0{places}d}" if places else f"{sign}{whole}"
    text = f"{value:.{places}f}"
    return text[1:] if text[0] == "-" and not text.strip("-0.") else text
