"""Plug-in Gait upper body (mocap.plugingait.upper; the foot progression, a lower-body
angle, is test_foot_progression.py).

Known answers: an exact synthetic posture (upper_posture.py places the markers by
inverting the model's chords) gives back its joint centres and frames to rounding, zero
angles when neutral and the angle of each single-plane movement in the one component
it belongs to.  Real files: the convention table turns Vicon's own segment outputs
(TRXO/TRXA/TRXL/TRXP …) into the angles Vicon stored beside them, and our angles from
the markers equal Vicon's stored ones (the 27-file comparison with its design and
held-out halves is benchmarks/upper_body.py).
"""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from mocap.errors import MocapError
from mocap.io import read
from mocap.plugingait.clinical import clinical_columns, plugingait_angles, vicon_label
from mocap.plugingait.model import AnatomicalOffsetWarning, Kinematics, progression_frame
from mocap.plugingait.upper import (ANGLES, UPPER_JOINTS, VICON_NAMES, UpperBodyWarning,
                                    UpperSubject, upper_angles, upper_columns,
                                    upper_kinematics, upper_subject_from_trial,
                                    vicon_angles)
from tests.conftest import realdata_path
from tests.mocap.plugingait.upper_posture import RADIUS, SUBJECT, posture, rot

ZOO = "biomechzoo_sample_study"
#: A straight walk and a turn, each with its subject's static (HC030A is on the held-out
#: half of benchmarks/upper_body.py, HC038A on the design half).
WALKS = [(("HC030A", "Straight", "HC030A05.c3d"), ("HC030A", "Static", "HC030A01.c3d")),
         (("HC038A", "Turn", "HC038A27.c3d"), ("HC038A", "Static", "HC038A01.c3d"))]


# ------------------------------------------------------------------ known answers

def _angles(markers: dict) -> dict:
    """Upper-body angles of a one-frame posture (pelvis and progression: the lab)."""
    upper = upper_kinematics(markers, SUBJECT, RADIUS)
    lower = Kinematics({}, {"pelvis": np.eye(3)[None]})
    return dict(zip(upper_columns(), upper_angles(lower, upper, np.eye(3))[0]))


def test_the_posture_gives_back_its_joint_centres_and_frames():
    markers, truth = posture(trunk=rot("z", 20) @ rot("y", 8), head=rot("x", -12),
                             shoulder={"l": rot("y", -40) @ rot("x", 15), "r": rot("z", 25)},
                             elbow_deg={"l": 60.0, "r": 130.0},
                             wrist={"l": rot("y", 25), "r": rot("x", -10)})
    kin = upper_kinematics(markers, SUBJECT, RADIUS)
    assert kin.notes == []
    for name in ("l_shoulder", "l_elbow", "l_wrist", "l_hand", "r_shoulder", "r_elbow",
                 "r_wrist", "r_hand"):
        np.testing.assert_allclose(kin.centres[name][0], truth[name], atol=1e-12)
    np.testing.assert_allclose(kin.centres["l_hand_end"][0],
                               2 * truth["l_hand"] - truth["l_wrist"], atol=1e-12)
    for name, true in (("thorax", "thorax"), ("head", "head"), ("l_humerus", "l_humerus"),
                       ("r_radius", "r_radius"), ("l_hand", "l_hand_frame"),
                       ("r_hand", "r_hand_frame")):
        np.testing.assert_allclose(kin.frames[name][0], truth[true], atol=1e-12)


def test_neutral_posture_is_zero_but_the_elbow():
    angles = _angles(posture()[0])
    for side in "lr":
        for joint in UPPER_JOINTS:
            expected = [90.0, 0.0, 0.0] if joint == "elbow" else [0.0, 0.0, 0.0]
            np.testing.assert_allclose(angles[f"{side}_{joint}"], expected, atol=1e-9,
                                       err_msg=f"{side}_{joint}")


