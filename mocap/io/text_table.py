"""Helpers shared by the text formats (CSV, TRC): numeric tables with empty cells."""
from __future__ import annotations

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
