"""Low-pass filtering and smoothing of sampled trajectories: the one home of both.

Everything runs through ``scipy.signal`` (imported when a filter is first used, not
with this module: it costs about 0.3 s of CPU at start-up):

* :func:`butterworth_sos` — a validated Butterworth low-pass design (second-order
  sections);
* :func:`butterworth_lowpass` — zero-lag (``sosfiltfilt``) low-pass of any array along
  its first axis: the dynamics check's motion, contact forces and force plates;
* :func:`lowpass` — the same filter on a :class:`~mocap.trial.Trial`, per run of valid
  samples of each marker, so a gap never smears into its neighbours;
* :func:`savgol` — Savitzky–Golay smoothing and derivatives (``savgol_filter``,
  ``mode="interp"``).
"""
from __future__ import annotations

import numpy as np

from mocap.errors import MocapError
from mocap.trial import Trial, runs


def savgol(values: np.ndarray, window: int, order: int, deriv: int = 0,
           delta: float = 1.0) -> np.ndarray:
    """Savitzky–Golay filter along axis 0, edges fitted as ``mode="interp"``.

    Parameters
    ----------
    values : ndarray, shape (samples, ...)
    window : int
        Odd window length, at most ``samples``.
    order : int
        Polynomial order, below ``window``.
    deriv : int
        Derivative to return (0: smoothed values).
    delta : float
        Sample spacing (seconds), for derivatives.

    Returns
    -------
    ndarray, shape of ``values``
        Smoothed values or their ``deriv``-th derivative (units per ``delta**deriv``).
    """
    x = np.asarray(values, dtype=float)
    if window % 2 != 1 or window > x.shape[0] or order >= window:
        raise ValueError(f"bad Savitzky–Golay window {window} / order {order} for "
                         f"{x.shape[0]} samples")
    # deferred: scipy.signal's start-up, see the module docstring
    from scipy.signal import savgol_filter
    return savgol_filter(x, window, order, deriv=deriv, delta=delta, axis=0, mode="interp")


def butterworth_lowpass(values: np.ndarray, cutoff: float, rate: float,
                        order: int = 2) -> np.ndarray:
    """Zero-lag Butterworth low-pass along axis 0 (``sosfiltfilt`` of ``butter(order)``).

    The gain is ``|H(f)|²`` of the one-way filter; the ends are padded by odd
    reflection over three periods of the cutoff (at most the whole series), so the
    filter settles before the first sample.

    Parameters
    ----------
    values : ndarray, shape (samples, ...)
    cutoff : float, Hz
        Below ``rate / 2``.
    rate : float, Hz
    order : int
        Order of the one-way filter (2: the customary 4th-order-equivalent zero-lag
        filter of gait analysis).

    Returns
    -------
    ndarray, shape of ``values``
        Filtered; fewer than 4 samples are returned unfiltered (a copy).
    """
    x = np.asarray(values, dtype=float)
    if not 0 < cutoff < rate / 2:
        raise MocapError(f"cutoff {cutoff} Hz must be between 0 and {rate / 2} Hz")
    n = x.shape[0]
    if n < 4:
        return x.copy()
    from scipy.signal import sosfiltfilt   # deferred: see the module docstring
    pad = min(n - 1, max(3 * int(np.ceil(rate / cutoff)), 3 * (order + 1)))
    return sosfiltfilt(butterworth_sos(cutoff, rate, order), x, axis=0, padtype="odd",
                       padlen=pad)


