"""Time normalisation of joint-angle curves: unwrap, bridge gaps, resample, detect cycles.

One trial's angle curves (frames, columns) become one gait cycle of ``samples`` frames
(:func:`mean_cycle`):

* **Unwrapping** (:func:`mocap.rotations.angles.unwrap_columns`). Every angle is unwrapped (no ±180° jumps) before
  interpolation, over the samples where it is defined (NaN where markers were missing); gaps
  are bridged by linear interpolation of the unwrapped angle (:func:`interpolate_missing`).
* **One cycle per trial** (default): the whole trial is the cycle; it is resampled linearly to
  ``samples`` instants spanning its first to its last frame (:func:`mocap.clean.resample.resample`), and the cycle's
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
* **Phase check** (:func:`warn_misaligned_cycles`). A trial whose cut cycle best matches
  the other trials of its action more than a quarter of a cycle away (cut at another event
  of the movement) is named in a :class:`CycleWarning`; it is never shifted silently.
* **Branch** (:func:`centre_branch`). Each angle curve is shifted by a whole number of turns
  so that its mean lies in (−180°, 180°], so cycles and trials unwrapped from different
  starting branches agree.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from mocap.clean.resample import resample
from mocap.rotations.angles import unwrap_columns
from mocap.errors import MocapError, MocapWarning
from synthesis.rotations import yaw_matrices

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
    from scipy.signal import find_peaks     # deferred: ~1 s to import, for cycle detection only

    peaks, _ = find_peaks(window)
    if peaks.size == 0:
        return None
    lag = first + int(peaks[np.argmax(window[peaks])])
    if correlation[lag] < 0.2:
        return None
    return lag * float(np.median(np.diff(times)))


def detect_cycles(times: np.ndarray, signal: np.ndarray, with_events: bool = False
                  ) -> np.ndarray:
    """Cycle boundaries: times of the successive maxima of a periodic reference signal.

    Parameters
    ----------
    times : ndarray, shape (frames,), seconds
    signal : ndarray, shape (frames,), degrees (or any unit), without NaN
    with_events : bool
        Return the times of all maxima instead of the cycles they bound.

    Returns
    -------
    ndarray, shape (cycles, 2)
        ``[start, end]`` seconds of each complete cycle (end of one = start of the next when
        they follow each other); with ``with_events``, shape (maxima,) seconds.
    """
    period = estimate_period(times, signal)
    if period is None:
        return np.empty((0,)) if with_events else np.empty((0, 2))
    step = float(np.median(np.diff(times)))
    spread = float(np.ptp(signal))
    from scipy.signal import find_peaks     # deferred, as above

    peaks, _ = find_peaks(signal, distance=max(int(0.7 * period / step), 1),
                          prominence=0.25 * spread)
    # Sub-frame refinement: vertex of the parabola through the three samples at each maximum.
    inner = peaks[(peaks > 0) & (peaks < signal.size - 1)]
    event = times[peaks].astype(float)
    below, at, above = signal[inner - 1], signal[inner], signal[inner + 1]
    curvature = below - 2 * at + above
    offset = np.where(curvature < 0, 0.5 * (below - above) / np.where(curvature < 0, curvature, -1),
                      0.0)
    event[np.isin(peaks, inner)] = times[inner] + np.clip(offset, -0.5, 0.5) * step
    if with_events:
        return event
    if peaks.size < 2:
        return np.empty((0, 2))
    spans = np.diff(event)
    keep = (spans >= 0.6 * period) & (spans <= 1.5 * period)
    return np.column_stack([event[:-1][keep], event[1:][keep]])


def mean_cycle(times: np.ndarray, values: np.ndarray, samples: int = DEFAULT_SAMPLES,
               cycles: bool = False, reference: int | None = None,
               source: str | Path | None = None) -> tuple[np.ndarray, float, int]:
    """One time-normalised cycle of ``samples`` frames: the whole trial, or the mean of
    its detected cycles.

    Gait cycles between the file's foot strikes, one per cycle, are
    :func:`mocap.plugingait.events.normalise_cycles`; both resample with
    :func:`mocap.clean.resample.resample`.

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