#: Single-plane movements from the neutral posture and the one component each gives
#: (docs/plugingait-upper.md states these senses): (posture, {column: (X, Y, Z)}).
MOVEMENTS = {
    "trunk leans forward 10": (dict(trunk=rot("y", 10)), {
        "l_thorax": (10, 0, 0), "r_thorax": (10, 0, 0), "l_spine": (10, 0, 0),
        "l_head": (-10, 0, 0)}),
    "trunk leans right 10": (dict(trunk=rot("x", 10)), {
        "l_thorax": (0, 10, 0), "r_thorax": (0, -10, 0), "l_spine": (0, -10, 0),
        "r_spine": (0, 10, 0), "l_head": (0, 10, 0)}),
    "trunk turns left 10": (dict(trunk=rot("z", 10)), {
        "l_thorax": (0, 0, -10), "r_thorax": (0, 0, 10), "l_spine": (0, 0, 10),
        "r_spine": (0, 0, -10), "r_head": (0, 0, 10)}),
    "head nods forward 10": (dict(head=rot("y", 10)), {
        "l_neck": (10, 0, 0), "r_neck": (10, 0, 0), "l_head": (-10, 0, 0)}),
    "head tilts right 10": (dict(head=rot("x", 10)), {
        "l_neck": (0, -10, 0), "r_neck": (0, 10, 0), "l_head": (0, 10, 0)}),
    "head turns left 10": (dict(head=rot("z", 10)), {
        "l_neck": (0, 0, 10), "r_neck": (0, 0, -10), "r_head": (0, 0, 10)}),
    "arms flex 30": (dict(shoulder={"l": rot("y", -30), "r": rot("y", -30)}), {
        "l_shoulder": (30, 0, 0), "r_shoulder": (30, 0, 0)}),
    "arms abduct 30": (dict(shoulder={"l": rot("x", 30), "r": rot("x", -30)}), {
        "l_shoulder": (0, 30, 0), "r_shoulder": (0, 30, 0)}),
    "arms rotate in 30": (dict(shoulder={"l": rot("z", -30), "r": rot("z", 30)}), {
        "l_shoulder": (0, 0, 30), "r_shoulder": (0, 0, 30)}),
    "elbows flex to 120": (dict(elbow_deg={"l": 120.0, "r": 120.0}), {
        "l_elbow": (120, 0, 0), "r_elbow": (120, 0, 0)}),
    "hands turn about the flexion axis 20": (dict(wrist={"l": rot("y", 20),
                                                         "r": rot("y", 20)}), {
        "l_wrist": (20, 0, 0), "r_wrist": (20, 0, 0)}),
    "hands turn about their x 20": (dict(wrist={"l": rot("x", 20), "r": rot("x", 20)}), {
        "l_wrist": (0, -20, 0), "r_wrist": (0, 20, 0)}),
    "hands turn about their long axis 20": (dict(wrist={"l": rot("z", 20),
                                                        "r": rot("z", 20)}), {
        "l_wrist": (0, 0, -20), "r_wrist": (0, 0, 20)}),
}


@pytest.mark.parametrize("name", MOVEMENTS)
def test_a_single_plane_movement_gives_its_one_angle(name):
    pose, expected = MOVEMENTS[name]
    angles = _angles(posture(**pose)[0])
    neutral = _angles(posture()[0])
    for column, value in expected.items():
        np.testing.assert_allclose(angles[column], value, atol=1e-9, err_msg=column)
    # the joints the movement does not cross keep their neutral angles
    crossed = {"trunk": {"thorax", "spine", "head"}, "head": {"neck", "head"},
               "shoulder": {"shoulder"}, "elbow_deg": {"elbow"},
               "wrist": {"wrist"}}[next(iter(pose))]
    for column in angles:
        if column.split("_", 1)[1] not in crossed:
            np.testing.assert_allclose(angles[column], neutral[column], atol=1e-9,
                                       err_msg=column)


