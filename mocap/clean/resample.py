"""The one resampling of curves: linear interpolation of every column at evenly spaced
instants, used to time-normalise gait cycles (:func:`mocap.plugingait.events.normalise_cycles`)
and the cycles of a synthesis corpus (:mod:`synthesis.cycles`)."""
from __future__ import annotations

import numpy as np


def resample(times: np.ndarray, values: np.ndarray, start: float, end: float,
             samples: int) -> np.ndarray:
    """Linear interpolation of every column at ``samples`` instants from ``start`` to ``end``.

    Parameters
    ----------
    times : ndarray, shape (frames,), increasing (seconds, or frame numbers)
    values : ndarray, shape (frames, columns)
        A sample blended from a NaN neighbour is NaN.
    start, end : float
        In the unit of ``times``; both instants are included.
    samples : int

    Returns
    -------
    ndarray, shape (samples, columns)

    Examples
    --------
    >>> resample(np.arange(3.0), np.array([[0.0], [10.0], [30.0]]), 0.0, 2.0, 5)[:, 0]
    array([ 0.,  5., 10., 20., 30.])
    """
    instants = np.linspace(start, end, samples)
    # Vectorised over columns: locate each instant once, then blend its two neighbours.
    right = np.clip(np.searchsorted(times, instants, side="right"), 1, len(times) - 1)
    left = right - 1
    span = times[right] - times[left]
    weight = np.clip((instants - times[left]) / np.where(span > 0, span, 1.0), 0.0, 1.0)
    return values[left] * (1.0 - weight)[:, None] + values[right] * weight[:, None]
