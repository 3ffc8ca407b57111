"""The Plug-in Gait model's pieces against hand-checkable answers and pyCGM's
published examples (Kadaba 1990, Davis 1991; pyCGM, Schwartz et al.)."""
from __future__ import annotations

import numpy as np

from mocap.rotations.angles import angles_to_matrices
from mocap.plugingait.model import (Subject, chord, clinical_angles, hip_joint_centres,
                              progression_frame, yxz_angles)


def test_chord_matches_pycgm_example_and_its_defining_geometry():
    # pyCGM's calc_joint_center docstring: thigh marker, hip centre, knee marker, 59.5 mm
    plane = np.array([[468.14, 325.09, 673.12]])
    joint = np.array([[355.90, 365.38, 940.69]])
    marker = np.array([[452.35, 329.06, 524.77]])
    centre = chord(plane, joint, marker, 59.5)
    np.testing.assert_allclose(centre[0], [396.25, 347.92, 518.63], atol=0.01)
    # |J - marker| = delta, a right angle at J, J in the plane of the three points
    assert abs(np.linalg.norm(centre - marker) - 59.5) < 1e-9
    assert abs(np.dot((centre - marker)[0], (centre - joint)[0])) < 1e-6
    normal = np.cross(plane - marker, joint - marker)[0]
    assert abs(np.dot(normal, (centre - marker)[0])) < 1e-6


def test_chord_rotation_turns_the_plane_about_the_segment_axis():
    rng = np.random.default_rng(5)
    joint = rng.normal(0, 10, (50, 3)) + [0, 0, 450]
    marker = rng.normal(0, 10, (50, 3)) + [0, 60, 0]
    plane = rng.normal(0, 10, (50, 3)) + [20, 80, 220]
    for degrees in (-13.0, 4.0, 25.0):
        centre = chord(plane, joint, marker, 55.0, np.radians(degrees))
        np.testing.assert_allclose(np.linalg.norm(centre - marker, axis=1), 55.0, atol=1e-6)
        axis = (joint - centre) / np.linalg.norm(joint - centre, axis=1, keepdims=True)

        def about_axis(p):
            v = p - centre
            v -= np.sum(v * axis, axis=1, keepdims=True) * axis
            return v / np.linalg.norm(v, axis=1, keepdims=True)
        u, w = about_axis(plane), about_axis(marker)
        angle = np.degrees(np.arctan2(np.sum(np.cross(u, w) * axis, axis=1),
                                      np.sum(u * w, axis=1)))
        np.testing.assert_allclose(angle, degrees, atol=1e-4)


def test_davis_hip_centres_match_pycgm_example():
    # pyCGM's calc_joint_center_hip docstring (mean leg 940 mm, ASIS-trochanter
    # 72.51 mm, inter-ASIS 215.90 mm, 14 mm markers); rows of its 4x4 are the axes.
    # The model works in metres: the example's millimetres are converted in and out.
    pelvis = np.array([[0.14, 0.98, -0.11, 251.60], [-0.99, 0.13, -0.02, 391.74],
                       [0, 0.1, 0.99, 1032.89]])
    subject = Subject(marker_diameter=0.014, leg_length={"l": 0.940, "r": 0.940},
                      asis_trochanter={"l": 0.07251, "r": 0.07251}, inter_asis=0.21590)
    centres = hip_joint_centres(pelvis[:, :3].T[None], pelvis[:, 3][None] / 1000.0, subject)
    np.testing.assert_allclose(centres["r"][0] * 1000.0, [307.36, 323.83, 938.72], atol=0.01)
    np.testing.assert_allclose(centres["l"][0] * 1000.0, [181.71, 340.33, 936.18], atol=0.01)


def test_subject_lengths_in_millimetres_are_refused():
    """Subject holds metres: a knee 100 (mm) wide is a MocapError naming the field."""
    import pytest

    from mocap.errors import MocapError
    with pytest.raises(MocapError, match=r"knee_width\['l'\] = 100 .*millimetres"):
        Subject(knee_width={"l": 100.0, "r": 0.1})
    assert Subject(knee_width={"l": 0.1, "r": 0.1}).radius == 0.007


def test_yxz_angles_and_clinical_signs_on_known_rotations():
    truth = np.array([[30.0, -10.0, 20.0], [-50.0, 25.0, -5.0]])
    distal = angles_to_matrices(truth, "YXZ")
    proximal = np.broadcast_to(np.eye(3), distal.shape)
    np.testing.assert_allclose(yxz_angles(proximal, distal), truth, atol=1e-9)
    # a knee flexed 30°: the shank's z tilts forward, about +y: knee flexion +30 on
    # both sides; the same rotation of the thigh in the pelvis is hip extension
    flexed = angles_to_matrices(np.array([[30.0, 0, 0]]), "YXZ")
    eye = np.eye(3)[None]
    for side in "lr":
        assert np.isclose(clinical_angles(eye, flexed, "knee", side)[0, 0], 30.0)
        assert np.isclose(clinical_angles(eye, flexed, "hip", side)[0, 0], -30.0)
    # the thigh turned about its long axis toward the body's midline is internal rotation
    left_internal = angles_to_matrices(np.array([[0, 0, -12.0]]), "YXZ")   # x toward -y
    right_internal = angles_to_matrices(np.array([[0, 0, 12.0]]), "YXZ")   # x toward +y
    assert np.isclose(clinical_angles(eye, left_internal, "hip", "l")[0, 2], 12.0)
    assert np.isclose(clinical_angles(eye, right_internal, "hip", "r")[0, 2], 12.0)
    # the foot at neutral: its z runs backwards, x up (Plug-in Gait's foot frame)
    foot = np.array([[[0.0, 0, -1], [0, 1, 0], [1, 0, 0]]])
    np.testing.assert_allclose(clinical_angles(eye, foot, "ankle", "l")[0], 0.0, atol=1e-9)


def test_progression_frame_follows_the_pelvis_along_the_lab_axis():
    t = np.linspace(0, 2, 50)[:, None]
    walking_minus_y = np.hstack([0.005 + 0.00002 * t, -1.2 * t, 0 * t + 0.9])   # metres
    frame = progression_frame(walking_minus_y, np.full((50, 3, 3), np.nan))
    np.testing.assert_allclose(frame[:, 0], [0, -1, 0])
    np.testing.assert_allclose(frame[:, 2], [0, 0, 1])
