"""Low-pass filtering and smoothing of sampled trajectories: the one home of both, numpy only.

``scipy.signal`` takes about 0.3-0.5 s of CPU to import (it parses docstrings for its
array-API wrappers), which is most of a short command's run: ``mocap check`` of a real
trial must import no scipy at all (tests/cli/test_check_startup.py).  So the filters are
written here in numpy and tested against scipy's:

* :func:`savgol` — Savitzky–Golay smoothing and derivatives, the same numbers as
  ``scipy.signal.savgol_filter(..., mode="interp")``;
* :func:`butterworth_lowpass` — the zero-lag Butterworth low-pass of gait analysis
  (``filtfilt`` of a ``butter``) of any array along its first axis, applied in the
  frequency domain: the gain is ``filtfilt``'s exactly, ``1 / (1 + (tan(πf/fs) /
  tan(πfc/fs))^(2·order))``, i.e. ``|H(f)|²`` of the digital Butterworth; the ends are
  padded by odd reflection, as ``filtfilt`` does, so only the first and last few
  samples differ from it;
* :func:`lowpass` — that filter on a :class:`~mocap.trial.Trial`, per run of valid
  samples of each marker, so a gap never smears into its neighbours;
* :func:`butterworth_sos` — the same Butterworth as scipy second-order sections, for
  frequency-response checks (imports scipy.signal when called).
"""
from __future__ import annotations

from math import factorial

import numpy as np

from mocap.errors import MocapError
from mocap.trial import Trial, runs


