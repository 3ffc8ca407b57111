"""Smoothing and differentiation of sampled trajectories with numpy only.

``scipy.signal`` takes about a second to import (it parses docstrings for its array-API
wrappers), which is most of a short command's run; these two filters are all the dynamics
check needs:

* :func:`savgol` — Savitzky–Golay smoothing and derivatives, the same numbers as
  ``scipy.signal.savgol_filter(..., mode="interp")`` (tested against it);
* :func:`butterworth_lowpass` — the zero-lag Butterworth low-pass of gait analysis
  (``filtfilt`` of a 2nd-order ``butter``), applied in the frequency domain: the gain is
  ``filtfilt``'s exactly, ``1 / (1 + (tan(πf/fs) / tan(πfc/fs))^(2·order))``, i.e.
  ``|H(f)|²`` of the digital Butterworth; the ends are padded by odd reflection, as
  ``filtfilt`` does, so only the first and last few samples differ from it.
"""
from __future__ import annotations

from math import factorial

import numpy as np

from mocap.errors import MocapError


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
                        order: int = 2) -> np.ndarray:
    """Zero-lag Butterworth low-pass along axis 0 (``filtfilt`` of ``butter(order)``).

    Parameters
    ----------
    values : ndarray, shape (samples, ...)
    cutoff : float, Hz
        Below ``rate / 2``.
    rate : float, Hz
    order : int
        Order of the one-way filter (2: the customary 4th-order-equivalent zero-lag
        filter of gait analysis).
    """
    x = np.asarray(values, dtype=float)
    if not 0 < cutoff < rate / 2:
        raise MocapError(f"cutoff {cutoff} Hz must be between 0 and {rate / 2} Hz")
    n = x.shape[0]
    if n < 4:
        return x.copy()
    pad = min(n - 1, max(3 * int(np.ceil(rate / cutoff)), 3 * (order + 1)))
    first, last = x[:1], x[-1:]
    padded = np.concatenate([2 * first - x[pad:0:-1], x, 2 * last - x[-2:-pad - 2:-1]])
    size = padded.shape[0]
    frequencies = np.fft.rfftfreq(size, 1.0 / rate)
    ratio = np.tan(np.pi * np.minimum(frequencies, rate / 2 * 0.999999) / rate) / \
        np.tan(np.pi * cutoff / rate)
    gain = 1.0 / (1.0 + ratio ** (2 * order))            # |H|², forward and back
    spectrum = np.fft.rfft(padded, axis=0)
    shape = (-1,) + (1,) * (x.ndim - 1)
    smoothed = np.fft.irfft(spectrum * gain.reshape(shape), n=size, axis=0)
    return smoothed[pad:pad + n]
