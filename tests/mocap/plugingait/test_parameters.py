"""Gait-cycle parameters: Vicon's definitions, a synthetic walk, Vicon's stored values."""
import numpy as np
import pytest

import mocap
from mocap.plugingait.events import FOOT_OFF, FOOT_STRIKE, GaitEvent
from mocap.plugingait.parameters import cycle_timing, gait_parameters, to_dataframe
from mocap.trial import Trial
from tests.conftest import realdata_path

SUB_LABELS = ("c3dorg_via_c3dio", "sample_04", "sub_labels.c3d")


def _vicon(trial):
    """Vicon's ANALYSIS group as {(context, name): value}."""
    a = trial.parameters["ANALYSIS"]
    return {(c, n): float(v) for c, n, v in zip(a["CONTEXTS"], a["NAMES"], a["VALUES"])}


def test_definitions_are_the_identities_vicons_stored_values_satisfy():
    # Rebuild the right cycle's event times from Vicon's stored percentages and stride
    # time; our timing must then give back Vicon's step time, cadence and supports.
    v = {n: x for (c, n), x in _vicon(mocap.read(realdata_path(*SUB_LABELS))).items()
         if c == "Right"}
    T, rate = v["Stride Time"], 60.0
    fo, ofo, ofc = (T * v[n] / 100 for n in ("Foot Off", "Opposite Foot Off",
                                             "Opposite Foot Contact"))
    events = [GaitEvent(side, label, time * rate) for side, label, time in (
        ("r", FOOT_STRIKE, 0.0), ("l", FOOT_OFF, ofo), ("l", FOOT_STRIKE, ofc),
        ("r", FOOT_OFF, fo), ("r", FOOT_STRIKE, T))]
    trial = Trial(["C7"], np.zeros((int(T * rate) + 2, 1, 3)), rate)  # no heels
    right = gait_parameters(trial, events)[1]
    assert right.cycles == 1 and np.isnan(right.stride_length)
    for field, name in (("stride_time", "Stride Time"), ("step_time", "Step Time"),
                        ("cadence", "Cadence"), ("foot_off", "Foot Off"),
                        ("opposite_foot_off", "Opposite Foot Off"),
                        ("opposite_foot_contact", "Opposite Foot Contact"),
                        ("single_support", "Single Support"),
                        ("double_support", "Double Support")):
        assert getattr(right, field) == pytest.approx(v[name], abs=1e-4), name
    assert cycle_timing([0.0, 1.0], [0.6], [0.5], [0.1])[0, 1] == pytest.approx(0.5)


def test_a_synthetic_walk_gives_its_stride_and_step():
    # Heels planted at x = 0, 1.2 (left) and 0.6, 1.8 (right), 1 m/s drift between plants.
    rate, frames = 100.0, 130
    t = np.arange(frames) / rate
    left = np.stack([np.clip(t - 0.1, 0, 1.2), np.full(frames, 0.1), np.zeros(frames)], 1)
    right = np.stack([0.6 + np.clip(t - 0.7, 0, 1.2), np.full(frames, -0.1),
                      np.zeros(frames)], 1)
    trial = Trial(["LHEE", "RHEE"], np.stack([left, right], 1), rate)
    events = [GaitEvent("l", FOOT_STRIKE, 0), GaitEvent("r", FOOT_OFF, 10),
              GaitEvent("r", FOOT_STRIKE, 60), GaitEvent("l", FOOT_OFF, 70),
              GaitEvent("l", FOOT_STRIKE, 130 - 1)]
    left_p, right_p = gait_parameters(trial, events)
    assert left_p.cycles == 1 and right_p.cycles == 0
    assert left_p.stride_time == pytest.approx(1.29)
    assert left_p.stride_length == pytest.approx(1.19)  # heel at frame 129: x = 1.29 - 0.1
    assert left_p.step_length == pytest.approx(1.19 - 0.6)
    assert left_p.step_width == pytest.approx(0.2)      # heels at y = +0.1 and -0.1
    assert left_p.walking_speed == pytest.approx(1.19 / 1.29)
    assert left_p.opposite_foot_contact == pytest.approx(100 * 0.6 / 1.29)
    assert np.isnan(right_p.stride_time)
    frame = to_dataframe([left_p, right_p])
    assert list(frame["Context"]) == ["Left", "Right"]
    assert frame.loc[0, "Stride Length (m)"] == pytest.approx(1.19)
    assert frame.loc[0, "Step Width (m)"] == pytest.approx(0.2)


def test_step_width_is_across_the_stride_whatever_the_walking_direction():
    # The same walk turned 30° about the vertical: lengths and width do not change.
    rate, frames = 100.0, 130
    t = np.arange(frames) / rate
    left = np.stack([np.clip(t - 0.1, 0, 1.2), np.full(frames, 0.13), np.zeros(frames)], 1)
    right = np.stack([0.6 + np.clip(t - 0.7, 0, 1.2), np.full(frames, -0.1),
                      np.zeros(frames)], 1)
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    turn = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    points = np.stack([left, right], 1) @ turn.T
    events = [GaitEvent("l", FOOT_STRIKE, 0), GaitEvent("r", FOOT_OFF, 10),
              GaitEvent("r", FOOT_STRIKE, 60), GaitEvent("l", FOOT_OFF, 70),
              GaitEvent("l", FOOT_STRIKE, 130 - 1)]
    left_p = gait_parameters(Trial(["LHEE", "RHEE"], points, rate), events)[0]
    assert left_p.step_width == pytest.approx(0.23)
    assert left_p.step_length == pytest.approx(1.19 - 0.6)
    assert left_p.stride_length == pytest.approx(1.19)


def test_left_stride_matches_vicons_stored_analysis():
    # sub_labels.c3d is the one real file whose ANALYSIS holds values. Its left cycle
    # spans the file's two left strikes; Vicon's right cycle (2.77 s) and its step
    # timing do not come from the events the file stores, so they are not compared.
    trial = mocap.read(realdata_path(*SUB_LABELS))
    vicon = _vicon(trial)
    left = gait_parameters(trial)[0]
    dt = 1 / trial.rate                       # events are frame-quantised
    T = vicon[("Left", "Stride Time")]
    assert abs(left.stride_time - T) <= dt
    assert abs(left.cadence - vicon[("Left", "Cadence")]) <= 120 / T**2 * dt * 1.05
    # the file has no heel marker: the ankle marker stands in, 15 mm allowed
    assert abs(left.stride_length - vicon[("Left", "Stride Length")] / 100) <= 0.015
    speed = vicon[("Left", "Walking Speed")] / 100
    assert abs(left.walking_speed - speed) <= 0.015 / T + speed * dt / T
