"""A rig's soles: where the floor contact of a skeleton whose feet end at joints lies.

A BVH or ASF rig's ankle and toe are points on the foot's bones (joint centres), not on
the sole. :func:`joint_soles` puts each foot's contact points below its lowest rig point
by what the trial's still feet stand above the floor, within what anatomy and a shoe
allow (:data:`SOLE_BELOW_LOWEST`); :func:`rig_soles` does it for the feet a body's rig
ends at. The check (:mod:`dynamics.humanoid.check`) and the physics replay
(:mod:`dynamics.humanoid.tracking`) stand on these; :func:`dynamics.humanoid.contact.calibrate_contacts`
then fits them to the stances.
"""
from __future__ import annotations

import numpy as np

from mocap.body.anthropometry import foot_points, leg_length
from mocap.skeleton import Motion

from dynamics.humanoid.model import Humanoid

#: How far a rig's sole may lie below the lowest of its foot's points (ankle, toe), in
#: leg lengths, by what that point is: the most a foot's anatomy and a shoe put between
#: them, so that a trial whose feet stand further above the floor than this floats. A toe
#: joint (the metatarsophalangeal joint centre) stands about 2-2.5 cm above the sole
#: barefoot, and a running shoe's forefoot adds up to 4.5 cm: 7 cm, 0.085 of a 0.82 m
#: leg (Bandai's stand 4.0-5.8 cm above the floor in stance); a toe-tip end site lies
#: on the toe, 0-2 cm above the sole, and the shoe's 3 cm at the toe: 0.06; an ankle
#: joint centre the lateral malleolus height 0.039 of the stature (Winter 2009,
#: Fig. 4.1) over the hip-to-ankle 0.491, 6.8 cm, and a shoe's heel 3 cm: 0.115.
#: Held out: the shoe's forefoot went from 3.5 cm (0.07) to 4.5 cm after one take of
#: bandai2's design half (styles active, exhausted, masculine, youthful: 14 of 72 takes
#: stand above 0.07, the highest 0.0735); on the report half (elderly, feminine,
#: normal), not looked at for it, 0 of 54 stand above 0.085 (9 above 0.07; the highest
#: 0.0733). ``python benchmarks/check_validation.py`` prints both.
SOLE_BELOW_LOWEST = {"toe joint": 0.085, "end site": 0.06, "ankle": 0.115}
#: The toes (phalanges) beyond a rig's toe joint, in leg lengths: 0.27 of the foot length
#: (the metatarsal heads at 0.73 of it from the heel), the foot 0.152 of the stature
#: (Winter 2009), i.e. 0.041 of the stature over the hip-to-ankle 0.491.
TOE_LENGTH = 0.084


def _flat_foot_normal(rotations: np.ndarray, origins: np.ndarray, toe: np.ndarray,
                      within: float = 0.01) -> np.ndarray:
    """The floor's normal in a foot's frame while the foot is flat (unit, shape (3,)).

    Flat: ankle and toe point both at their lowest together — the frames whose summed
    heights above their minima are within ``within`` (m) of the least sum. No speed test,
    so a runner's short stances count as well as a walker's; heights are only compared
    with themselves, so the floor's level plays no part.
    """
    ankle = origins[:, 1]
    tip = origins[:, 1] + rotations[:, 1, :] @ toe
    raised = (ankle - ankle.min()) + (tip - tip.min())
    seen = np.swapaxes(rotations, 1, 2)[:, :, 1]                       # Rᵀ e_y, (F, 3)
    normal = np.median(seen[raised <= raised.min() + within], axis=0)
    return normal / np.linalg.norm(normal)