def test_missing_markers_and_measurements_leave_only_their_segments_out():
    markers, _ = posture()
    del markers["RFIN"], markers["LBHD"]
    subject = UpperSubject(shoulder_offset=dict(SUBJECT.shoulder_offset),
                           elbow_width={"l": None, "r": 0.07},
                           wrist_width=dict(SUBJECT.wrist_width),
                           hand_thickness=dict(SUBJECT.hand_thickness))
    kin = upper_kinematics(markers, subject, RADIUS)
    assert set(kin.frames) == {"thorax", "r_humerus", "r_radius"}
    assert any("no head" in n for n in kin.notes)
    assert any("L: no arm" in n and "elbow width" in n for n in kin.notes)
    assert any("R: no hand (RFIN" in n for n in kin.notes)
    subject.hand_thickness = {"l": 0.02, "r": None}
    subject.elbow_width = dict(SUBJECT.elbow_width)
    markers, _ = posture()
    kin = upper_kinematics(markers, subject, RADIUS)
    assert "l_hand" in kin.frames and "r_radius" in kin.frames and "r_hand" not in kin.frames


# ------------------------------------------------------------------ real files

def _vicon(trial) -> dict:
    modelled = trial.modelled
    return {label.rpartition(":")[2]: modelled["values"][:, k]
            for k, label in enumerate(modelled["labels"])}


def _vicon_frame(trial, segment: str) -> np.ndarray:
    """Vicon's segment output (origin, anterior, left, proximal points) as rotations."""
    index = {label.rpartition(":")[2]: k for k, label in enumerate(trial.labels)}
    origin = trial.points[:, index[f"{segment}O"]]
    axes = [trial.points[:, index[f"{segment}{k}"]] - origin for k in "ALP"]
    return np.stack([a / np.linalg.norm(a, axis=1, keepdims=True) for a in axes], axis=-1)


@pytest.fixture(scope="module")
def walks():
    out = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AnatomicalOffsetWarning)
        for walk, static in WALKS:
            trial = read(realdata_path(ZOO, *walk))
            angles = plugingait_angles(trial, static=read(realdata_path(ZOO, *static)),
                                       upper_body=True)
            out.append((walk[-1], trial, angles))
    return out


def test_the_table_turns_vicons_segment_outputs_into_vicons_angles(walks):
    """Vicon's own frames through ANGLES give the angles Vicon stored (< 0.001°)."""
    segments = {"pelvis": "PEL", "thorax": "TRX", "head": "HED", "humerus": "HU",
                "radius": "RA", "hand": "HN"}
    for name, trial, _ in walks:
        pelvis = _vicon_frame(trial, "PEL")
        origin = trial.points[:, [k for k, label in enumerate(trial.labels)
                                  if label.endswith("PELO")][0]]
        frames = {"progression": np.broadcast_to(progression_frame(origin, pelvis),
                                                 pelvis.shape)}
        stored = _vicon(trial)
        for side in "lr":
            for joint, (proximal, distal, _, _) in ANGLES.items():
                pair = [frames.get(f) if f == "progression" else _vicon_frame(
                    trial, segments[f] if f in ("pelvis", "thorax", "head")
                    else side.upper() + segments[f]) for f in (proximal, distal)]
                ours = vicon_angles(*pair, joint, side)
                difference = (ours - stored[side.upper() + VICON_NAMES[joint]] + 180) % 360 - 180
                assert np.nanmax(np.abs(difference)) < 1e-3, (name, side, joint)


def test_upper_body_equals_vicons_stored_angles(walks):
    """Every upper-body component within 0.01° RMS of Vicon's (measured: < 0.001°)."""
    for name, trial, angles in walks:
        assert angles.segments == clinical_columns() + upper_columns()
        stored = _vicon(trial)
        assert all(vicon_label(s) in stored for s in angles.segments)
        for side in "lr":
            for joint in UPPER_JOINTS:
                ours = angles.segment(f"{side}_{joint}")
                vicon = stored[side.upper() + VICON_NAMES[joint]]
                both = np.isfinite(ours).all(axis=1) & np.isfinite(vicon).all(axis=1)
                assert both.sum() > 0.9 * len(both), (name, side, joint)
                rms = np.sqrt(np.mean((ours[both] - vicon[both]) ** 2, axis=0))
                assert (rms < 0.01).all(), (name, side, joint, rms)


