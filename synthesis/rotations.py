"""Wrap-free, heading-free features of skeleton motions, and back to rotations and a root path.

A skeleton trial (BVH, ASF/AMC; :class:`mocap.skeleton.Motion`, Y up) becomes, per frame:

* **Heading.** The *body root* is the first joint below the file's root where the figure
  branches (``Hips`` below a static ``joint_Root``; the root itself in most files). Its world
  rotation splits into a rotation about the vertical axis — the heading ``ψ``, the twist of
  the swing–twist decomposition — and the rest, the *tilt* ``T = R_y(ψ)ᵀ R``. The root's
  features use the tilt, so a trial walking north and one walking south look alike.
* **Root motion in the heading frame**: forward and sideways velocity of the body root
  (m/s, the horizontal velocity rotated by ``−ψ``), the turning rate ``dψ/dt`` (degrees/s)
  and the height of the body root (m).
* **Joint rotations as rotation vectors about the corpus mean.** For every joint ``j`` the
  mean rotation ``M_j`` over all frames of the corpus (chordal L2 mean: the rotation nearest
  to the sum of the matrices), and the feature ``x = log(M_jᵀ R_j)`` (rotation vector,
  degrees). A rest pose near ±180° no longer wraps: a joint's rotations stay within a
  fraction of a turn of its mean, where the logarithm is smooth, so cycles and people can be
  averaged and interpolated linearly. The angle between two poses of a joint is then the
  geodesic ``|log(exp(−x̂) exp(x))|``, independent of any Euler sequence.

Synthesised features go back with :func:`features_to_rotations` and :func:`root_path`.

Euler-angle corpora (marker trials, angle CSVs read with a marker set) have no root-motion
features to carry the turning, so :func:`remove_mean_heading` takes away one rotation about
the lab vertical per trial — the trial's mean heading, by the same swing–twist split — and a
trial captured walking the other way through the lab gives the same angles.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.rotations.angles import JointAngles, angles_to_matrices, matrices_to_angles

#: Index of the vertical axis of :class:`mocap.skeleton.Motion` (Y up).
UP = 1
#: Index of the vertical axis of marker labs and of the angles computed in them (Z up).
LAB_UP = 2
#: Names of the root-motion features, in order.
ROOT_FEATURES = ("forward_m_s", "sideways_m_s", "turn_deg_s", "height_m")


def body_root(parents: list[int]) -> int:
    """The first joint from the root down where the skeleton branches (or its only leaf).

    Examples
    --------
    >>> body_root([-1, 0, 1, 1, 1])
    1
    >>> body_root([-1, 0, 0])
    0
    """
    index = 0
    while True:
        children = [i for i, p in enumerate(parents) if p == index]
        if len(children) != 1:
            return index
        index = children[0]


def feature_joints(parents: list[int]) -> list[int]:
    """Joints whose rotations are features: the body root and every joint below it."""
    start = body_root(parents)
    inside = {start}
    for i in range(start + 1, len(parents)):
        if parents[i] in inside:
            inside.add(i)
    return sorted(inside)


def heading_split(world: np.ndarray, up: int = UP) -> tuple[np.ndarray, np.ndarray]:
    """Heading (rotation about the vertical) and tilt of world rotations.

    The heading is the twist about the vertical of the swing–twist decomposition.

    Parameters
    ----------
    world : ndarray, shape (frames, 3, 3)
        Finite rotations.
    up : int
        Index of the vertical axis: :data:`UP` (skeletons, Y) or :data:`LAB_UP` (marker
        labs, Z).

    Returns
    -------
    heading : ndarray, shape (frames,), radians, unwrapped over frames
    tilt : ndarray, shape (frames, 3, 3)
        ``R_up(heading)ᵀ world``.
    """
    quat = Rotation.from_matrix(world).as_quat()                  # x, y, z, w
    heading = np.unwrap(2.0 * np.arctan2(quat[:, up], quat[:, 3]))
    tilt = np.einsum("fji,fjk->fik", yaw_matrices(heading, up), world)
    return heading, tilt


def yaw_matrices(heading: np.ndarray, up: int = UP) -> np.ndarray:
    """Rotations by ``heading`` (radians) about the vertical axis ``up``, shape (frames, 3, 3)."""
    return Rotation.from_rotvec(np.outer(heading, np.eye(3)[up])).as_matrix()


def hierarchy_known(angles: JointAngles) -> bool:
    """Whether the segments' parents are known: some segment has a parent (an angle CSV read
    without a marker set gives every segment ``-1``, and then a root cannot be told from a
    joint).

    Examples
    --------
    >>> hierarchy_known(JointAngles(np.zeros(1), np.zeros((1, 2, 3)), ["a", "b"], "ZXY", [-1, 0]))
    True
    >>> hierarchy_known(JointAngles(np.zeros(1), np.zeros((1, 2, 3)), ["a", "b"], "ZXY", [-1, -1]))
    False
    """
    return any(parent >= 0 for parent in angles.parents)


def mean_heading(world: np.ndarray, up: int = LAB_UP) -> float:
    """Circular mean of the heading (:func:`heading_split`) of world rotations, radians.

    Parameters
    ----------
    world : ndarray, shape (frames, 3, 3)
        NaN frames (missing markers) are left out.
    up : int
        Index of the vertical axis.

    Returns
    -------
    float
        In (−π, π]; 0 when no frame is finite.
    """
    world = np.asarray(world, dtype=float)
    finite = np.isfinite(world).all(axis=(1, 2))
    if not finite.any():
        return 0.0
    heading, _ = heading_split(world[finite], up)
    return float(np.arctan2(np.sin(heading).mean(), np.cos(heading).mean()))


def remove_mean_heading(angles: JointAngles, up: int = LAB_UP) -> JointAngles:
    """Euler angles of a trial turned about the lab vertical so its mean heading is zero.

    The heading ``ψ̄`` is the circular mean over the trial of the heading of the first root
    segment (parent −1, the pelvis); every root segment's rotation in the lab becomes
    ``R_up(ψ̄)ᵀ R``, the joints (relative to a parent) are unchanged. The swing and the
    heading's change within the trial (pelvic rotation, a turn) stay; a constant rotation of
    the whole trial about the vertical (walking the other way through the lab) leaves the
    angles unchanged.

    Parameters
    ----------
    angles : mocap.rotations.angles.JointAngles
        ``values`` (frames, segments, 3) degrees in the lab's axes; ``parents`` known
        (:func:`hierarchy_known`).
    up : int
        Index of the lab's vertical axis (:data:`LAB_UP`, Z).

    Returns
    -------
    mocap.rotations.angles.JointAngles
        A copy; the roots' angles are principal values (NaN where they were NaN).
    """
    roots = [s for s, parent in enumerate(angles.parents) if parent < 0]
    if not roots:
        return angles
    world = angles_to_matrices(np.asarray(angles.values, float)[:, roots], angles.sequence)
    turn = yaw_matrices(np.array([mean_heading(world[:, 0], up)]), up)[0]
    values = np.array(angles.values, dtype=float)
    values[:, roots] = matrices_to_angles(np.einsum("ji,fsjk->fsik", turn, world),
                                          angles.sequence)
    return JointAngles(times=angles.times, values=values, segments=list(angles.segments),
                       sequence=angles.sequence, parents=list(angles.parents), axes=angles.axes)


def chordal_mean(matrices: np.ndarray) -> np.ndarray:
    """The rotation nearest (Frobenius) to the mean of ``matrices`` (..., 3, 3) over axis 0."""
    total = np.asarray(matrices, dtype=float).sum(axis=0)
    u, _, vt = np.linalg.svd(total)
    flip = np.sign(np.linalg.det(u @ vt))
    return u @ np.diag([1.0, 1.0, flip]) @ vt


@dataclass
class SkeletonFrames:
    """Per-frame quantities of one skeleton trial that the features are made from.

    Attributes
    ----------
    joints : list of int
        Feature joints (:func:`feature_joints`), in skeleton order.
    rotations : ndarray, shape (frames, joints, 3, 3)
        Local rotation of each feature joint; the body root's is its tilt.
    heading : ndarray, shape (frames,), radians
    root : ndarray, shape (frames, 3), metres
        World position of the body root.
    positions : ndarray, shape (frames, segments, 3), metres
        World positions of every joint (for the leg signal).
    """

    joints: list
    rotations: np.ndarray
    heading: np.ndarray
    root: np.ndarray
    positions: np.ndarray


def skeleton_frames(motion) -> SkeletonFrames:
    """Split a :class:`mocap.skeleton.Motion` into heading, tilt, local rotations, root path."""
    parents = motion.skeleton.parents
    joints = feature_joints(parents)
    world_r, world_p = motion.forward_kinematics()
    heading, tilt = heading_split(world_r[:, joints[0]])
    rotations = motion.rotations[:, joints].copy()
    rotations[:, 0] = tilt
    return SkeletonFrames(joints, rotations, heading, world_p[:, joints[0]].copy(), world_p)


def rotation_features(rotations: np.ndarray, means: np.ndarray) -> np.ndarray:
    """Rotation vectors of ``M_jᵀ R_j`` in degrees.

    Parameters
    ----------
    rotations : ndarray, shape (frames, joints, 3, 3)
    means : ndarray, shape (joints, 3, 3)

    Returns
    -------
    ndarray, shape (frames, joints · 3), degrees
    """
    frames, joints = rotations.shape[:2]
    relative = np.einsum("jba,fjbc->fjac", means, rotations)
    vectors = Rotation.from_matrix(relative.reshape(-1, 3, 3)).as_rotvec(degrees=True)
    return vectors.reshape(frames, joints * 3)


def features_to_rotations(features: np.ndarray, means: np.ndarray) -> np.ndarray:
    """Inverse of :func:`rotation_features`: (frames, joints · 3) degrees → (frames, joints, 3, 3)."""
    frames = features.shape[0]
    joints = means.shape[0]
    local = Rotation.from_rotvec(np.asarray(features, float).reshape(-1, 3),
                                 degrees=True).as_matrix().reshape(frames, joints, 3, 3)
    return np.einsum("jab,fjbc->fjac", means, local)


def geodesic_deg(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Angle between the rotations of two feature arrays, degrees.

    Parameters
    ----------
    first, second : ndarray, shape (..., joints · 3), rotation-vector features (degrees)
        About the same mean rotations.

    Returns
    -------
    ndarray, shape (..., joints)
    """
    first = np.asarray(first, float)
    shape = first.shape[:-1] + (first.shape[-1] // 3,)
    a = Rotation.from_rotvec(first.reshape(-1, 3), degrees=True)
    b = Rotation.from_rotvec(np.asarray(second, float).reshape(-1, 3), degrees=True)
    return np.degrees((a.inv() * b).magnitude()).reshape(shape)


def root_features(times: np.ndarray, heading: np.ndarray, root: np.ndarray) -> np.ndarray:
    """Forward/sideways velocity in the heading frame, turning rate, height.

    Parameters
    ----------
    times : ndarray, shape (frames,), seconds
    heading : ndarray, shape (frames,), radians
    root : ndarray, shape (frames, 3), metres

    Returns
    -------
    ndarray, shape (frames, 4): m/s, m/s, degrees/s, m (:data:`ROOT_FEATURES`)
    """
    if times.size < 2:
        return np.column_stack([np.zeros((times.size, 3)), root[:, UP]])
    velocity = np.gradient(root, times, axis=0)
    local = np.einsum("fji,fj->fi", yaw_matrices(heading), velocity)
    horizontal = [axis for axis in range(3) if axis != UP]
    # Forward is the heading frame's Z (BVH convention: a figure faces +Z at rest), sideways X.
    turn = np.degrees(np.gradient(heading, times))
    return np.column_stack([local[:, horizontal[1]], local[:, horizontal[0]], turn,
                            root[:, UP]])


def root_path(times: np.ndarray, features: np.ndarray, heading0: float = 0.0,
              start: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Integrate root features back into a heading and a body-root path.

    Parameters
    ----------
    times : ndarray, shape (frames,), seconds
    features : ndarray, shape (frames, 4) (:data:`ROOT_FEATURES`)
    heading0 : float
        Heading at the first frame, radians.
    start : ndarray, shape (3,), optional
        Horizontal start of the path (its height comes from the features); default origin.

    Returns
    -------
    heading : ndarray, shape (frames,), radians
    root : ndarray, shape (frames, 3), metres
    """
    features = np.asarray(features, float)
    steps = np.diff(times)
    turn = np.radians(features[:, 2])
    heading = heading0 + np.concatenate([[0.0], np.cumsum(0.5 * (turn[1:] + turn[:-1]) * steps)])
    horizontal = [axis for axis in range(3) if axis != UP]
    local = np.zeros((features.shape[0], 3))
    local[:, horizontal[1]] = features[:, 0]
    local[:, horizontal[0]] = features[:, 1]
    velocity = np.einsum("fij,fj->fi", yaw_matrices(heading), local)
    root = np.zeros_like(velocity)
    root[1:] = np.cumsum(0.5 * (velocity[1:] + velocity[:-1]) * steps[:, None], axis=0)
    if start is not None:
        root += np.asarray(start, float)
    root[:, UP] = features[:, 3]
    return heading, root
