"""mocap.rotations.quaternions against scipy's Rotation (the reference it replaces on the check path)
and against rotations worked out by hand."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocap.errors import MocapError
from mocap.rotations.quaternions import matrices_to_quaternions, quaternions_to_matrices


def _rotations(count: int, seed: int) -> np.ndarray:
    return Rotation.random(count, random_state=seed).as_matrix()


def test_matrices_to_quaternions_equals_scipy_to_the_bit():
    rng = np.random.default_rng(3)
    matrices = _rotations(20000, 1)
    # some a little off orthogonal (scipy keeps them), some far off (scipy's SVD fix)
    matrices[:500] += rng.normal(scale=1e-14, size=(500, 3, 3))
    matrices[500:1000] += rng.normal(scale=1e-4, size=(500, 3, 3))
    # half-turns and the identity: each of Markley's four branches wins somewhere
    special = np.array([np.eye(3), np.diag([1.0, -1, -1]), np.diag([-1.0, 1, -1]),
                        np.diag([-1.0, -1, 1])])
    matrices = np.concatenate([matrices, special])
    expected = Rotation.from_matrix(matrices).as_quat()
    assert np.array_equal(matrices_to_quaternions(matrices), expected)
    # any leading shape, and one matrix alone
    assert np.array_equal(matrices_to_quaternions(matrices[:1000].reshape(50, 20, 3, 3)),
                          expected[:1000].reshape(50, 20, 4))
    assert np.array_equal(matrices_to_quaternions(matrices[7]), expected[7])


def test_quaternions_to_matrices_equals_scipy_to_the_bit():
    quats = np.random.default_rng(4).normal(size=(20000, 4))      # not unit: normalised
    expected = Rotation.from_quat(quats).as_matrix()
    assert np.array_equal(quaternions_to_matrices(quats), expected)
    assert np.array_equal(quaternions_to_matrices(quats.reshape(100, 200, 4)),
                          expected.reshape(100, 200, 3, 3))


def test_known_rotations_by_hand():
    # a quarter turn about z: x -> y; quaternion (0, 0, sin 45°, cos 45°)
    quarter = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    half = np.sqrt(0.5)
    assert np.allclose(matrices_to_quaternions(quarter), [0, 0, half, half], atol=1e-15)
    assert np.allclose(quaternions_to_matrices(np.array([0, 0, 2.0, 2.0])), quarter,
                       atol=1e-15)
    # a half turn about x (trace -1: the x branch): (1, 0, 0, 0)
    assert np.array_equal(matrices_to_quaternions(np.diag([1.0, -1, -1])), [1.0, 0, 0, 0])
    # 120° about (1, 1, 1)/√3 cycles the axes: x -> y -> z; quaternion (½, ½, ½, ½)
    cycle = np.array([[0.0, 0, 1], [1, 0, 0], [0, 1, 0]])
    assert np.allclose(matrices_to_quaternions(cycle), [0.5] * 4, atol=1e-15)
    assert np.allclose(quaternions_to_matrices(np.full(4, 0.5)), cycle, atol=1e-15)


def test_mirrors_and_zero_quaternions_are_refused():
    with pytest.raises(MocapError, match="determinant"):
        matrices_to_quaternions(np.diag([1.0, 1, -1]))
    with pytest.raises(MocapError, match="zero length"):
        quaternions_to_matrices(np.zeros((2, 4)))
