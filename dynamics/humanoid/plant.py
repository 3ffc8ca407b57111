"""Give a motion without a root path (joint angles only) the root path its feet imply."""
from __future__ import annotations

import numpy as np

from mocap.rotations.angles import JointAngles
from mocap.body.angles import motion_from_angles
from mocap.body.anthropometry import foot_points
from mocap.body.planting import planted_translation
from mocap.clean.filtering import butterworth_lowpass
from mocap.errors import MocapError
from mocap.skeleton import Motion


def foot_contact_positions(motion: Motion) -> np.ndarray:
    """World positions of both feet's contact points (heel, toe, their sides).

    Returns
    -------
    ndarray, shape (frames, points, 3), metres, Y up.
    """
    world_r, world_p = motion.forward_kinematics()
    positions = []
    for foot in ("l_foot", "r_foot"):
        index = motion.skeleton.index(foot)
        local = np.array(list(foot_points(motion.skeleton.end_sites[index]).values()))
        positions.append(world_p[:, index, None] + np.einsum("fij,pj->fpi", world_r[:, index], local))
    return np.concatenate(positions, axis=1)


def plant_feet(motion: Motion, smooth_hz: float | None = 4.0) -> Motion:
    """The motion with a root translation that keeps the supporting foot point still.

    The joint rotations are kept; the root path is replaced by
    :func:`mocap.body.planting.planted_translation` of the feet's contact points, so the
    lowest point is on the floor (y = 0) and does not slide while it carries the body.
    Where the supporting point changes (heel to toe, one foot to the other) that path
    has kinks, which inverse dynamics would read as impacts; ``smooth_hz`` low-passes
    it (zero-lag Butterworth, 4th order) at the cost of a few millimetres of slide.

    Parameters
    ----------
    motion : Motion
        With ``l_foot`` and ``r_foot`` segments (the 15-segment body).
    smooth_hz : float or None
        Cutoff of the path's low-pass in Hz; None keeps the kinks.

    Returns
    -------
    Motion
    """
    still_root = Motion(motion.skeleton, np.zeros_like(motion.root_translation),
                        motion.rotations, motion.rate, dict(motion.metadata))
    translation = planted_translation(foot_contact_positions(still_root), up=1)
    if smooth_hz is not None and motion.frames > 15 and smooth_hz < motion.rate / 2:
        translation = butterworth_lowpass(translation, smooth_hz, motion.rate, order=4)
    return Motion(motion.skeleton, translation, motion.rotations, motion.rate,
                  dict(motion.metadata, root="planted feet"))


def motion_from_cycle(angles, skeleton=None, cycles: int = 1, up: str = "z") -> Motion:
    """A walking :class:`Motion` from one cycle of joint angles (a synthesised cycle).

    The cycle is closed first (its end made to continue smoothly into its start by a
    linear ramp of the small mismatch), repeated ``cycles + 2`` times, the root path
    planted on the feet and smoothed (:func:`plant_feet`), and the middle ``cycles``
    kept, so neither the seams nor the ends carry artificial accelerations.

    Parameters
    ----------
    angles : mocap.rotations.angles.JointAngles
        One cycle: ``values`` (samples, segments, 3) degrees, ``times`` seconds.
    skeleton : mocap.skeleton.Skeleton, optional
        The body to put the angles on (default :func:`mocap.body.segments.default_skeleton`).
    cycles : int
        Cycles in the result.
    up : {"z", "y"}
        Vertical axis of the lab the angles were measured in.

    Returns
    -------
    Motion
        ``cycles × samples`` frames, feet planted on the floor y = 0.
    """
    cycle = np.asarray(angles.values, dtype=float)
    if cycle.shape[0] < 3:
        raise MocapError("a cycle needs at least 3 samples (samples= of the synthesised cycle)")
    mismatch = cycle[0] - (2 * cycle[-1] - cycle[-2])          # where the next sample should be
    cycle = cycle + np.linspace(0.0, 1.0, len(cycle))[:, None, None] * mismatch
    samples, repeats = len(cycle), cycles + 2
    values = np.concatenate([cycle] * repeats, axis=0)
    step = float(angles.times[1] - angles.times[0])
    tiled = JointAngles(times=np.arange(values.shape[0]) * step, values=values,
                        segments=list(angles.segments), sequence=angles.sequence,
                        parents=list(angles.parents))
    motion = plant_feet(motion_from_angles(tiled, skeleton, up=up))
    return motion.slice(samples, samples * (cycles + 1))