def joint_soles(humanoid: Humanoid, feet: dict[str, str], world_r: np.ndarray,
                world_p: np.ndarray, rate: float, floor: float = 0.0,
                still_speed: float = 0.2) -> tuple[np.ndarray, dict, dict]:
    """Contact points under the feet of a rig whose foot ends at a joint (module docstring).

    A skeleton's ankle and toe are points of the rig on the foot's bones: joint centres
    inside the foot (a captured skeleton: Bandai's toe joint 42 mm above its floor), or
    points on the sole itself (game and tool rigs whose ankle and toe joints touch the
    floor). Which one is found from the trial, with no constant of any dataset: where the
    foot stands still, its lowest rig point stands ``h`` above ``floor`` (median over
    those frames); the sole lies ``h`` below that point when ``0 ≤ h ≤``
    :data:`SOLE_BELOW_LOWEST` (what a foot's anatomy and a shoe can put between them), and
    at the point itself otherwise: a trial standing higher floats, one standing lower
    penetrates, by what the rig's own points show (nothing is invented below them). The
    sole's normal in the foot frame is the floor's normal seen from the foot when it is
    flat (:func:`_flat_foot_normal`; Bandai's foot X runs along the bone, pitched 40°
    down); the contact points are laid out across and along it
    (:func:`mocap.body.anthropometry.foot_points` with that ``up``).
    :func:`calibrate_contacts` then fits the sole's height to the stances, never above
    the rig's lowest point (``sole_lowest``).

    Parameters
    ----------
    humanoid : Humanoid
    feet : dict
        The feet to lay out (``"l_foot"``, ``"r_foot"``) → what their toe point is,
        ``"toe joint"`` (the toes, :data:`TOE_LENGTH`, are added beyond it) or
        ``"end site"`` (the rig's toe tip); the others keep their points.
    world_r, world_p : segment poses, (frames, segments, 3, 3) and (frames, segments, 3)
    rate : float, Hz
    floor : float, m
        The floor's height (Y up).
    still_speed : float, m/s
        A foot whose rig points are all slower stands still.

    Returns
    -------
    points : ndarray, shape (points, 3)
        Contact points in their foot's frame (``humanoid.contact_points`` order).
    normals : dict
        Foot segment index → sole normal in its frame (the ``sole_up`` of
        :func:`calibrate_contacts`).
    lowest : dict
        Foot segment index → the sole's offset ``d`` (``n·x = −d``) through the rig's
        lowest point: the least the sole lies below the foot's origin.
    """
    skeleton = humanoid.skeleton
    segments = np.asarray(humanoid.contact_segments)
    points = np.array(humanoid.contact_points, dtype=float)
    normals, lowest = {}, {}
    leg = leg_length(skeleton)
    for name, kind in feet.items():
        foot = skeleton.index(name)
        mine = np.flatnonzero(segments == foot)
        toe = skeleton.end_sites[foot]
        normal = _flat_foot_normal(world_r[:, foot], world_p[:, foot], toe)
        h = still_foot_height(world_r[:, foot], world_p[:, foot], toe, rate, still_speed) \
            - floor
        low = min(0.0, float(toe @ normal))
        bound = SOLE_BELOW_LOWEST[kind if toe @ normal < 0.0 else "ankle"] * leg
        level = low - (h if 0.0 <= h <= bound else 0.0)
        laid = foot_points(toe, up=normal)
        if kind == "toe joint":
            # The toes beyond the toe joint (phalanges), which push off after the heel
            # rises; the ball (metatarsal heads) stays under the joint.
            ahead = toe - (toe @ normal) * normal
            tip = toe + TOE_LENGTH * leg * ahead / max(np.linalg.norm(ahead), 1e-9)
            longer = foot_points(tip, up=normal)
            ball = longer["heel"] + 0.8 * (tip - longer["heel"])
            laid = {k: v + (toe - ball if k.startswith("toe_") else 0.0)
                    for k, v in longer.items()}
        laid = np.array(list(laid.values()))
        points[mine] = laid - np.outer(laid @ normal - level, normal)
        normals[int(foot)] = normal
        lowest[int(foot)] = -low
    return points, normals, lowest


def still_foot_height(rotations: np.ndarray, origins: np.ndarray, toe: np.ndarray,
                      rate: float, still_speed: float = 0.2) -> float:
    """How high (m, Y up) a rig's foot stands when still: the median over the frames
    where its ankle (the foot's origin) and toe point are both slower than
    ``still_speed`` of the lower of the two. A foot that never stands still (it slides
    throughout) stands where it is lowest: the frames whose ankle and toe are both
    within 1 cm of their least heights; NaN for no frames.

    Parameters
    ----------
    rotations, origins : ndarray, shapes (frames, 3, 3) and (frames, 3)
        The foot segment's world poses.
    toe : ndarray, shape (3,)
        The toe point in the foot frame (its end site).
    rate : float, Hz
    """
    rig = np.stack([origins, origins + rotations @ toe], axis=1)           # (F, 2, 3)
    speed = np.linalg.norm(np.gradient(rig, 1.0 / rate, axis=0), axis=2) \
        if rig.shape[0] > 1 else np.zeros(rig.shape[:2])
    still = (speed < still_speed).all(axis=1)
    if not still.any():
        still = (rig[:, :, 1] <= rig[:, :, 1].min(axis=0) + 0.01).all(axis=1)
    return float(np.median(rig[still, :, 1].min(axis=1))) if still.any() else np.nan


def rig_soles(body: Motion, humanoid: Humanoid, floor: float = 0.0
              ) -> tuple[np.ndarray, dict, dict]:
    """The contact points of a body: the humanoid's, with :func:`joint_soles` under the
    feet its rig ends at joints (``body.metadata["feet_at_joints"]``, set by
    :func:`mocap.body.retarget.reduce_to_segments`). The check and the physics replay
    both stand on these.

    Parameters
    ----------
    body : Motion
        The reduced body motion the soles are seen in.
    humanoid : Humanoid
    floor : float, m
        The floor's height in the motion (Y up).

    Returns
    -------
    points : ndarray, shape (points, 3)
        Contact points in their foot's frame (``humanoid.contact_points`` order).
    normals : dict
        Foot segment index → sole normal in its frame (empty without rig feet).
    lowest : dict
        Foot segment index → the sole offset through the rig's lowest point
        (:func:`joint_soles`; empty without rig feet).
    """
    feet = {n: kind for n, kind in body.metadata.get("feet_at_joints", {}).items()
            if n in body.skeleton.names}
    if not feet:
        return humanoid.contact_points, {}, {}
    return joint_soles(humanoid, feet, *body.forward_kinematics(), body.rate, floor)