def _design(window: int, order: int) -> tuple[np.ndarray, np.ndarray]:
    half = window // 2
    t = np.arange(window, dtype=float) - half
    design = t[:, None] ** np.arange(order + 1)[None, :]           # (w, p+1)
    return design, np.linalg.pinv(design)                           # (p+1, w)


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
    """
    x = np.asarray(values, dtype=float)
    if window % 2 != 1 or window > x.shape[0] or order >= window:
        raise ValueError(f"bad Savitzky–Golay window {window} / order {order} for "
                         f"{x.shape[0]} samples")
    design, inverse = _design(window, order)
    half = window // 2
    # Row k of `basis` gives the deriv-th derivative of the fitted polynomial at sample k.
    powers = np.arange(order + 1)
    t = np.arange(window, dtype=float) - half
    falling = np.array([factorial(p) / factorial(p - deriv) if p >= deriv else 0.0
                        for p in powers])
    exponents = np.clip(powers - deriv, 0, None)
    basis = falling[None, :] * t[:, None] ** exponents[None, :]      # (w, p+1)
    weights = (basis @ inverse) / delta ** deriv                     # (w, w)
    flat = x.reshape(x.shape[0], -1)
    out = np.empty_like(flat)
    windows = np.lib.stride_tricks.sliding_window_view(flat, window, axis=0)  # (n-w+1, c, w)
    out[half:flat.shape[0] - half] = windows @ weights[half]
    out[:half] = weights[:half] @ flat[:window]
    out[flat.shape[0] - half:] = weights[half + 1:] @ flat[-window:]
    return out.reshape(x.shape)


def butterworth_lowpass(values: np.ndarray, cutoff: float, rate: float,
                        order: int = 2, ends: str = "reflect", axis: int = 0) -> np.ndarray:
    """Zero-lag Butterworth low-pass along ``axis`` (``filtfilt`` of ``butter(order)``).

    The one Butterworth of the toolkit: the markers' :func:`lowpass`, the dynamics
    check's motion and plate forces, and the planted root path all call it.

    ``ends="reflect"`` pads each end by odd reflection about the end sample, as
    ``filtfilt`` does: it keeps the end's value and slope but reverses its curvature, so
    a trial that ends (or starts) accelerating gets the opposite acceleration in its
    padding, and the filtered signal's second derivative swings towards zero (−g turned
    towards +g at the ends of a short free fall). ``ends="curvature"`` adds back twice the
    end's curvature: it filters what is left after the quintic with each end's value,
    slope and curvature (least-squares cubics over one period of the cut-off) and adds
    that quintic back, so nothing is reflected but what has no slope or curvature at the
    ends; a free fall or a constant velocity passes through unchanged, ends included.
    ``ends="fitted"`` does the same with least-squares quadratics and reflects what is left
    about the quintic rather than about the end sample, so that the ends are smoothed like
    the middle: white noise through this filter (6 Hz) and a 0.1 s Savitzky-Golay second
    derivative at 100 Hz spreads 1.37 m/s² per mm in the end frame with
    ``"curvature"``, 0.40 with ``"fitted"`` and 0.69 with ``"reflect"`` (0.17 in the
    middle); the price is a coarser end curvature where the motion's own changes within
    one period (a quadratic's is constant over it, a cubic's linear). The dynamics check
    uses it (noisy captures: tests/mocap/synthetic/test_generator.py).

    Parameters
    ----------
    values : ndarray, samples along ``axis``
    cutoff : float, Hz
        Below ``rate / 2``.
    rate : float, Hz
    order : int
        Order of the one-way filter (2: the customary 4th-order-equivalent zero-lag
        filter of gait analysis).
    ends : {"reflect", "curvature", "fitted"}
        How the ends are padded (above).
    axis : int
        The axis of the samples (frames).

    Examples
    --------
    >>> t = np.arange(30) / 100.0
    >>> fall = -0.5 * 9.81 * t ** 2                       # 0.3 s of free fall
    >>> smooth = butterworth_lowpass(fall, 6.0, 100.0, ends="curvature")
    >>> bool(np.abs(smooth - fall).max() < 1e-9)
    True
    """
    if ends not in ("reflect", "curvature", "fitted"):
        raise ValueError(f"ends must be 'reflect', 'curvature' or 'fitted', not {ends!r}")
    x = np.moveaxis(np.asarray(values, dtype=float), axis, 0)
    if not 0 < cutoff < rate / 2:
        raise MocapError(f"cutoff {cutoff} Hz must be between 0 and {rate / 2} Hz")
    if not cutoff / (rate / 2) > 0:
        # a denormal cut-off (5e-324 Hz): its normalised frequency underflows to 0
        raise MocapError(f"cutoff {cutoff} Hz is too small for a rate of {rate:g} Hz")
    n = x.shape[0]
    if n < 4:
        return np.moveaxis(x.copy(), 0, axis)
    periods = rate / cutoff                 # samples per period of the cut-off (may be inf)
    pad = n - 1 if not periods < n else min(n - 1, max(3 * int(np.ceil(periods)),
                                                       3 * (order + 1)))
    trend = _end_trend(x, periods, 2 if ends == "fitted" else 3) if ends != "reflect" \
        else 0.0
    x = x - trend
    # "fitted": reflected about the trend, which holds each end's fitted value (about the
    # end sample, that sample's noise would pass unfiltered into the ends).
    first, last = (np.zeros_like(x[:1]), np.zeros_like(x[-1:])) if ends == "fitted" \
        else (x[:1], x[-1:])
    padded = np.concatenate([2 * first - x[pad:0:-1], x, 2 * last - x[-2:-pad - 2:-1]])
    size = padded.shape[0]
    frequencies = np.fft.rfftfreq(size, 1.0 / rate)
    ratio = np.tan(np.pi * np.minimum(frequencies, rate / 2 * 0.999999) / rate) / \
        np.tan(np.pi * cutoff / rate)
    with np.errstate(over="ignore"):        # far above a tiny cutoff: inf, gain 0
        gain = 1.0 / (1.0 + ratio ** (2 * order))        # |H|², forward and back
    spectrum = np.fft.rfft(padded, axis=0)
    shape = (-1,) + (1,) * (x.ndim - 1)
    smoothed = np.fft.irfft(spectrum * gain.reshape(shape), n=size, axis=0)
    return np.moveaxis(smoothed[pad:pad + n] + trend, 0, axis)


def _end_trend(x: np.ndarray, periods: float, degree: int = 3) -> np.ndarray:
    """The quintic through the trial (samples, ...) with the value, slope and curvature
    of its ends (:func:`butterworth_lowpass`, ``ends="curvature"`` or ``"fitted"``).

    Each end's three are those of the least-squares polynomial of ``degree`` (3 or 2)
    through one period of the cut-off at that end (at least ``degree + 1`` samples, at
    most the trial): a trial of that degree is its own trend. What is left has neither
    slope nor curvature at the ends to reflect.
    """
    n = x.shape[0]
    span = int(min(n, max(degree + 1, np.ceil(min(periods, n)))))
    flat = x.reshape(n, -1)
    t = np.arange(span, dtype=float)
    fit = np.linalg.pinv(t[:, None] ** np.arange(min(degree + 1, span))[None, :])
    fit = np.vstack([fit, np.zeros((4 - fit.shape[0], span))])          # (4, span)
    c_start = fit @ flat[:span]                                 # about sample 0
    c_end = fit @ flat[::-1][:span]                             # about sample n-1, reversed
    length = float(n - 1)
    # value, slope and curvature (per unit of u = sample / (n - 1)) at u = 0 and u = 1
    ends = np.stack([c_start[0], c_start[1] * length, 2 * c_start[2] * length ** 2,
                     c_end[0], -c_end[1] * length, 2 * c_end[2] * length ** 2])
    u0, u1 = np.zeros(6), np.ones(6)
    powers = np.arange(6)
    rows = [u0 ** powers, powers * np.r_[0.0, u0[1:] ** (powers[1:] - 1)],
            powers * (powers - 1) * np.r_[0.0, 0.0, u0[2:] ** (powers[2:] - 2)],
            u1 ** powers, powers * u1 ** np.clip(powers - 1, 0, None),
            powers * (powers - 1) * u1 ** np.clip(powers - 2, 0, None)]
    coefficients = np.linalg.solve(np.array(rows), ends)       # (6, columns)
    u = np.arange(n, dtype=float) / length
    return ((u[:, None] ** powers) @ coefficients).reshape(x.shape)


def butterworth_sos(cutoff_hz: float, rate: float, order: int = 4,
                    path: str | None = None) -> np.ndarray:
    """Second-order sections of a Butterworth low-pass, validated.

    Raises
    ------
    MocapError
        ``cutoff_hz`` not in (0, rate / 2), or ``order`` not a positive integer.
    """
    _validate(cutoff_hz, rate, order, path)
    # deferred: scipy.signal costs ~0.5 s of start-up, and only this design needs it
    from scipy.signal import butter
    return butter(int(order), cutoff_hz, btype="lowpass", fs=rate, output="sos")


def _validate(cutoff_hz: float, rate: float, order: int, path: str | None) -> None:
    """MocapError unless 0 < ``cutoff_hz`` < rate / 2 and ``order`` is a positive integer."""
    nyquist = rate / 2.0
    if not np.isfinite(cutoff_hz) or cutoff_hz <= 0:
        raise MocapError(f"low-pass cutoff must be a positive frequency in Hz, not "
                         f"{cutoff_hz}", path)
    if cutoff_hz >= nyquist:
        raise MocapError(f"low-pass cutoff {cutoff_hz:g} Hz is not below the Nyquist "
                         f"frequency {nyquist:g} Hz (half the {rate:g} Hz sampling rate)", path)
    if int(order) != order or order < 1:
        raise MocapError(f"filter order must be a positive whole number, not {order}", path)


def lowpass(trial: Trial, cutoff_hz: float, order: int = 4, short_runs: str = "error"
            ) -> Trial:
    """Zero-lag Butterworth low-pass of every marker, per run of valid samples.

    A Butterworth filter of ``order`` run forward and backward
    (:func:`butterworth_lowpass`, as ``scipy.signal.sosfiltfilt``), so there is
    no phase lag and the magnitude response is ``|H(f)|²``: 1 in the pass band, 1/2 (-6 dB) at ``cutoff_hz``,
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
    _validate(cutoff_hz, trial.rate, order, trial.path)
    sections = (int(order) + 1) // 2                # of the filter as second-order sections
    padlen = 3 * (2 * sections + 1)
    points = trial.points.copy()
    valid = np.isfinite(points).all(axis=2)
    points[~valid] = np.nan
    complete = valid.all(axis=0)
    if complete.any() and trial.frames > padlen:
        # markers without gaps: one call over all of them
        points[:, complete, :] = butterworth_lowpass(points[:, complete, :], cutoff_hz,
                                                      trial.rate, int(order))
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
            points[s:s + n, m, :] = butterworth_lowpass(points[s:s + n, m, :], cutoff_hz,
                                                       trial.rate, int(order))
    return trial.with_points(points)