def test_measurements_come_from_the_walk_then_the_static():
    walk = read(realdata_path(ZOO, "HC030A", "Straight", "HC030A05.c3d"))
    sub = upper_subject_from_trial(walk)
    assert sub.shoulder_offset == {"l": 0.035, "r": 0.035}
    assert sub.elbow_width["l"] == pytest.approx(0.084) and sub.head_offset == 0.0
    bare = read(realdata_path("pycgm", "ROM", "Sample_Static.c3d"))    # no PROCESSING
    assert upper_subject_from_trial(bare).missing("l") == [
        "shoulder_offset", "elbow_width", "wrist_width", "hand_thickness"]
    assert upper_subject_from_trial(bare, walk).wrist_width["r"] == pytest.approx(0.050)


def test_a_trial_without_upper_body_markers_is_refused(walks):
    _, trial, _ = walks[0]
    keep = [label for label in trial.labels
            if label.rpartition(":")[2] not in ("C7", "T10", "CLAV", "STRN", "LFHD", "RFHD",
                                               "LBHD", "RBHD", "LSHO", "RSHO", "LELB",
                                               "RELB", "LWRA", "LWRB", "RWRA", "RWRB",
                                               "LFIN", "RFIN")]
    lower_only = trial.select(keep)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AnatomicalOffsetWarning)
        with pytest.raises(MocapError, match="no Plug-in Gait upper-body markers"):
            plugingait_angles(lower_only, upper_body=True)
        assert plugingait_angles(lower_only).segments == clinical_columns()


def test_missing_measurements_warn_and_leave_the_arms_empty(walks):
    _, trial, _ = walks[0]
    subject = upper_subject_from_trial(trial)
    subject.hand_thickness = {"l": None, "r": 0.03}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        angles = plugingait_angles(trial, upper_body=True, upper_subject=subject)
    notes = [str(w.message) for w in caught if issubclass(w.category, UpperBodyWarning)]
    assert len(notes) == 1 and "L: no hand" in notes[0] and "hand thickness" in notes[0]
    assert np.isnan(angles.segment("l_wrist")).all()
    assert np.isfinite(angles.segment("l_shoulder")).any()
    assert np.isfinite(angles.segment("r_wrist")).any()
    assert np.isfinite(angles.segment("l_thorax")).any()


def test_thorax_and_head_gaps_are_filled_from_their_groups(walks):
    """A 0.2 s gap of a head or thorax marker is filled from the other three of its
    group: the upper-body angles inside it stay within 0.2° (worst joint-plane RMS;
    0.015° and 0.13° measured here) and every frame outside it is untouched."""
    from mocap.plugingait.clinical import fill_plugingait, plugingait_labels, prepare_subject

    walk, static = WALKS[0]
    trial = read(realdata_path(ZOO, *walk))
    trial = trial.select(plugingait_labels(trial, upper_body=True))
    subject = prepare_subject(trial, static=read(realdata_path(ZOO, *static)), warn=False)
    truth = plugingait_angles(trial, subject=subject, upper_body=True).values
    inside, outside = slice(90, 110), np.r_[0:90, 110:trial.frames]
    for name in ("LFHD", "CLAV"):
        points = trial.points.copy()
        points[inside, trial.labels.index(name)] = np.nan
        filled, report = fill_plugingait(trial.with_points(points), subject, 20)
        assert len(report.filled) == 1 and not report.unfilled
        angles = plugingait_angles(filled, subject=subject, upper_body=True).values
        assert np.array_equal(angles[outside], truth[outside], equal_nan=True)
        rms = np.sqrt(np.mean((angles[inside] - truth[inside]) ** 2, axis=0))
        assert np.nanmax(rms) < 0.2, (name, np.nanmax(rms))
