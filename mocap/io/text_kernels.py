"""The compiled loops of :mod:`mocap.io.text_table` (numba, cached on disk).

Imported only for tables large enough to be worth loading numba (~1.5 s per process).
``parse_kernel`` reads delimited numbers in one pass over the bytes (exact: an integer
mantissa of at most 2**53 times or divided by an exact power of ten, else the cell is
handed back for Python's ``float``); ``format_kernel`` writes fixed decimals: the value
rounded to its column's places as an integer (``floor(|x| 10^p + 0.5)``), written two
digits at a time, integer part then fraction.
"""
from __future__ import annotations

import numba
import numpy as np

#: Exact powers of ten as float64.
POW10 = np.array([10.0 ** k for k in range(23)])
#: "00" to "99" as ASCII digit pairs (``PAIRS[2k]``, ``PAIRS[2k + 1]``): the writer puts
#: down two digits per division.
PAIRS = np.array([list(f"{k:02d}".encode()) for k in range(100)], dtype=np.uint8).reshape(-1)


@numba.njit(cache=True, nogil=True)
def parse_kernel(data, delimiter, width, pow10):         # pragma: no cover - compiled
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


@numba.njit(cache=True, nogil=True, inline="always")
def _put_digits(out, end, value, digits):                 # pragma: no cover - compiled
    """Write the last ``digits`` decimal digits of ``value`` (>= 0) into ``out`` ending
    before ``end``, two at a time from the last, with leading zeros: the integer part
    (``digits`` its digit count) and the fraction (``digits`` the places) alike."""
    k = end
    while digits >= 2:
        q = value // 100
        pair = 2 * (value - q * 100)
        out[k - 1] = PAIRS[pair + 1]
        out[k - 2] = PAIRS[pair]
        k -= 2
        value = q
        digits -= 2
    if digits == 1:
        out[k - 1] = 48 + value


@numba.njit(cache=True, nogil=True)
def format_kernel(table, decimals, delimiter, pow10, nan_cells):   # pragma: no cover
    rows, cols = table.shape
    max_decimals = 0
    for c in range(cols):
        if decimals[c] > max_decimals:
            max_decimals = decimals[c]
    out = np.empty(rows * cols * (23 + max_decimals) + 1, dtype=np.uint8)
    units = np.empty(16, dtype=np.int64)
    u = 1
    for k in range(16):
        units[k] = u
        u *= 10
    limits = np.empty(cols)
    scales = np.empty(cols)
    column_units = np.empty(cols, dtype=np.int64)
    for c in range(cols):
        limits[c] = 9.0e15 / pow10[decimals[c]]
        scales[c] = pow10[decimals[c]]
        column_units[c] = units[decimals[c]]
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
                if magnitude >= limits[c] or not magnitude < np.inf:
                    return out[:0], False
                scaled = np.int64(np.floor(magnitude * scales[c] + 0.5))
                if scaled == 0:
                    negative = False
                if negative:
                    out[position] = 45
                    position += 1
                unit = column_units[c]
                whole = scaled // unit
                fraction = scaled - whole * unit
                count = 1
                while count < 16 and whole >= units[count]:
                    count += 1
                _put_digits(out, position + count, whole, count)
                position += count
                if places > 0:
                    out[position] = 46
                    position += 1
                    _put_digits(out, position + places, fraction, places)
                    position += places
            out[position] = delimiter if c < cols - 1 else 10
            position += 1
    return out[:position], True
