"""The compiled reading loop of :mod:`mocap.io.text_table` (numba, cached on disk).

Imported only for tables large enough to be worth loading numba (~1.5 s per process).
``parse_kernel`` reads delimited numbers in one pass over the bytes (exact: an integer
mantissa of at most 2**53 times or divided by an exact power of ten, else the cell is
handed back for Python's ``float``) and counts each row's cells (a row of fewer cells
than ``width``: its count; of more: up to its last cell that is not blank). Writing needs no compiled loop
(:func:`mocap.io.text_format._format_block`).
"""
from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def parse_kernel(data, delimiter, width, pow10):         # pragma: no cover - compiled
    n = data.size
    lines = 1
    for i in range(n):
        if data[i] == 10:
            lines += 1
    table = np.empty((lines, width))
    cells = np.empty(lines, dtype=np.int64)
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
        filled = col
        if col == width:
            # cells beyond the width: the last one that is not blank counts
            while i <= end:
                j = i
                blank = True
                while j < end and data[j] != delimiter:
                    c = data[j]
                    if c != 32 and c != 13 and c != 9:
                        blank = False
                    j += 1
                col += 1
                if not blank:
                    filled = col
                i = j + 1
        cells[row] = filled
        while filled < width:
            table[row, filled] = np.nan
            filled += 1
        row += 1
        start = end + 1
    fallback = np.empty((slow, 4), dtype=np.int64)
    for m in range(slow):
        fallback[m, 0] = slow_rows[m + 1]
        fallback[m, 1] = slow_cols[m + 1]
        fallback[m, 2] = slow_start[m + 1]
        fallback[m, 3] = slow_end[m + 1]
    return table[:row], fallback, cells[:row]
