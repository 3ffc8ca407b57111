"""Gait-event peak finding in numpy (mocap.plugingait.events.find_peaks) gives exactly
scipy.signal.find_peaks's peaks: on hard synthetic signals (flat runs, ties, edges) and
on every heel and toe signal of the biomechzoo walks and pyCGM's Movement_trial."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import find_peaks as scipy_find_peaks

from mocap.io import read
from mocap.plugingait.events import (FOOT_STRIKE, detect_events, find_peaks,
                                     progression_signals)
from tests.conftest import realdata_path


def scipy_peaks(x, distance, prominence):
    return scipy_find_peaks(x, distance=distance, prominence=prominence)[0]


def test_known_peaks():
    """Hand-worked: a flat top gives its middle (rounded down), an edge is no peak, the
    lower of two close peaks goes, a shallow bump fails the prominence."""
    x = np.array([5, 0, 2, 2, 2, 2, 0, 1, 0.8, 1, 0, 3, 0, 6.0])
    assert find_peaks(x, 1, 0.0).tolist() == [3, 7, 9, 11]
    assert find_peaks(x, 3, 0.0).tolist() == [3, 7, 11]
    assert find_peaks(x, 1, 1.5).tolist() == [3, 11]


@pytest.mark.parametrize("seed", range(6))
def test_same_peaks_as_scipy_on_hard_signals(seed):
    """Rounded random walks (many flat runs and equal heights) and noisy sines, over a
    range of distances and prominences: identical indices."""
    rng = np.random.default_rng(seed)
    signals = [np.round(np.cumsum(rng.normal(size=400)), 0),
               np.round(rng.normal(size=300), 1),
               np.sin(np.linspace(0, 20, 500)) + 0.05 * rng.normal(size=500),
               rng.integers(0, 3, size=200).astype(float)]
    for x in signals:
        spread = float(np.ptp(x))
        for distance in (1, 2, 7, 30, 150):
            for share in (0.0, 0.05, 0.2, 0.5):
                np.testing.assert_array_equal(find_peaks(x, distance, share * spread),
                                              scipy_peaks(x, distance, share * spread))


def walks():
    study = realdata_path("biomechzoo_sample_study")
    files = [f for f in sorted(study.glob("*/*/*.c3d")) if "Static" not in f.parts]
    return files + [realdata_path("pycgm", "Test_Files", "Movement_trial.c3d")]


def test_same_events_as_scipy_on_every_walk():
    """Every heel and toe signal detect_events reads, on all 16 biomechzoo walks and
    Movement_trial: the same peaks as scipy, so the same detected events."""
    files = walks()
    assert len(files) == 17
    signals = 0
    for path in files:
        trial = read(path)
        strikes = 0
        for side, kind, filled, finite, distance, prominence in progression_signals(trial):
            ours = find_peaks(filled, distance, prominence)
            np.testing.assert_array_equal(ours, scipy_peaks(filled, distance, prominence),
                                          err_msg=f"{path.name} {side} {kind}")
            signals += 1
            strikes += kind == FOOT_STRIKE and len(ours)
        assert strikes > 0, path.name                    # a walk: some strikes found
        assert all(e.source == "detected" for e in detect_events(trial))
    assert signals == 4 * len(files)
