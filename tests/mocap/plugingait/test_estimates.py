"""Subject measurements estimated from a walk's markers (mocap.plugingait.estimates):
exact on a synthetic subject built to the ratios, within the held-out error on a real
subject whose measurements are withheld, and the angles then close to Vicon's."""
from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocap.errors import MocapError
from mocap.io import read
from mocap.plugingait.clinical import plugingait_angles, prepare_subject
from mocap.plugingait.estimates import (ANKLE_WIDTH_PER_FOOT, ANKLE_WIDTH_PER_LEG,
                                        KNEE_WIDTH_PER_ASIS, EstimatedMeasurementWarning,
                                        estimate_missing)
from mocap.plugingait.model import MARKERS, PLANES, Subject, markers_from_trial, subject_from_trial
from tests.conftest import realdata_path

#: A held-out subject of benchmarks/plugingait_estimates.py (not used to choose the ratios).
WALK = ("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")
STATIC = ("biomechzoo_sample_study", "HC030A", "Static", "HC030A01.c3d")
#: Largest held-out errors of that benchmark (5 subjects, 10 legs), mm, rounded up.
KNEE_WIDTH_BOUND_MM, ANKLE_WIDTH_BOUND_MM = 25.0, 9.0
#: Largest held-out RMS against Vicon's angles with estimated widths and the static,
#: degrees per plane (hip, knee, ankle of 8 walks; benchmark), rounded up.
ANGLE_BOUND_DEG = {"flexion": 1.0, "adduction": 4.0, "rotation": 7.0}


def _synthetic_markers(frames: int = 50, asis_m: float = 0.24, foot_m: float = (0.25, 0.27)):
    """Rigidly moving pelvis and feet: LASI-RASI always asis_m apart, HEE-TOE foot_m."""
    t = np.linspace(0, 1, frames)
    turn = Rotation.from_euler("z", 40 * np.sin(2 * np.pi * t)[:, None], degrees=True)
    travel = np.stack([1.2 * t, 0 * t, 0.9 + 0.02 * np.sin(4 * np.pi * t)], axis=1)
    m = {"LASI": travel + turn.apply([0, asis_m / 2, 0]),
         "RASI": travel + turn.apply([0, -asis_m / 2, 0])}
    for S, y, foot in (("L", 0.1, foot_m[0]), ("R", -0.1, foot_m[1])):
        m[f"{S}ANK"] = travel + turn.apply([0, y, -0.8])
        m[f"{S}HEE"] = travel + turn.apply([-0.05, y, -0.85])
        m[f"{S}TOE"] = m[f"{S}HEE"] + turn.apply([foot, 0, 0])
    return m


def test_widths_of_a_subject_built_to_the_ratios_are_exact_with_one_warning_each():
    m = _synthetic_markers()
    given = Subject(leg_length={"l": 0.9, "r": 0.9}, inter_asis=0.22)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sub = estimate_missing(given, m, "walk.c3d")
    assert sub.knee_width == {"l": pytest.approx(KNEE_WIDTH_PER_ASIS * 0.24, abs=1e-12),
                              "r": pytest.approx(KNEE_WIDTH_PER_ASIS * 0.24, abs=1e-12)}
    assert sub.ankle_width["l"] == pytest.approx(ANKLE_WIDTH_PER_FOOT * 0.25, abs=1e-12)
    assert sub.ankle_width["r"] == pytest.approx(ANKLE_WIDTH_PER_FOOT * 0.27, abs=1e-12)
    assert sub.inter_asis == 0.22 and sub.leg_length == {"l": 0.9, "r": 0.9}   # given: kept
    lines = [str(w.message) for w in caught if w.category is EstimatedMeasurementWarning]
    assert len(lines) == len(caught) == 4
    for name, value in (("L knee width", sub.knee_width["l"]),
                        ("R knee width", sub.knee_width["r"]),
                        ("L ankle width", sub.ankle_width["l"]),
                        ("R ankle width", sub.ankle_width["r"])):
        assert sum(f"{name} not measured: estimated {value * 1000:.0f} mm" in line
                   for line in lines) == 1, (name, lines)
    assert given.knee_width == {"l": None, "r": None}           # the input is not changed


