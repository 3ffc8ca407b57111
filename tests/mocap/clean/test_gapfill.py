"""Gap filling (cubic spline) and the zero-lag Butterworth low-pass."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import sosfreqz

from mocap.clean import butterworth_sos, fill_gaps, lowpass
from mocap.errors import MocapError
from mocap.trial import Trial

RATE = 100.0


def smooth_trial(frames: int = 300) -> tuple[Trial, np.ndarray]:
    """Two markers on smooth known curves (metres)."""
    t = np.arange(frames) / RATE
    a = np.stack([0.3 * np.sin(2 * np.pi * 0.7 * t), 0.1 * np.cos(2 * np.pi * 0.4 * t),
                  1.0 + 0.05 * t ** 2], axis=1)
    b = np.stack([t, 0.2 * np.sin(2 * np.pi * 1.1 * t + 1), 0.9 + 0 * t], axis=1)
    truth = np.stack([a, b], axis=1)
    return Trial(["A", "B"], truth.copy(), RATE, path="walk.c3d"), truth


def test_short_gaps_recovered_long_and_edge_gaps_left_and_reported():
    trial, truth = smooth_trial()
    points = trial.points.copy()
    points[100:108, 0] = np.nan          # 8 frames: filled
    points[200:240, 0] = np.nan          # 40 frames: too long
    points[0:5, 1] = np.nan              # at the start: no extrapolation
    points[150:153, 1, 2] = np.nan       # one coordinate missing = marker missing
    filled, report = fill_gaps(trial.with_points(points), max_gap_seconds=0.1)
    assert report.max_gap_frames == 10
    # a cubic spline through the samples: within 0.1 mm on a 0.3 m, 0.7 Hz
    # curve (a straight line across the same gap is off by about 5 mm)
    np.testing.assert_allclose(filled.points[100:108, 0], truth[100:108, 0], atol=1e-4)
    np.testing.assert_allclose(filled.points[150:153, 1], truth[150:153, 1], atol=1e-4)
    line = np.linspace(truth[99, 0], truth[108, 0], 10)[1:-1]
    assert np.abs(line - truth[100:108, 0]).max() > 3e-3
    assert np.isnan(filled.points[200:240, 0]).all()
    assert np.isnan(filled.points[0:5, 1]).all()
    # samples that were there are untouched
    assert np.array_equal(filled.points[:100, 0], truth[:100, 0])
    unfilled = {(g.label, g.start, g.length): g.reason for g in report.unfilled}
    assert unfilled == {("A", 200, 40): "longer than 10 frames", ("B", 0, 5): "at the start"}
    assert sorted((g.label, g.start, g.length) for g in report.filled) == \
        [("A", 100, 8), ("B", 150, 3)]
    assert report.unfilled_frames == 45
    text = report.summary()
    assert "A: frames 200-239 (longer than 10 frames)" in text
    # the input is not modified
    assert np.isnan(points[100, 0]).all()


def test_frames_and_seconds_limits_agree_and_are_validated():
    trial, _ = smooth_trial()
    points = trial.points.copy()
    points[50:60, 0] = np.nan
    gappy = trial.with_points(points)
    by_frames = fill_gaps(gappy, max_gap_frames=10)[0]
    by_seconds = fill_gaps(gappy, max_gap_seconds=0.1)[0]
    assert np.array_equal(by_frames.points, by_seconds.points, equal_nan=True)
    assert np.isnan(fill_gaps(gappy, max_gap_frames=9)[0].points[50:60, 0]).all()
    for kwargs in ({}, {"max_gap_frames": 3, "max_gap_seconds": 0.1},
                   {"max_gap_frames": -1}, {"max_gap_seconds": float("nan")}):
        with pytest.raises(MocapError, match="walk.c3d"):
            fill_gaps(gappy, **kwargs)


def test_marker_never_seen_is_reported():
    trial, _ = smooth_trial(50)
    points = trial.points.copy()
    points[:, 1] = np.nan
    filled, report = fill_gaps(trial.with_points(points), max_gap_frames=100)
    assert np.isnan(filled.points[:, 1]).all()
    assert [(g.label, g.reason) for g in report.unfilled] == [("B", "marker never seen")]


def sine_trial(frequency: float, frames: int = 2000) -> Trial:
    t = np.arange(frames) / RATE
    x = np.sin(2 * np.pi * frequency * t)
    return Trial(["M"], np.stack([x, 0 * x, 0 * x + 1], axis=1)[:, None, :], RATE)


def test_lowpass_passes_slow_sine_without_lag_and_attenuates_fast_one():
    cutoff, order = 6.0, 4
    slow = lowpass(sine_trial(1.0), cutoff, order).points[:, 0, 0]
    t = np.arange(len(slow)) / RATE
    middle = slice(300, -300)           # away from the ends' transients
    reference = np.sin(2 * np.pi * 1.0 * t)
    amplitude = np.abs(slow[middle]).max()
    assert abs(amplitude - 1.0) < 0.01
    # zero phase: the filtered sine matches the original sample by sample,
    # and the best-matching shift is zero
    np.testing.assert_allclose(slow[middle], reference[middle], atol=0.01)
    shifts = range(-5, 6)
    errors = [np.abs(np.roll(slow, s)[middle] - reference[middle]).max() for s in shifts]
    assert shifts[int(np.argmin(errors))] == 0

    fast_frequency = 20.0
    fast = lowpass(sine_trial(fast_frequency), cutoff, order).points[:, 0, 0]
    sos = butterworth_sos(cutoff, RATE, order)
    _, response = sosfreqz(sos, worN=[fast_frequency], fs=RATE)
    expected = np.abs(response[0]) ** 2        # forward and backward: squared
    assert expected < 1e-3
    measured = np.abs(fast[middle]).max()
    assert measured == pytest.approx(expected, rel=0.05)
    # at the cutoff the double pass halves the amplitude (-6 dB)
    at_cutoff = lowpass(sine_trial(cutoff), cutoff, order).points[:, 0, 0]
    assert np.abs(at_cutoff[middle]).max() == pytest.approx(0.5, abs=0.01)


def test_lowpass_filters_each_valid_run_separately():
    trial = sine_trial(1.0, 600)
    points = trial.points.copy()
    points[280:300] = np.nan
    out = lowpass(trial.with_points(points), 6.0).points
    assert np.isnan(out[280:300]).all()
    assert np.isfinite(out[:280]).all() and np.isfinite(out[300:]).all()
    whole = lowpass(sine_trial(1.0, 280), 6.0).points
    np.testing.assert_allclose(out[:280], whole, atol=1e-12)


def test_lowpass_errors_and_short_runs():
    trial = sine_trial(1.0, 200)
    for cutoff in (50.0, 80.0):
        with pytest.raises(MocapError, match="Nyquist"):
            lowpass(trial, cutoff)
    with pytest.raises(MocapError, match="positive"):
        lowpass(trial, 0.0)
    with pytest.raises(MocapError, match="order"):
        lowpass(trial, 5.0, order=0)
    points = trial.points.copy()
    points[10] = np.nan                                  # frames 0-9: a run of 10
    short = trial.with_points(points)
    with pytest.raises(MocapError, match=r"marker M: only 10 valid frame\(s\).*frames 0-9"):
        lowpass(short, 5.0)
    kept = lowpass(short, 5.0, short_runs="keep").points
    assert np.array_equal(kept[:10], points[:10])
    dropped = lowpass(short, 5.0, short_runs="drop").points
    assert np.isnan(dropped[:10]).all() and np.isfinite(dropped[11:]).all()


def test_rigid_fill_keeps_a_fast_turning_segment_rigid():
    """A 30-frame gap in one marker of a segment spinning at 1.5 turns per second:
    its two donors keep it on the body (< 1 mm), a spline cuts the corner."""
    from mocap.rotations.frames import segment_frames
    from mocap.markersets import load_markerset

    rate, frames = 100.0, 200
    t = np.arange(frames) / rate
    angle = 2 * np.pi * 1.5 * t
    rotations = np.zeros((frames, 3, 3))
    rotations[:, 0, 0] = rotations[:, 1, 1] = np.cos(angle)
    rotations[:, 0, 1], rotations[:, 1, 0] = -np.sin(angle), np.sin(angle)
    rotations[:, 2, 2] = 1.0
    origin = np.stack([0.5 * t, 0 * t, 1 + 0 * t], axis=1)
    local = np.array([[0.0, 0, 0], [0.1, 0, 0], [0, 0.1, 0]])
    points = origin[:, None, :] + np.einsum("fij,mj->fmi", rotations, local)
    labels = ["PELO", "PELA", "PELL"]
    truth = Trial(labels, points, rate)
    gappy = points.copy()
    gappy[80:110, 1] = np.nan
    markerset = load_markerset("synthetic15")
    donors = markerset.donors(labels)
    assert donors == {"PELO": ["PELA", "PELL"], "PELA": ["PELO", "PELL"],
                      "PELL": ["PELO", "PELA"]}
    by_pattern, report = fill_gaps(truth.with_points(gappy), max_gap_frames=30, donors=donors)
    by_spline, _ = fill_gaps(truth.with_points(gappy), max_gap_frames=30)
    assert report.filled[0].method == "rigid PELO,PELL"
    pattern_error = np.linalg.norm(by_pattern.points - points, axis=2).max()
    spline_error = np.linalg.norm(by_spline.points - points, axis=2).max()
    assert pattern_error < 1e-3 < 1e-2 < spline_error
    # the segment frame stays within a degree of the truth through the gap
    frame = (by_pattern.points[:, 1] - by_pattern.points[:, 0]) / 0.1        # e1
    truth_e1 = rotations[:, :, 0]
    error = np.degrees(np.arccos(np.clip(np.sum(frame / np.linalg.norm(frame, axis=1)[:, None]
                                                * truth_e1, axis=1), -1, 1)))
    assert error.max() < 1.0


def test_rigid_fill_with_three_donors_is_exact_and_one_donor_keeps_the_distance():
    from scipy.spatial.transform import Rotation

    rate, frames = 100.0, 120
    t = np.arange(frames) / rate
    rotations = Rotation.from_rotvec(np.outer(t, [2.0, -1.0, 3.0])).as_matrix()
    local = np.array([[0.0, 0, 0], [0.12, 0, 0], [0, 0.1, 0], [0, 0, 0.08]])
    points = np.stack([0.3 * t, np.sin(t), 1 + 0 * t], axis=1)[:, None, :] \
        + np.einsum("fij,mj->fmi", rotations, local)
    labels = ["A", "B", "C", "D"]
    gappy = points.copy()
    gappy[40:70, 3] = np.nan
    trial = Trial(labels, gappy, rate)
    everyone = {"D": ["A", "B", "C"]}
    filled, report = fill_gaps(trial, max_gap_frames=30, donors=everyone)
    assert report.filled[0].method == "rigid A,B,C"
    np.testing.assert_allclose(filled.points, points, atol=1e-9)
    alone, report = fill_gaps(trial, max_gap_frames=30, donors={"D": ["A"]})
    assert report.filled[0].method == "rigid A"
    distance = np.linalg.norm(alone.points[40:70, 3] - points[40:70, 0], axis=1)
    np.testing.assert_allclose(distance, 0.08, atol=1e-9)
