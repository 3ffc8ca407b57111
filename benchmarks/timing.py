"""Timing helpers shared by the benchmark scripts (run them as ``python benchmarks/X.py``)."""
from __future__ import annotations

import statistics
import time
from typing import Callable


def best_of(function: Callable[[], object], repeats: int = 3) -> float:
    """Shortest wall time of ``repeats`` calls of ``function``, seconds."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def median_of(function: Callable[[], object], repeats: int = 5) -> float:
    """Median wall time of ``repeats`` calls of ``function``, seconds."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)
