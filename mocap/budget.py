"""The memory budget of reading: what a file declares is checked before anything is allocated.

A header (a TRC's marker columns, a CSV's columns, a C3D's frames and points, an AMC's
frames, a scene's cloth resolution) says how large the arrays will be; a damaged or hostile
one can ask for gigabytes. Every reader checks what the header asks for against
:func:`read_budget` (1 GB of numbers by default, ``MOCAP_READ_BUDGET_MB`` to change it)
and, where it can, against the bytes present, and refuses with one line naming the file
before allocating: no ``MemoryError``, no minutes of swapping.
"""
from __future__ import annotations

import math
import os

from mocap.errors import MocapError

#: Bytes of numbers (float64) a file may take when read: 1 GB, 125 million
#: cells (for example 150 markers over 300 000 frames). The reading takes about three
#: times the table at its peak. ``MOCAP_READ_BUDGET_MB`` in the environment sets another.
READ_BUDGET_BYTES = 1_000_000_000


def read_budget() -> int:
    """The memory budget of a table being read, bytes (:data:`READ_BUDGET_BYTES`, or
    ``MOCAP_READ_BUDGET_MB`` megabytes when that is set to a positive number)."""
    text = os.environ.get("MOCAP_READ_BUDGET_MB", "")
    try:
        megabytes = float(text)
    except ValueError:
        return READ_BUDGET_BYTES
    return int(megabytes * 1e6) if math.isfinite(megabytes) and megabytes > 0 \
        else READ_BUDGET_BYTES


#: Below this many bytes a table is never refused for the bytes present (a few short rows
#: of a small file are ragged rows, warned about, not a size problem).
SPARSE_FLOOR_BYTES = 64 << 20


def check_table_size(lines: int, size: int, width: int, path=None,
                     what: str = "columns") -> None:
    """Refuse, before anything is allocated, a table that would not fit: what a header
    declares (``width`` columns) is checked against the memory budget (:func:`read_budget`)
    and against the bytes present.

    Parameters
    ----------
    lines : int
        Lines of the table's text (each may be a row).
    size : int
        Bytes of the table's text.
    width : int
        Columns the header names.

    The table can take up to ``lines × width × 8`` bytes. Beyond the budget the file is refused; and so it is when that is beyond
    :data:`SPARSE_FLOOR_BYTES` while the text holds fewer bytes than the cells it would
    fill (a row of ``width`` cells takes at least ``width`` bytes: its delimiters and line
    break), which is garbage after a header or a header naming far more columns than the
    rows hold.

    Raises
    ------
    MocapError
        Naming the lines, the columns and the megabytes it would take.

    >>> check_table_size(3_000_000, 12_000_000, 1_000_000, "big.csv")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    mocap.errors.MocapError: big.csv: the header names 1000000 columns and the file has ...
    """
    need = 8 * lines * width
    budget = read_budget()
    if need > budget:
        raise MocapError(f"the header names {width} {what} and the file has {lines} lines: "
                         f"reading them would take {need / 1e6:.0f} MB, more than the "
                         f"reading budget of {budget / 1e6:.0f} MB (MOCAP_READ_BUDGET_MB)",
                         path)
    if need > SPARSE_FLOOR_BYTES and lines * width > size:
        raise MocapError(f"the header names {width} {what}, but the {lines} lines after it "
                         f"hold only {size} bytes, fewer than one per cell: the rows "
                         f"do not match the header (damaged, or not this format)", path)


def check_budget(need: float, what: str, path=None) -> None:
    """Refuse ``what`` (a description such as ``"1000000 frames × 31 bones"``) that would
    take ``need`` bytes when that is more than :func:`read_budget`.

    >>> check_budget(8e12, "10^12 samples", "huge.amc")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    mocap.errors.MocapError: huge.amc: 10^12 samples would take 8000000 MB, more than ...
    """
    budget = read_budget()
    if need > budget:
        raise MocapError(f"{what} would take {need / 1e6:.0f} MB, more than the reading "
                         f"budget of {budget / 1e6:.0f} MB (MOCAP_READ_BUDGET_MB)", path)


def read_npz(path, damaged: str) -> dict:
    """The arrays of a numpy ``.npz`` archive, each member's declared size checked against
    :func:`read_budget` before it is read.

    Parameters
    ----------
    path : str or PathLike
    damaged : str
        The message of the :class:`MocapError` for a file that is not a readable archive
        (truncated, a bad checksum, a member that is not an array, pickled objects).

    Returns
    -------
    dict of str → ndarray

    Raises
    ------
    MocapError
        ``damaged`` (with the reason), or the budget's refusal naming the member: a
        compressed archive can declare gigabytes in a few kilobytes.
    """
    import zipfile
    import zlib

    import numpy as np

    try:
        with zipfile.ZipFile(path) as archive:
            total = 0
            for info in archive.infolist():
                with archive.open(info) as member:
                    version = np.lib.format.read_magic(member)
                    header = np.lib.format.read_array_header_1_0 if version == (1, 0) \
                        else np.lib.format.read_array_header_2_0
                    shape, _, dtype = header(member)
                total += math.prod(shape) * dtype.itemsize
                check_budget(total, f"its arrays (up to {info.filename!r})", path)
        with np.load(path, allow_pickle=False) as archive:
            return {key: archive[key] for key in archive.files}
    except MocapError:
        raise
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile, zlib.error) as error:
        reason = str(error).splitlines()[0] if str(error) else type(error).__name__
        raise MocapError(f"{damaged} ({reason})", path) from None
