"""The ONE motion ↔ joint angles: :func:`motion_joint_angles` and :func:`motion_from_angles`.

Joint angles follow ``docs/formats/angles-csv.md``: each joint's rotation relative to
its parent, expressed in a Z-up lab's axes (X anterior, Y left), Euler angles in degrees in a
scipy sequence, unwrapped over time — the convention of angles computed from markers, so a
BVH or ASF/AMC motion gives angles comparable with a marker trial's. Every writer of motion
angles (angle CSV, OpenSim ``.mot``) and every corpus reader goes through here.
"""
from __future__ import annotations

import numpy as np

from mocap.rotations.angles import JointAngles, matrices_to_angles, unwrap_angles
from mocap.body.retarget import motion_to_lab, reduce_to_segments, up_matrix
from mocap.body.segments import default_skeleton
from mocap.errors import MocapError
from mocap.skeleton import Motion, Skeleton, frame_rate


def motion_joint_angles(motion: Motion, sequence: str = "ZXY", body: bool = True):
    """Joint angles of a motion as ``mocap.rotations.angles.JointAngles`` (``docs/formats/angles-csv.md`` convention).

    Rotations are expressed in a Z-up lab (X anterior, Y left), like angles computed from
    markers, so BVH and ASF/AMC trials can join a marker corpus (``mocap decompose``).

    Parameters
    ----------
    motion : Motion
    sequence : str
        scipy Euler sequence.
    body : bool
        Map the skeleton onto the 15 body segments first (``reduce_to_segments``).
    """
    if body:
        motion = reduce_to_segments(motion)
    rotations, _ = motion_to_lab(motion)
    values = unwrap_angles(matrices_to_angles(rotations, sequence), sequence)
    return JointAngles(motion.times, values, list(motion.names), sequence,
                       list(motion.skeleton.parents))


def motion_from_angles(angles, skeleton: Skeleton | None = None,
                       root_translation: np.ndarray | None = None, up: str = "z") -> Motion:
    """A :class:`Motion` from joint angles (``mocap.rotations.angles.JointAngles``) on a skeleton.

    Parameters
    ----------
    angles : JointAngles
        ``values`` (frames, segments, 3) degrees in ``sequence`` (scipy convention), one
        rotation per segment relative to its parent expressed in the lab's segment frames
        (the root's relative to the lab); ``segments`` names; ``times`` seconds.
    skeleton : Skeleton, optional
        Y-up skeleton whose segment names include ``angles.segments``; default
        :func:`default_skeleton`. Segments of the skeleton without angles keep the rest pose.
    root_translation : ndarray, shape (frames, 3), metres, optional
        The root's origin in the lab (``up`` convention). Default: the root stays above the
        origin at the height where the rest pose's lowest point touches the floor.
    up : {"z", "y"}
        The vertical axis of the lab the angles were measured in.

    Returns
    -------
    Motion
    """
    skeleton = default_skeleton() if skeleton is None else skeleton
    turn = up_matrix(up)
    values = np.asarray(angles.values, dtype=float)
    frames = values.shape[0]
    times = np.asarray(getattr(angles, "times", np.arange(frames) / 100.0), float)
    rate = frame_rate(float(np.median(np.diff(times)))) if times.size > 1 else 100.0
    rotations = np.broadcast_to(np.eye(3), (frames, skeleton.count, 3, 3)).copy()
    from scipy.spatial.transform import Rotation   # deferred: 0.4 s to import
    for k, name in enumerate(angles.segments):
        if name not in skeleton.names:
            raise MocapError(f"the joint angles have segment {name!r} that the skeleton "
                             f"lacks (it has {', '.join(skeleton.names)})")
        column = np.nan_to_num(values[:, k])
        lab = Rotation.from_euler(angles.sequence, column, degrees=True).as_matrix()
        rotations[:, skeleton.index(name)] = turn @ lab @ turn.T
    if root_translation is None:
        still = Motion.still(skeleton, 1, rate)
        lowest = still.all_points()[0, :, 1].min()
        translation = np.tile([0.0, -lowest, 0.0], (frames, 1))
    else:
        translation = np.asarray(root_translation, float).reshape(frames, 3) @ turn.T \
            - skeleton.offsets[0]
    return Motion(skeleton, translation, rotations, rate,
                  {"source": getattr(angles, "path", None), "sequence": angles.sequence})