#: A cut cycle whose best match with the other trials of its action lies further than this
#: fraction of a cycle away is reported: a cut at the other foot's event is half a cycle
#: off, and a quarter is halfway between that and a right cut (bandai2's walks, turns and
#: runs lie within 0.04 of their action's other trials).
MISALIGNED_FRACTION = 0.25


def cycle_phase_lags(curves: np.ndarray) -> np.ndarray:
    """Circular lag at which each trial's cycle best matches the mean of the others' cycles.

    Every column is centred on its mean over the cycle and scaled by its spread over all
    the trials (so no unit or joint dominates); the lag maximises the circular
    cross-correlation, summed over the columns, of the trial with the mean of the other
    trials (one FFT for all).

    Parameters
    ----------
    curves : ndarray, shape (trials, samples, columns)
        Time-normalised cycles of one action, at least two trials.

    Returns
    -------
    ndarray, shape (trials,)
        Lag of each trial as a fraction of a cycle in (−½, ½]: a trial equal to the others
        rolled forward by ``k`` samples has ``k / samples``.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0, 1, 40, endpoint=False)[:, None]
    >>> base = np.hstack([np.sin(2 * np.pi * t), np.cos(4 * np.pi * t)])
    >>> curves = np.stack([base, base, base, np.roll(base, 20, axis=0)])
    >>> cycle_phase_lags(curves).round(3).tolist()
    [0.0, 0.0, 0.0, 0.5]
    """
    curves = np.asarray(curves, dtype=float)
    trials, samples = curves.shape[:2]
    if trials < 2:
        raise MocapError("a phase lag needs at least two trials of an action")
    centred = curves - curves.mean(axis=1, keepdims=True)
    spread = centred.std(axis=(0, 1))
    centred = centred / np.where(spread > 0, spread, 1.0)
    spectra = np.fft.rfft(centred, axis=1)                            # (trials, bins, columns)
    others = (spectra.sum(axis=0) - spectra) / (trials - 1)
    correlation = np.fft.irfft(spectra * np.conj(others), n=samples, axis=1).sum(axis=2)
    lag = np.argmax(correlation, axis=1)
    lag = np.where(lag > samples // 2, lag - samples, lag)
    return lag / samples


def warn_misaligned_cycles(curves: np.ndarray, sources: list, action: str) -> np.ndarray:
    """Warn (:class:`CycleWarning`), naming the file, for every trial of an action whose cut
    cycle best matches the others more than :data:`MISALIGNED_FRACTION` of a cycle away.

    Parameters
    ----------
    curves : ndarray, shape (trials, samples, columns)
        The trials' cut cycles (only trials cut into cycles; fewer than three: no check).
    sources : list of str or Path, length trials
    action : str

    Returns
    -------
    ndarray, shape (trials,)
        The lags (:func:`cycle_phase_lags`), NaN when not checked.
    """
    curves = np.asarray(curves, dtype=float)
    if curves.shape[0] < 3:
        return np.full(curves.shape[0], np.nan)
    lags = cycle_phase_lags(curves)
    for source, lag in zip(sources, lags):
        if abs(lag) > MISALIGNED_FRACTION:
            warnings.warn(f"{source}: its cycle matches the other trials of {action!r} best "
                          f"when shifted by {100 * abs(lag):.0f} % of a cycle — cut at another "
                          "event of the movement? Check the trial (a misaligned cycle blurs the "
                          "action's mean and the person's cell)", CycleWarning, stacklevel=3)
    return lags


# --------------------------------------------------------------------------- skeleton cycles

class CycleWarning(MocapWarning):
    """A trial of a cyclic action held no complete cycle and is used whole."""


#: A trial is cyclic when its leg signal spans at least this fraction of the leg length.
LEG_SWING_FRACTION = 0.25


def foot_joints(positions: np.ndarray, parents: list[int]) -> tuple[int, int]:
    """The two lowest leaf joints on different branches (the feet), from a standing frame.

    Parameters
    ----------
    positions : ndarray, shape (segments, 3), metres, Y up
    parents : list of int

    Returns
    -------
    (first, second) : joint indices, ordered by index (the same for every trial of a rig)
    """
    leaves = [i for i in range(len(parents)) if i not in parents]
    if len(leaves) < 2:
        raise MocapError("cycle detection needs a skeleton with two legs")
    order = sorted(leaves, key=lambda i: positions[i, 1])
    first = order[0]
    chain = _ancestors(parents, first)
    for other in order[1:]:
        if other not in chain and first not in _ancestors(parents, other):
            return tuple(sorted((first, other)))
    raise MocapError("cycle detection needs a skeleton with two legs")


def _ancestors(parents: list[int], index: int) -> set[int]:
    found = set()
    while index >= 0:
        found.add(index)
        index = parents[index]
    return found


def leg_separation(positions: np.ndarray, heading: np.ndarray, feet: tuple[int, int]
                   ) -> np.ndarray:
    """Horizontal vector from the first foot to the second in the heading frame.

    Parameters
    ----------
    positions : ndarray, shape (frames, segments, 3), metres
    heading : ndarray, shape (frames,), radians
    feet : (int, int)

    Returns
    -------
    ndarray, shape (frames, 2): the two horizontal components (X, Z)
    """
    between = positions[:, feet[1]] - positions[:, feet[0]]
    local = np.einsum("fji,fj->fi", yaw_matrices(heading), between)
    return local[:, [0, 2]]


def walking_axis(separations: list[np.ndarray]) -> np.ndarray:
    """The horizontal axis along which the feet swing most over a corpus (unit 2-vector).

    The feet pass each other along the walking direction; sideways they keep their stance
    width. The sign is fixed so the axis' larger component is positive (any fixed choice:
    the same for every trial of the corpus).
    """
    stacked = np.concatenate([s - s.mean(axis=0) for s in separations])
    _, vectors = np.linalg.eigh(stacked.T @ stacked)
    axis = vectors[:, -1]
    return axis * (1.0 if axis[np.argmax(np.abs(axis))] > 0 else -1.0)


def leg_cycles(times: np.ndarray, signal: np.ndarray, leg_length: float) -> np.ndarray:
    """Cycles of a leg signal (one foot ahead of the other), with their mid-cycle event.

    A cycle runs from a maximum of the signal (the second foot furthest ahead) to the next;
    its middle event is the minimum between them (the first foot furthest ahead). Maxima and
    minima come from :func:`detect_cycles`' rules (autocorrelation period, prominence,
    sub-frame parabola).

    Parameters
    ----------
    times : ndarray, shape (frames,), seconds
    signal : ndarray, shape (frames,), metres
    leg_length : float, metres
        The signal must span at least :data:`LEG_SWING_FRACTION` of it (the feet really swing).

    Returns
    -------
    ndarray, shape (cycles, 3)
        ``[start, middle, end]`` seconds of every complete cycle; empty when none.
    """
    if np.ptp(signal) < LEG_SWING_FRACTION * leg_length:
        return np.empty((0, 3))
    bounds = detect_cycles(times, signal)
    if bounds.shape[0] == 0:
        return np.empty((0, 3))
    lows = detect_cycles(times, -signal, with_events=True)
    cycles = []
    for start, end in bounds:
        inside = lows[(lows > start) & (lows < end)]
        if inside.size == 1:
            cycles.append((start, float(inside[0]), end))
    return np.array(cycles, dtype=float).reshape(-1, 3)


def register_cycle(times: np.ndarray, values: np.ndarray, events: np.ndarray,
                   phases: np.ndarray, samples: int) -> np.ndarray:
    """Resample ``values`` between events so that event ``k`` falls at phase ``phases[k]``.

    Piecewise-linear landmark registration: the time warp is linear between consecutive
    events.

    Parameters
    ----------
    times : ndarray, shape (frames,), seconds
    values : ndarray, shape (frames, columns)
    events : ndarray, shape (k,), seconds, increasing
    phases : ndarray, shape (k,), in [0, 1], increasing, first 0 and last 1
    samples : int

    Returns
    -------
    ndarray, shape (samples, columns)
    """
    instants = np.interp(np.linspace(0.0, 1.0, samples), phases, events)
    right = np.clip(np.searchsorted(times, instants, side="right"), 1, len(times) - 1)
    left = right - 1
    span = times[right] - times[left]
    weight = np.clip((instants - times[left]) / np.where(span > 0, span, 1.0), 0.0, 1.0)
    return values[left] * (1.0 - weight)[:, None] + values[right] * weight[:, None]
