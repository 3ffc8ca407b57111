"""Kinematics of a motion on the humanoid's configuration manifold, and its centre of mass.

q, v, a for Pinocchio (the check's first step, ``docs/check.md``): quaternions made sign-continuous, optionally
low-passed (zero-lag Butterworth), smoothed and differentiated with a Savitzky–Golay filter
(:mod:`mocap.clean.filtering`, numpy only; exact for constant, linear and quadratic
motion, so a still pose and a free fall are known answers); angular velocity and
acceleration in each joint's frame are ``2 Im(q* ⊗ q̇)`` and ``2 Im(q* ⊗ q̈)``; the root's
linear velocity is in its own frame (Pinocchio's free-flyer convention). Tests compare
them with ``pin.difference`` of neighbouring configurations.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocap.errors import MocapError
from mocap.clean.filtering import butterworth_lowpass, savgol
from mocap.rotations.quaternions import matrices_to_quaternions, quaternions_to_matrices
from mocap.skeleton import Motion

from dynamics.humanoid.model import Humanoid


def _quat_conj_product_vector(q: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Vector part of conj(q) ⊗ d for quaternions (…, 4) stored x, y, z, w:
    ``w·d_v − d_w·q_v − q_v × d_v`` (written out: np.cross is slow on small last axes)."""
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    a, b, c, e = d[..., 0], d[..., 1], d[..., 2], d[..., 3]
    return np.stack([w * a - e * x - (y * c - z * b),
                     w * b - e * y - (z * a - x * c),
                     w * c - e * z - (x * b - y * a)], axis=-1)


def _continuous_quaternions(rotations: np.ndarray) -> np.ndarray:
    """Quaternions (frames, joints, 4) of rotation matrices, sign-continuous over frames."""
    frames = rotations.shape[0]
    quats = matrices_to_quaternions(rotations)
    if frames > 1:
        dots = np.einsum("fjk,fjk->fj", quats[1:], quats[:-1])
        flips = np.cumprod(np.where(dots < 0, -1.0, 1.0), axis=0)
        quats[1:] *= flips[..., None]
    return quats


def _window(frames: int, rate: float, seconds: float) -> tuple[int, int]:
    """Savitzky–Golay window length (odd, ≤ frames) and polynomial order."""
    if frames < 3:
        raise MocapError(f"inverse dynamics needs at least 3 frames, the motion has {frames}")
    length = int(round(seconds * rate)) | 1
    length = max(3, min(length, frames if frames % 2 else frames - 1))
    return length, (2 if length < 5 else 3)


@dataclass
class Kinematics:
    """Configurations, velocities and accelerations of a motion, frame by frame.

    Attributes
    ----------
    q : ndarray, shape (frames, nq)
    v, a : ndarray, shape (frames, nv)
    rotations : ndarray, shape (frames, segments, 3, 3)
        Smoothed joint rotations (relative to the parent), as used in ``q``.
    root : ndarray, shape (frames, 3), metres
        Smoothed world position of the root.
    """

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    rotations: np.ndarray
    root: np.ndarray


def motion_kinematics(motion: Motion, smoothing: float = 0.1,
                      lowpass: float | None = None) -> Kinematics:
    """q, v, a of a 15-segment motion for the Pinocchio model (vectorised over frames).

    Parameters
    ----------
    motion : Motion
        On the body skeleton (segment order = model joint order).
    smoothing : float, seconds
        Savitzky–Golay window (polynomial order 3; 0 gives central differences).
    lowpass : float, Hz, optional
        First low-pass the (sign-continuous) quaternions and the root's path with
        :func:`mocap.clean.filtering.butterworth_lowpass` (6 Hz is customary for walking inverse dynamics).

    Returns
    -------
    Kinematics
    """
    dt = 1.0 / motion.rate
    window, order = _window(motion.frames, motion.rate, smoothing)
    quats = _continuous_quaternions(motion.rotations)                   # (F, J, 4)
    root = motion.skeleton.offsets[0] + motion.root_translation         # (F, 3)
    if lowpass:
        # zero-lag 2nd-order Butterworth (4th overall, the gait-analysis filter), the ends
        # padded so that they keep their velocity and acceleration: a free fall still
        # falls at g in its first and last frames
        quats = butterworth_lowpass(quats, lowpass, motion.rate, ends="fitted")
        root = butterworth_lowpass(root, lowpass, motion.rate, ends="fitted")

    def smooth(x: np.ndarray, deriv: int) -> np.ndarray:
        return savgol(x, window, order, deriv=deriv, delta=dt)

    frames, joints = quats.shape[:2]
    stacked = np.concatenate([quats.reshape(frames, -1), root], axis=1)
    q0, q1, q2 = (smooth(stacked, d) for d in (0, 1, 2))
    (p0, q0), (p1, q1), (p2, q2) = ((x[:, -3:], x[:, :-3].reshape(frames, joints, 4))
                                    for x in (q0, q1, q2))
    norm2 = np.einsum("fjk,fjk->fj", q0, q0)[..., None]
    omega = 2.0 * _quat_conj_product_vector(q0, q1) / norm2             # body frame
    alpha = 2.0 * _quat_conj_product_vector(q0, q2) / norm2
    q0 = q0 / np.sqrt(norm2)
    rotations = quaternions_to_matrices(q0)                                # (F, J, 3, 3)
    root_r = rotations[:, 0]
    v_lin = np.einsum("fji,fj->fi", root_r, p1)                         # Rᵀ ṗ
    a_lin = np.einsum("fji,fj->fi", root_r, p2) - np.cross(omega[:, 0], v_lin)
    frames = motion.frames
    q = np.concatenate([p0, q0.reshape(frames, -1)], axis=1)
    v = np.concatenate([v_lin, omega.reshape(frames, -1)], axis=1)
    a = np.concatenate([a_lin, alpha.reshape(frames, -1)], axis=1)
    return Kinematics(q, v, a, rotations, p0)


def configurations(motion: Motion) -> np.ndarray:
    """Pinocchio configurations of every frame, unsmoothed, shape (frames, nq)."""
    quats = _continuous_quaternions(motion.rotations)
    root = motion.skeleton.offsets[0] + motion.root_translation
    return np.concatenate([root, quats.reshape(motion.frames, -1)], axis=1)


def centre_of_mass(humanoid: Humanoid, world_r: np.ndarray, world_p: np.ndarray
                    ) -> np.ndarray:
    """Whole-body centre of mass (frames, 3)."""
    parts = [(i, s) for i, s in enumerate(humanoid.inertias)]
    parts += [(host, s) for _, host, s in humanoid.lumped]
    owners = [i for i, _ in parts]
    masses = np.array([s.mass for _, s in parts])
    coms = np.stack([s.com for _, s in parts])
    points = world_p[:, owners] + np.einsum("fsij,sj->fsi", world_r[:, owners], coms)
    return np.einsum("s,fsi->fi", masses, points) / masses.sum()
