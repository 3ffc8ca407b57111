"""The one home of the low-pass and smoothing filters (mocap.clean.filtering), on known answers."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.errors import MocapError
from mocap.clean.filtering import butterworth_lowpass, savgol

RATE, CUTOFF = 100.0, 6.0


def digital_gain(frequency: float, order: int = 2) -> float:
    """|H(f)|² of a digital Butterworth low-pass (bilinear transform), by hand."""
    ratio = np.tan(np.pi * frequency / RATE) / np.tan(np.pi * CUTOFF / RATE)
    return 1.0 / (1.0 + ratio ** (2 * order))


@pytest.mark.parametrize("frequency", [1.0, CUTOFF, 20.0])
def test_zero_lag_butterworth_has_the_squared_butterworth_gain_and_no_lag(frequency):
    t = np.arange(1000) / RATE
    sine = np.sin(2 * np.pi * frequency * t)
    out = butterworth_lowpass(np.stack([sine, 2 * sine], axis=1), CUTOFF, RATE)
    middle = slice(200, 800)
    gain = digital_gain(frequency)                 # 0.9994, 0.5, 0.0047
    # no lag: the output is the input scaled, sample for sample
    np.testing.assert_allclose(out[middle, 0], gain * sine[middle], atol=2e-3 * max(gain, 0.1))
    np.testing.assert_allclose(out[:, 1], 2 * out[:, 0], rtol=1e-12, atol=1e-12)


def test_zero_lag_butterworth_keeps_a_ramp_to_its_ends_and_short_series():
    t = np.arange(300) / RATE
    ramp = 0.3 + 2.0 * t                           # odd reflection continues it
    np.testing.assert_allclose(butterworth_lowpass(ramp, CUTOFF, RATE), ramp, atol=1e-5)
    np.testing.assert_array_equal(butterworth_lowpass(np.ones(3), CUTOFF, RATE), np.ones(3))
    with pytest.raises(MocapError, match="between 0 and 50"):
        butterworth_lowpass(ramp, 60.0, RATE)


def test_savitzky_golay_is_exact_on_a_cubic_and_its_derivatives():
    t = np.arange(50) / RATE
    cubic = t ** 3 - t
    for deriv, answer in ((0, cubic), (1, 3 * t ** 2 - 1), (2, 6 * t)):
        np.testing.assert_allclose(savgol(cubic, 11, 3, deriv, 1 / RATE), answer,
                                   atol=1e-9, err_msg=f"derivative {deriv}")
    with pytest.raises(ValueError, match="window 10"):
        savgol(cubic, 10, 3)
