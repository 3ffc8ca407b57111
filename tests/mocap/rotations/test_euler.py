"""Euler branches (issue 12): the principal range by default, whole turns
unwrapped within runs of valid frames, the continuous branch only on request."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocap.rotations.angles import (SEQUENCES, GimbalLockWarning, angles_to_matrices, is_proper_euler,
                          joint_angles, unwrap_columns, unwrap_turns)
from mocap.markersets import markerset_from_dict
from mocap.trial import Trial

FRAMES = 200


def one_segment_trial(rotations: np.ndarray) -> tuple[Trial, object]:
    e1, e2 = rotations[:, :, 0], rotations[:, :, 1]
    origin = 0.001 * np.arange(len(rotations))[:, None] * np.ones(3)
    points = np.stack([origin, origin + 0.1 * e1, origin + 0.1 * e2], axis=1)
    markerset = markerset_from_dict({"segment": [{"name": "arm", "markers": ["O", "A", "P"]}]})
    return Trial(["O", "A", "P"], points, 100.0), markerset


@pytest.mark.parametrize("sequence", SEQUENCES)
def test_known_rotation_comes_out_on_the_principal_branch(sequence):
    """A motion generated on the non-principal branch (the middle angle outside
    the principal range), first and third angles sweeping past ±180°: the angles
    are the principal triple of the same rotation, continuous by whole turns."""
    t = np.linspace(0.0, 1.0, FRAMES)
    proper = is_proper_euler(sequence)
    # the other branch: proper Euler middle in (-180, 0), Tait-Bryan |middle| > 90
    middle = (-60 - 30 * np.sin(2 * np.pi * t)) if proper else (130 + 20 * np.sin(2 * np.pi * t))
    truth = np.stack([-150 + 400 * t, middle, 170 - 380 * t ** 2], axis=1)
    rotations = angles_to_matrices(truth, sequence)
    trial, markerset = one_segment_trial(rotations)
    with warnings.catch_warnings():
        warnings.simplefilter("error", GimbalLockWarning)   # 40° or more from the lock
        angles = joint_angles(trial, markerset, sequence).values[:, 0]
    # the principal triple: (a + 180, 180 - b, c + 180) Tait-Bryan, (a + 180, -b, c + 180) proper
    expected_middle = -middle if proper else 180 - middle
    np.testing.assert_allclose(angles[:, 1], expected_middle, atol=1e-6)
    if proper:
        assert (angles[:, 1] >= 0).all() and (angles[:, 1] <= 180).all()
    else:
        assert (np.abs(angles[:, 1]) <= 90).all()
    # the first and third differ from the truth by 180° plus a constant number of turns
    for k in (0, 2):
        offset = angles[:, k] - truth[:, k] - 180.0
        np.testing.assert_allclose(offset - offset[0], 0.0, atol=1e-6)
        assert abs(offset[0] / 360.0 - round(offset[0] / 360.0)) < 1e-9
        assert np.abs(np.diff(angles[:, k])).max() < 30      # continuous, no 360° jump
    np.testing.assert_allclose(angles_to_matrices(angles, sequence), rotations, atol=1e-10)


@pytest.mark.parametrize("sequence", ["ZYZ", "xzx", "ZXY", "yxz"])
def test_after_passing_near_gimbal_lock_the_branch_is_principal_again(sequence):
    """Issue 12: ZYZ came out with a negative middle angle after passing within a
    degree of gimbal lock.  The principal default stays in range; the continuous
    branch is still there on request."""
    proper = is_proper_euler(sequence)
    limit = 0.0 if proper else 90.0
    inside = 1.0 if proper else -1.0
    t = np.linspace(0.0, 1.0, FRAMES)
    # from 30° inside the range to 0.6° past the limit and back inside
    middle = limit + inside * (30 - 30.6 * np.sin(np.pi * t))
    truth = np.stack([20 + 40 * t, middle, -10 + 30 * t], axis=1)
    rotations = angles_to_matrices(truth, sequence)
    trial, markerset = one_segment_trial(rotations)
    with pytest.warns(GimbalLockWarning):
        principal = joint_angles(trial, markerset, sequence).values[:, 0]
    with pytest.warns(GimbalLockWarning):
        continuous = joint_angles(trial, markerset, sequence, branch="continuous").values[:, 0]
    if proper:
        assert (principal[:, 1] >= 0).all()
    else:
        assert (np.abs(principal[:, 1]) <= 90).all()
    np.testing.assert_allclose(angles_to_matrices(principal, sequence), rotations, atol=1e-9)
    np.testing.assert_allclose(continuous, truth, atol=1e-6)       # the branch followed
    # once back inside the range, the principal triple is the truth again, up to
    # whole turns of the first and third angles (ill-defined at the lock)
    back = (np.abs(middle - limit) > 5) & (t > 0.5)
    difference = (principal[back] - truth[back] + 180.0) % 360.0 - 180.0
    np.testing.assert_allclose(difference, 0.0, atol=1e-6)
    assert np.abs(np.diff(principal[back][:, [0, 2]], axis=0)).max() < 30


def test_whole_turns_unwrapped_across_a_gap_without_a_branch_change():
    """360° jumps are removed between consecutive valid frames (a gap skipped);
    the middle angle is never touched, so no 180° set can appear after a gap."""
    first = np.concatenate([np.linspace(100, 260, 17), [np.nan] * 5, np.linspace(280, 400, 10)])
    wrapped = (first + 180) % 360 - 180
    middle = np.full_like(first, 80.0)
    values = np.stack([wrapped, middle, -wrapped], axis=1)[:, None, :]
    out = unwrap_turns(values)[:, 0]
    np.testing.assert_allclose(out[:, 0], first, atol=1e-9)
    np.testing.assert_allclose(out[:, 2], -first, atol=1e-9)
    np.testing.assert_array_equal(out[:, 1], values[:, 0, 1])


def test_unwrapping_a_column_slice_with_gaps_keeps_its_writes():
    """unwrap_columns on a non-contiguous slice (the first and third angles of
    (frames, segments, 3)) must unwrap, not silently return the input."""
    first = np.concatenate([np.linspace(100, 260, 17), [np.nan] * 5, np.linspace(280, 400, 10)])
    wrapped = (first + 180) % 360 - 180
    values = np.stack([wrapped, np.zeros_like(first), wrapped], axis=1)[:, None, :]
    sliced = values[..., [0, 2]]
    assert not sliced.flags["C_CONTIGUOUS"]
    np.testing.assert_allclose(unwrap_columns(sliced)[:, 0, 0], first, atol=1e-9)


def test_unknown_branch_is_refused():
    trial, markerset = one_segment_trial(Rotation.random(3, random_state=0).as_matrix())
    with pytest.raises(ValueError, match="branch"):
        joint_angles(trial, markerset, "ZXY", branch="nearest")
