"""Time normalisation: resampling, gap bridging, branch, cycle detection."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.errors import MocapError
from mocap.clean.resample import resample
from mocap.rotations.angles import JointAngles
from synthesis.corpus import CorpusEntry, corpus_from_angles
from synthesis.cycles import (CycleWarning, cycle_phase_lags, detect_cycles, mean_cycle,
                              warn_misaligned_cycles)


def test_resample_is_exact_for_linear_signals():
    times = np.sort(np.random.default_rng(0).uniform(0, 2, 50))
    values = np.column_stack([3 * times + 1, -times])
    out = resample(times, values, times[0], times[-1], 17)
    instants = np.linspace(times[0], times[-1], 17)
    assert np.allclose(out, np.column_stack([3 * instants + 1, -instants]))


def test_one_cycle_normalisation_keeps_duration_fills_gaps_and_picks_the_branch():
    times = np.arange(91) / 100.0                              # 0.90 s
    angle = 200.0 + 10 * np.sin(2 * np.pi * times / 0.9)       # stored wrapped to (-180, 180]
    values = np.column_stack([(angle + 180) % 360 - 180, 5 * times])
    values[30:40, 1] = np.nan                                  # a gap in a linear angle
    curve, duration, count = mean_cycle(times, values, samples=10)
    assert duration == pytest.approx(0.9) and count == 1
    phase = np.linspace(0, 0.9, 10)
    assert np.allclose(curve[:, 1], 5 * phase, atol=1e-9)
    # Mean 200° is brought to the branch with mean in (-180, 180]: −160°.
    expected = -160.0 + 10 * np.sin(2 * np.pi * phase / 0.9)
    assert np.allclose(curve[:, 0], expected, atol=0.1)


def test_cycle_detection_finds_the_period_and_averages_cycles():
    rate, period = 100.0, 1.1
    times = np.arange(int(3.6 * period * rate)) / rate
    hip = 20 * np.cos(2 * np.pi * (times - 0.25) / period)    # maxima at 0.25 + k·1.1 s
    knee = 30 + 25 * np.sin(2 * np.pi * (times - 0.25) / period) ** 2
    bounds = detect_cycles(times, hip)
    assert len(bounds) == 3
    assert np.allclose(bounds[:, 0], 0.25 + period * np.arange(3), atol=2e-3)
    assert np.allclose(bounds[:, 1] - bounds[:, 0], period, atol=2e-3)
    curve, duration, count = mean_cycle(times, np.column_stack([hip, knee]), 50,
                                              cycles=True)
    assert count == 3 and duration == pytest.approx(period, abs=2e-3)
    u = np.linspace(0, 1, 50)
    assert np.allclose(curve[:, 0], 20 * np.cos(2 * np.pi * u), atol=0.1)


def test_cycle_detection_without_repetition_is_a_clear_error():
    times = np.arange(100) / 100.0
    with pytest.raises(MocapError, match="no complete cycle"):
        mean_cycle(times, np.column_stack([times ** 2]), cycles=True)


def _separations(period, seconds=4.0, rate=30.0, across=False, backwards=False):
    """Foot separation (X across, Z along the walking direction) of a gait, metres."""
    times = np.arange(0.0, seconds, 1.0 / rate)
    swing = 0.3 * np.sin(2 * np.pi * times / period) * (-1 if backwards else 1)
    steady = 0.2 + 0.01 * np.cos(2 * np.pi * times / period)
    along = np.column_stack([steady, swing])
    return times, (along[:, ::-1] if across else along)


def test_sidesteps_are_cut_along_their_own_axis_and_walks_along_the_walking_axis():
    from synthesis.skeletons import cut_action
    axis = np.array([0.0, 1.0])                      # the corpus' walking axis (Z)
    times, sidestep = _separations(1.2, across=True)
    events, own = cut_action([times, times], [sidestep, sidestep * 1.1], axis, 0.9)
    assert own is not None and abs(own[0]) > 0.99    # across the walking direction
    for cycles in events:
        assert len(cycles) >= 2
        assert np.allclose(cycles[:, 2] - cycles[:, 0], 1.2, atol=0.02)
    for backwards in (False, True):                  # walking backwards: the walking axis
        times, walk = _separations(1.1, backwards=backwards)
        events, own = cut_action([times], [walk], axis, 0.9)
        assert own is None and np.allclose(events[0][:, 2] - events[0][:, 0], 1.1, atol=0.02)


def test_a_run_at_30_hz_is_cut_into_its_short_cycles():
    """0.7 s run cycles are 21 frames at 30 Hz: every complete one is found, to the frame."""
    from synthesis.skeletons import cut_action
    times, run = _separations(0.7, seconds=3.0)
    events, own = cut_action([times], [run], np.array([0.0, 1.0]), 0.9)
    assert own is None and len(events[0]) >= 3
    assert np.allclose(events[0][:, 2] - events[0][:, 0], 0.7, atol=1 / 30)


def _cycle(samples=50, columns=6, seed=0):
    """A smooth periodic cycle of a few harmonics per column."""
    rng = np.random.default_rng(seed)
    phase = np.linspace(0.0, 1.0, samples, endpoint=False)[:, None]
    harmonics = np.arange(1, 4)[None, :, None]
    amplitude = rng.normal(size=(1, 3, columns)) / harmonics
    offset = rng.uniform(0, 2 * np.pi, size=(1, 3, columns))
    return np.sum(amplitude * np.sin(2 * np.pi * harmonics * phase[:, :, None] + offset), axis=1)


@pytest.mark.parametrize("roll", [1, 7, -12, 25])
def test_phase_lag_of_a_rolled_trial_is_its_roll(roll):
    base = _cycle()
    others = [base * (1 + 0.05 * k) + 0.01 * k for k in range(4)]       # same phase, other size
    curves = np.stack(others + [np.roll(base, roll, axis=0)])
    lags = cycle_phase_lags(curves)
    assert lags[-1] == pytest.approx(roll / 50)
    # The others' reference holds the rolled trial at a quarter weight: a sample at most.
    assert np.abs(lags[:-1]).max() <= 1 / 50
    with pytest.raises(MocapError, match="two trials"):
        cycle_phase_lags(curves[:1])


def test_only_a_trial_cut_half_a_cycle_off_is_named():
    base = _cycle()
    curves = np.stack([base, 1.1 * base, 0.9 * base, np.roll(base, 3, axis=0),
                       np.roll(base, 25, axis=0)])
    sources = [f"t{k}.bvh" for k in range(5)]
    pattern = r"t4\.bvh: .* 'walk' best when shifted by 4[6-9] %"
    with pytest.warns(CycleWarning, match=pattern) as caught:
        lags = warn_misaligned_cycles(curves, sources, "walk")
    assert len(caught) == 1 and abs(lags[3]) < 0.1
    # Two trials are too few to say which one is off: nothing is checked.
    assert np.isnan(warn_misaligned_cycles(curves[:2], sources[:2], "walk")).all()


def test_an_euler_corpus_names_a_trial_whose_cut_falls_at_another_event():
    """Cycles cut at the reference angle's maxima: in one trial every other angle runs half
    a cycle behind the reference (its maxima mark another event of the movement), and the
    corpus reader names that trial; the well-cut trials pass without a word."""
    rate, period = 100.0, 1.0
    times = np.arange(int(4.2 * period * rate)) / rate
    def angles(scale, delay=0.0):
        u = times / period
        reference = 30 * np.cos(2 * np.pi * u)
        rest = [scale * 20 * np.sin(2 * np.pi * (u - delay) + k) + 5 * np.sin(4 * np.pi * (u - delay))
                for k in (0.3, 1.1, 2.0, 2.9, 4.1)]
        values = np.column_stack([reference] + rest).reshape(len(times), 2, 3)
        return JointAngles(times, values, ["thigh", "shank"], "ZXY", [-1, 0])
    trials = [(CorpusEntry(f"{name}_walk.csv", name, "walk"), angles(scale))
              for name, scale in (("ana", 1.0), ("ben", 1.2), ("cy", 0.8))]
    trials.append((CorpusEntry("dan_walk.csv", "dan", "walk"), angles(1.0, delay=0.5)))
    trials += [(CorpusEntry(f"{e.person}_run.csv", e.person, "run"), a) for e, a in trials]
    with pytest.warns(CycleWarning) as caught:
        corpus = corpus_from_angles(trials, samples=40, cycles=True, cycle_column="thigh.Z")
    named = [str(w.message) for w in caught if "shifted by" in str(w.message)]
    assert len(named) == 2 and all(m.startswith("dan_") for m in named)
    assert corpus.cycle_counts.min() >= 3
