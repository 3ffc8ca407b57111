"""Time normalisation of joint-angle curves: unwrap, bridge gaps, resample, detect cycles.

One trial's angle curves (frames, columns) become one gait cycle of ``samples`` frames
(:func:`normalise_cycles`):

* **Unwrapping** (:func:`mocap.angles.unwrap_columns`). Every angle is unwrapped (no ±180° jumps) before
  interpolation, over the samples where it is defined (NaN where markers were missing); gaps
  are bridged by linear interpolation of the unwrapped angle (:func:`interpolate_missing`).
* **One cycle per trial** (default): the whole trial is the cycle; it is resampled linearly to
  ``samples`` instants spanning its first to its last frame (:func:`resample`), and the cycle's
  duration is the trial's duration (last time − first time).
* **Cycle detection** (``cycles=True``, :func:`detect_cycles`): the cycles are cut at the
  maxima of one reference angle, by default the angle that moves most over the corpus (usually
  hip or knee flexion; its maximum falls near the same gait event in every trial, so phase 0
  agrees across trials and actions). The period is first estimated from the highest
  autocorrelation peak of the reference after its first zero crossing
  (:func:`estimate_period`); maxima are then found with ``scipy.signal.find_peaks`` at least
  0.7 periods apart and with a prominence of a quarter of the signal's range, and refined to
  sub-frame time by a parabola through the three samples around each maximum. Consecutive
  maxima 0.6–1.5 periods apart bound one cycle; every cycle is resampled to ``samples``
  instants and the cycles are averaged (durations too).
* **Branch** (:func:`centre_branch`). Each angle curve is shifted by a whole number of turns
  so that its mean lies in (−180°, 180°], so cycles and trials unwrapped from different
  starting branches agree.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.signal import find_peaks

from mocap.angles import unwrap_columns
from mocap.errors import MocapError

#: Default number of samples per normalised cycle.
DEFAULT_SAMPLES = 100


def interpolate_missing(times: np.ndarray, values: np.ndarray,
                        source: str | Path | None = None) -> np.ndarray:
    """Bridge NaN samples of each column by linear interpolation in time (constant at the ends).

    Parameters
    ----------
    times : ndarray, shape (frames,), seconds, increasing
    values : ndarray, shape (frames, columns), degrees; NaN where undefined
    source : path, optional
        For error messages.

    Returns
    -------
    ndarray, shape (frames, columns), without NaN

    Raises
    ------
    MocapError
        When a column has fewer than two defined samples.
    """
    values = np.array(values, dtype=float)
    missing = np.isnan(values)
    if not missing.any():
        return values
    for column in np.flatnonzero(missing.any(axis=0)):   # loop over incomplete columns only
        rows = ~missing[:, column]
        if rows.sum() < 2:
            raise MocapError(f"angle column {column} has fewer than two defined samples "
                             "(its markers are missing); fill the gaps or drop the trial", source)
        values[~rows, column] = np.interp(times[~rows], times[rows], values[rows, column])
    return values


def resample(times: np.ndarray, values: np.ndarray, start: float, end: float,
             samples: int) -> np.ndarray:
    """Linear interpolation of every column at ``samples`` instants from ``start`` to ``end``.

    The one resampling of curves: trial → cycle here, and a model's cycle to another sample
    count (:meth:`synthesis.model.MotionModel.synthesize`).

    Parameters
    ----------
    times : ndarray, shape (frames,), seconds, increasing
    values : ndarray, shape (frames, columns), without NaN
    start, end : float
        Seconds; both instants are included.
    samples : int

    Returns
    -------
    ndarray, shape (samples, columns)
    """
    instants = np.linspace(start, end, samples)
    # Vectorised over columns: locate each instant once, then blend its two neighbours.
    right = np.clip(np.searchsorted(times, instants, side="right"), 1, len(times) - 1)
    left = right - 1
    span = times[right] - times[left]
    weight = np.clip((instants - times[left]) / np.where(span > 0, span, 1.0), 0.0, 1.0)
    return values[left] * (1.0 - weight)[:, None] + values[right] * weight[:, None]


def centre_branch(curves: np.ndarray) -> np.ndarray:
    """Shift every angle curve by whole turns so its mean lies in (−180°, 180°].

    Parameters
    ----------
    curves : ndarray, shape (..., samples, columns), degrees
    """
    means = np.nanmean(curves, axis=-2, keepdims=True)
    return curves - 360.0 * np.ceil((means - 180.0) / 360.0)


def estimate_period(times: np.ndarray, signal: np.ndarray) -> float | None:
    """Period of a roughly periodic signal from its autocorrelation, seconds.

    The highest autocorrelation peak after the first zero crossing (lags up to half the
    record).

    Parameters
    ----------
    times : ndarray, shape (frames,), seconds, evenly spaced
    signal : ndarray, shape (frames,), without NaN

    Returns
    -------
    float or None
        Seconds; ``None`` when the signal shows no repetition.
    """
    x = signal - signal.mean()
    n = x.size
    if n < 8 or not np.any(x):
        return None
    spectrum = np.fft.rfft(x, 2 * n)
    correlation = np.fft.irfft(spectrum * np.conj(spectrum))[:n]
    correlation /= correlation[0]
    below = np.flatnonzero(correlation < 0)
    if below.size == 0:
        return None
    first = int(below[0])
    window = correlation[first:n // 2 + 1]
    if window.size < 3:
        return None
    peaks, _ = find_peaks(window)
    if peaks.size == 0:
        return None
    lag = first + int(peaks[np.argmax(window[peaks])])
    if correlation[lag] < 0.2:
        return None
    return lag * float(np.median(np.diff(times)))


def detect_cycles(times: np.ndarray, signal: np.ndarray) -> np.ndarray:
    """Cycle boundaries: times of the successive maxima of a periodic reference angle.

    Parameters
    ----------
    times : ndarray, shape (frames,), seconds
    signal : ndarray, shape (frames,), degrees, without NaN

    Returns
    -------
    ndarray, shape (cycles, 2)
        ``[start, end]`` seconds of each complete cycle (end of one = start of the next when
        they follow each other).
    """
    period = estimate_period(times, signal)
    if period is None:
        return np.empty((0, 2))
    step = float(np.median(np.diff(times)))
    spread = float(np.ptp(signal))
    peaks, _ = find_peaks(signal, distance=max(int(0.7 * period / step), 1),
                          prominence=0.25 * spread)
    if peaks.size < 2:
        return np.empty((0, 2))
    # Sub-frame refinement: vertex of the parabola through the three samples at each maximum.
    inner = peaks[(peaks > 0) & (peaks < signal.size - 1)]
    event = times[peaks].astype(float)
    below, at, above = signal[inner - 1], signal[inner], signal[inner + 1]
    curvature = below - 2 * at + above
    offset = np.where(curvature < 0, 0.5 * (below - above) / np.where(curvature < 0, curvature, -1),
                      0.0)
    event[np.isin(peaks, inner)] = times[inner] + np.clip(offset, -0.5, 0.5) * step
    spans = np.diff(event)
    keep = (spans >= 0.6 * period) & (spans <= 1.5 * period)
    return np.column_stack([event[:-1][keep], event[1:][keep]])


def normalise_cycles(times: np.ndarray, values: np.ndarray, samples: int = DEFAULT_SAMPLES,
                     cycles: bool = False, reference: int | None = None,
                     source: str | Path | None = None) -> tuple[np.ndarray, float, int]:
    """Time-normalise a trial to one cycle of ``samples`` frames.

    Parameters
    ----------
    times : ndarray, shape (frames,), seconds
    values : ndarray, shape (frames, columns), degrees; NaN where undefined
    samples : int
        Frames of the normalised cycle (at least 2).
    cycles : bool
        Detect cycles on ``values[:, reference]`` and average them; otherwise the whole trial
        is one cycle.
    reference : int, optional
        Column of the reference angle for cycle detection (default: the column with the
        largest standard deviation).
    source : path, optional
        For error messages.

    Returns
    -------
    curve : ndarray, shape (samples, columns), degrees
    duration : float
        Mean cycle duration, seconds.
    count : int
        Cycles averaged.
    """
    times = np.asarray(times, dtype=float)
    if times.size < 2:
        raise MocapError("a trial needs at least two frames to be time-normalised", source)
    if samples < 2:
        raise MocapError(f"samples per cycle must be at least 2, got {samples}", source)
    if np.any(np.diff(times) <= 0):
        raise MocapError("trial times must increase", source)
    values = interpolate_missing(times, unwrap_columns(values), source)
    if not cycles:
        curve = resample(times, values, times[0], times[-1], samples)
        return centre_branch(curve), float(times[-1] - times[0]), 1
    if reference is None:
        reference = int(np.argmax(values.std(axis=0)))
    bounds = detect_cycles(times, values[:, reference])
    if bounds.shape[0] == 0:
        raise MocapError("no complete cycle found (cycle detection needs at least two "
                         "repetitions of the movement); record more cycles or do not ask for "
                         "cycle detection", source)
    curves = np.stack([resample(times, values, start, end, samples) for start, end in bounds])
    curves = centre_branch(curves)          # per cycle, so cycles on other branches agree
    return curves.mean(axis=0), float(np.mean(bounds[:, 1] - bounds[:, 0])), int(len(bounds))