def butterworth_sos(cutoff_hz: float, rate: float, order: int = 4,
                    path: str | None = None) -> np.ndarray:
    """Second-order sections of a Butterworth low-pass, validated.

    Raises
    ------
    MocapError
        ``cutoff_hz`` not in (0, rate / 2), or ``order`` not a positive integer.
    """
    nyquist = rate / 2.0
    if not np.isfinite(cutoff_hz) or cutoff_hz <= 0:
        raise MocapError(f"low-pass cutoff must be a positive frequency in Hz, not "
                         f"{cutoff_hz}", path)
    if cutoff_hz >= nyquist:
        raise MocapError(f"low-pass cutoff {cutoff_hz:g} Hz is not below the Nyquist "
                         f"frequency {nyquist:g} Hz (half the {rate:g} Hz sampling rate)", path)
    if int(order) != order or order < 1:
        raise MocapError(f"filter order must be a positive whole number, not {order}", path)
    # deferred: scipy.signal costs ~0.5 s of start-up, and only low-pass filtering needs it
    from scipy.signal import butter
    return butter(int(order), cutoff_hz, btype="lowpass", fs=rate, output="sos")


def lowpass(trial: Trial, cutoff_hz: float, order: int = 4, short_runs: str = "error"
            ) -> Trial:
    """Zero-lag Butterworth low-pass of every marker, per run of valid samples.

    A Butterworth filter of ``order`` is run forward and backward
    (``scipy.signal.sosfiltfilt``), so there is no phase lag and the magnitude
    response is ``|H(f)|²``: 1 in the pass band, 1/2 (-6 dB) at ``cutoff_hz``,
    falling by ``2 × 6 × order`` dB per octave above.

    Parameters
    ----------
    trial : Trial
    cutoff_hz : float
        Must be below the Nyquist frequency ``rate / 2``.
    order : int
        Order of the single-pass filter (default 4).
    short_runs : {"error", "keep", "drop"}
        What to do with a run of valid samples too short to filter (at most
        ``3 × (2 × sections + 1)`` frames, scipy's padding): raise MocapError
        (default), keep it unfiltered, or make it missing.

    Returns
    -------
    Trial
        A copy with filtered positions; missing samples stay NaN.

    Raises
    ------
    MocapError
        Cutoff at or above Nyquist, bad order, or a too-short run with
        ``short_runs="error"`` (the message names the marker and frames).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(1000) / 100.0
    >>> x = np.sin(2 * np.pi * t) + 0.1 * np.sin(2 * np.pi * 30 * t)   # 1 Hz + 30 Hz
    >>> trial = Trial(["M"], np.stack([x, 0 * x, 0 * x], axis=1)[:, None, :], 100.0)
    >>> smooth = lowpass(trial, cutoff_hz=6.0).points[:, 0, 0]
    >>> bool(np.abs(smooth - np.sin(2 * np.pi * t))[100:-100].max() < 0.01)
    True
    """
    if short_runs not in ("error", "keep", "drop"):
        raise ValueError(f"short_runs must be 'error', 'keep' or 'drop', not {short_runs!r}")
    # deferred: see butterworth_sos
    from scipy.signal import sosfiltfilt
    sos = butterworth_sos(cutoff_hz, trial.rate, order, trial.path)
    padlen = 3 * (2 * len(sos) + 1)
    points = trial.points.copy()
    valid = np.isfinite(points).all(axis=2)
    points[~valid] = np.nan
    complete = valid.all(axis=0)
    if complete.any() and trial.frames > padlen:
        # markers without gaps: one call over all of them
        points[:, complete, :] = sosfiltfilt(sos, points[:, complete, :], axis=0)
    # a Python loop over the other markers and their runs (not frames)
    for m in np.flatnonzero(~complete):
        starts, lengths = runs(valid[:, m])
        for s, n in zip(starts, lengths):
            s, n = int(s), int(n)
            if n <= padlen:
                if short_runs == "error":
                    raise MocapError(
                        f"marker {trial.labels[m]}: only {n} valid frame(s) in a row at "
                        f"frames {s}-{s + n - 1}, too few for a zero-lag order-{order} "
                        f"filter (needs more than {padlen}); fill the gaps first or "
                        f"keep/drop short runs", trial.path)
                if short_runs == "drop":
                    points[s:s + n, m, :] = np.nan
                continue
            points[s:s + n, m, :] = sosfiltfilt(sos, points[s:s + n, m, :], axis=0)
    return trial.with_points(points)