def test_gap_filled_frames_and_given_widths_do_not_count():
    m = _synthetic_markers()
    m["LASI"] = m["LASI"].copy()
    m["LASI"][:10] += [0, 0.5, 0]                               # a bad fill in 10 frames
    keep = {"LASI": np.arange(50) >= 10}
    given = Subject(leg_length={"l": 0.9, "r": 0.9}, inter_asis=0.22,
                    knee_width={"l": 0.1, "r": None}, ankle_width={"l": 0.07, "r": 0.07})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sub = estimate_missing(given, m, keep=keep)
    assert sub.knee_width == {"l": 0.1, "r": pytest.approx(KNEE_WIDTH_PER_ASIS * 0.24)}
    assert sub.ankle_width == {"l": 0.07, "r": 0.07}
    assert len(caught) == 1 and "R knee width" in str(caught[0].message)


def test_without_the_foot_markers_the_ankle_width_is_a_share_of_the_leg():
    m = {k: v for k, v in _synthetic_markers().items() if k not in ("RHEE", "RTOE")}
    sub = estimate_missing(Subject(leg_length={"l": 0.9, "r": 0.8}, inter_asis=0.22), m,
                           warn=False)
    assert sub.ankle_width["r"] == pytest.approx(ANKLE_WIDTH_PER_LEG * 0.8, abs=1e-12)
    del m["LANK"], m["RANK"]
    with pytest.raises(MocapError, match="no LHEE/LTOE or leg length .* L ankle width"):
        estimate_missing(Subject(inter_asis=0.22, leg_length={"l": None, "r": None}),
                         {k: v for k, v in m.items() if k not in ("LHEE", "LTOE")},
                         lengths=False, warn=False)


@pytest.fixture(scope="module")
def real():
    walk, static = read(realdata_path(*WALK)), read(realdata_path(*STATIC))
    measured = subject_from_trial(walk)
    blank = replace(measured, knee_width={"l": None, "r": None},
                    ankle_width={"l": None, "r": None})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        estimated = estimate_missing(blank, markers_from_trial(walk, MARKERS)[0])
        angles = plugingait_angles(walk, estimated, static=static)
    return walk, measured, estimated, angles


def test_widths_of_a_held_out_subject_within_the_held_out_error(real):
    _, measured, estimated, _ = real
    for side in "lr":
        assert abs(estimated.knee_width[side] - measured.knee_width[side]) * 1000 \
            <= KNEE_WIDTH_BOUND_MM
        assert abs(estimated.ankle_width[side] - measured.ankle_width[side]) * 1000 \
            <= ANKLE_WIDTH_BOUND_MM


def test_angles_with_estimated_widths_stay_close_to_vicons(real):
    walk, _, _, angles = real
    m = walk.modelled
    vicon = {label.rpartition(":")[2]: m["values"][:, k] for k, label in enumerate(m["labels"])}
    for side in "lr":
        for joint in ("hip", "knee", "ankle"):
            theirs = vicon[f"{side.upper()}{joint.capitalize()}Angles"]
            ours = angles.segment(f"{side}_{joint}")
            for k, plane in enumerate(PLANES):
                ok = np.isfinite(ours[:, k]) & np.isfinite(theirs[:, k])
                assert ok.sum() > 100
                rms = np.sqrt(np.mean((ours[ok, k] - theirs[ok, k]) ** 2))
                assert rms <= ANGLE_BOUND_DEG[plane], (side, joint, plane, rms)


def test_a_static_without_medial_markers_takes_the_walks_estimate(real):
    """The pyCGM-style case: a static that cannot measure the widths no longer stops the
    calibration; the widths come from the walk, said once each."""
    walk, measured, estimated, _ = real
    static = read(realdata_path(*STATIC))
    static.parameters = {g: v for g, v in static.parameters.items() if g != "PROCESSING"}
    walk_bare = walk.with_points(walk.points)
    walk_bare.parameters = {g: v for g, v in walk.parameters.items() if g != "PROCESSING"}
    medial = {label for label in static.labels
              if label.rpartition(":")[2][1:] in ("KNM", "MKN", "MFC", "KNEM", "MED",
                                                  "MMA", "MMAL", "ANKM")}
    static = static.select([label for label in static.labels if label not in medial])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sub = prepare_subject(walk_bare, static=static)
    said = [str(w.message) for w in caught if w.category is EstimatedMeasurementWarning]
    for name in ("L knee width", "R knee width", "L ankle width", "R ankle width"):
        assert sum(f"{name} not measured" in line for line in said) == 1, said
    assert sub.calibrated
    for side in "lr":
        assert sub.knee_width[side] == pytest.approx(estimated.knee_width[side])
        assert sub.ankle_width[side] == pytest.approx(estimated.ankle_width[side])
