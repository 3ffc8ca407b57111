"""Motions on a skeleton built from other data: world segment frames, marker trials, and
foreign skeletons (BVH, ASF) moved onto the 15-segment body; and back to a Z-up lab.

* :func:`motion_from_frames` — world segment frames (``mocap.rotations.frames``) → :class:`Motion`;
* :func:`motion_from_trial` — a marker trial and its marker set → :class:`Motion`, with end
  sites from the markers and the soles calibrated on the floor;
* :func:`reduce_to_segments` — a BVH/ASF motion with any joint names → the body's segments;
* :func:`motion_to_lab` — joint rotations and root origin in a Z-up lab (the inverse turn).
"""
from __future__ import annotations

import numpy as np

from mocap.body.segments import (BODY_SEGMENTS, LOWER_BODY, body_parents, canonical_segment,
                                 describe_mapping, map_segments)
from mocap.errors import MocapError
from mocap.rotations.frames import segment_frames
from mocap.markersets import load_markerset
from mocap.skeleton import Motion, Skeleton

#: Rotation taking vectors of a Z-up lab (X anterior, Y left, Z up) into our Y-up frame
#: (X left, Y up, Z anterior): a cyclic permutation of the axes.
Z_UP_TO_Y_UP = np.array([[0.0, 1.0, 0.0],
                         [0.0, 0.0, 1.0],
                         [1.0, 0.0, 0.0]])




def up_matrix(up: str) -> np.ndarray:
    """The turn from a lab with vertical axis ``up`` ("z": X anterior, Y left, Z up; "y")
    into the motion's Y-up axes, shape (3, 3)."""
    if up.lower() == "z":
        return Z_UP_TO_Y_UP
    if up.lower() == "y":
        return np.eye(3)
    raise MocapError(f"unknown up axis {up!r}: use 'z' (lab Z up, X anterior) or 'y'")


def _fill_rotations(rotations: np.ndarray) -> np.ndarray:
    """Fill NaN frames of (frames, 3, 3) rotations by slerp between valid frames."""
    valid = np.isfinite(rotations).all(axis=(1, 2))
    if valid.all():
        return rotations
    if not valid.any():
        return np.broadcast_to(np.eye(3), rotations.shape).copy()
    times = np.flatnonzero(valid)
    if times.size == 1:
        return np.broadcast_to(rotations[times[0]], rotations.shape).copy()
    from scipy.spatial.transform import Rotation, Slerp   # deferred: 0.4 s to import
    slerp = Slerp(times, Rotation.from_matrix(rotations[valid]))
    query = np.clip(np.arange(rotations.shape[0]), times[0], times[-1])
    return slerp(query).as_matrix()


def _fill_linear(values: np.ndarray) -> np.ndarray:
    """Fill NaN rows of (frames, k) values by linear interpolation (edges held)."""
    result = values.copy()
    valid = np.isfinite(values).all(axis=1)
    if valid.all() or not valid.any():
        return np.nan_to_num(result)
    frames = np.arange(values.shape[0])
    for k in range(values.shape[1]):
        result[:, k] = np.interp(frames, frames[valid], values[valid, k])
    return result


def motion_from_frames(rotations: np.ndarray, origins: np.ndarray, names: list[str],
                       parents: list[int], rate: float, up: str = "z",
                       metadata: dict | None = None) -> Motion:
    """A :class:`Motion` from world segment frames (as given by ``mocap.rotations.frames``).

    Offsets are the child's origin in the parent's frame, averaged over the frames where
    both are seen; end sites are not known from frames alone and are left empty (NaN).
    Frames where a segment is missing are filled: rotations by slerp, the root's origin
    linearly (``metadata["filled_fraction"]`` says how much was filled).

    Parameters
    ----------
    rotations : ndarray, shape (frames, segments, 3, 3)
        World rotation of each segment frame in the lab; NaN where missing.
    origins : ndarray, shape (frames, segments, 3), metres
        World origin of each segment in the lab; NaN where missing.
    names, parents : segment names and parent indices (-1 for the root), parents first.
    rate : float, Hz
    up : {"z", "y"}
        The lab's vertical axis; "z" means X anterior, Y left, Z up (Vicon convention).
    """
    turn = up_matrix(up)
    rotations = np.asarray(rotations, float)
    origins = np.asarray(origins, float)
    count = origins.shape[1]
    world_r = np.einsum("ij,fsjk,lk->fsil", turn, rotations, turn)   # C R Cᵀ
    world_p = origins @ turn.T
    offsets = np.zeros((count, 3))
    for i, p in enumerate(parents):
        if p < 0:
            continue
        local = np.einsum("fji,fj->fi", world_r[:, p], world_p[:, i] - world_p[:, p])
        good = np.isfinite(local).all(axis=1)
        if not good.any():
            raise MocapError(f"segment {names[i]!r} and its parent {names[p]!r} are never "
                             "seen together: its offset is unknown")
        offsets[i] = local[good].mean(axis=0)
    missing = ~np.isfinite(world_r).all(axis=(2, 3))
    filled = np.stack([_fill_rotations(world_r[:, s]) for s in range(count)], axis=1)
    relative = filled.copy()
    for i, p in enumerate(parents):
        if p >= 0:
            relative[:, i] = np.swapaxes(filled[:, p], 1, 2) @ filled[:, i]
    relative = _orthonormalise(relative)
    root = _fill_linear(world_p[:, 0])
    meta = dict(metadata or {})
    meta["filled_fraction"] = float(missing.mean()) if missing.size else 0.0
    skeleton = Skeleton(list(names), list(parents), offsets)
    return Motion(skeleton, root, relative, rate, meta)


def _orthonormalise(matrices: np.ndarray) -> np.ndarray:
    """Nearest rotation matrices (polar decomposition by SVD), any leading shape."""
    u, _, vt = np.linalg.svd(matrices)
    d = np.sign(np.linalg.det(u @ vt))
    u[..., :, -1] *= d[..., None]
    return u @ vt


def motion_from_trial(trial, markerset, up: str = "z") -> Motion:
    """A :class:`Motion` from a marker trial: segment frames from three markers per segment.

    Segment lengths and offsets come from the markers: the offset of a child's origin in
    its parent's frame averaged over frames. The lab (Z up, X anterior by default) is
    turned to Y up. Leaf segments get default end sites along the parent's long axis (hand,
    head) or anterior (foot), scaled by the segment chain's lengths, so the figure has
    hands, a head top and toes to draw and to touch the floor.

    Parameters
    ----------
    trial : mocap.trial.Trial
    markerset : mocap.markersets.MarkerSet or str
        A marker set or the name/path of one (``load_markerset``).
    up : {"z", "y"}

    Returns
    -------
    Motion
    """
    if isinstance(markerset, str):
        markerset = load_markerset(markerset)
    rotations, origins = segment_frames(trial, markerset)
    motion = motion_from_frames(rotations, origins, list(markerset.segment_names),
                                list(markerset.parent_index), trial.rate, up=up,
                                metadata={"source": trial.path, "format": trial.format})
    turn = up_matrix(up)
    for index, segment in enumerate(markerset.segments):
        labels = [m for m in dict.fromkeys(list(segment.markers) + [segment.origin])
                  if m and m in trial.labels]
        if not labels or motion.skeleton.children(index):
            continue
        # Mean marker positions in the segment's frame (the frame turned to Y up).
        world = np.stack([trial.marker(m) for m in labels], axis=1) @ turn.T   # (F, k, 3)
        frame_r = np.einsum("ij,fjk,lk->fil", turn, rotations[:, index], turn)
        local = np.einsum("fji,fkj->fki", frame_r, world - (origins[:, index] @ turn.T)[:, None])
        local = np.nanmean(np.where(np.isfinite(local), local, np.nan), axis=0) \
            if np.isfinite(local).any() else None
        if local is not None and np.isfinite(local).all():
            _end_site_from_markers(motion.skeleton, index, local)
    _default_end_sites(motion.skeleton)
    _calibrate_soles(motion)
    if trial.frames:
        motion.start_time = float(trial.time_base()[1][0])     # the trial's own clock
    return motion


def _calibrate_soles(motion: Motion, still_speed: float = 0.15) -> None:
    """Put each foot's sole on the floor while the foot stands still (in place).

    Markers do not show where the sole is (they sit on the skin, at heights that vary by
    subject and protocol). In the frames where an ankle moves slower than ``still_speed``
    (m/s) in all three directions — the foot is planted — the sole (the end site's level,
    at the toe tip and under the ankle) must touch the floor: the end site's height in the
    foot frame is shifted by the median height found there. A trial with fewer than 5 %
    such frames keeps its estimate (``metadata["sole_calibration_m"]`` lists the shifts).
    """
    sk = motion.skeleton
    world_r, world_p = motion.forward_kinematics()
    shifts = {}
    for index, name in enumerate(sk.names):
        end = sk.end_sites[index]
        if not (canonical_segment(name) or name).endswith("foot") or not np.isfinite(end).all():
            continue
        speed = np.linalg.norm(np.gradient(world_p[:, index], 1.0 / motion.rate, axis=0), axis=1)
        still = speed < still_speed
        if still.mean() < 0.05:
            continue
        sole = np.stack([end, np.array([0.0, end[1], 0.0])])           # toe tip, below ankle
        height = (world_p[still, index, None] + np.einsum(
            "fij,kj->fki", world_r[still, index], sole))[..., 1].mean(axis=1)
        shift = float(np.median(height))
        # Moving the sole by d along the foot's y lowers it by about d (a planted foot is
        # roughly level), so subtract the height found.
        sk.end_sites[index, 1] -= shift
        shifts[name] = shift
    motion.metadata["sole_calibration_m"] = shifts


def _end_site_from_markers(skeleton: Skeleton, index: int, local: np.ndarray) -> None:
    """A foot's toe tip from its markers (in place), when they reach below the ankle.

    ``local`` (markers, 3) are the segment's markers in its own Y-up frame. Foot markers
    on the skin (heel, toe as in Plug-in Gait) sit about 12 mm above the sole (marker
    radius and skin); the toe tip is a quarter of the heel-to-toe-marker length beyond the
    toe marker. Marker sets whose foot markers are not below the ankle (synthetic ones)
    keep the proportional default of :func:`_default_end_sites`.
    """
    name = canonical_segment(skeleton.names[index]) or skeleton.names[index]
    if not name.endswith("foot") or local[:, 1].min() > -0.02:
        return
    toe = local[np.argmax(local[:, 2])]
    heel = local[np.argmin(local[:, 2])]
    sole = local[:, 1].min() - 0.012
    tip = toe[2] + 0.25 * (toe[2] - heel[2])
    skeleton.end_sites[index] = np.array([toe[0], sole, tip])


def _default_end_sites(skeleton: Skeleton) -> None:
    """Give leaf segments an end site (in place) when they have none.

    Head and hands continue the parent's long axis (direction parent origin → segment
    origin) for a fraction of the parent's length; feet point anterior (+Z) and down to the
    sole, in proportion to the shank. Fractions from Winter's table: hand 0.108 H vs forearm
    0.146 H; head 0.13 H vs trunk.
    """
    fractions = {"head": 0.85, "hand": 0.74}
    for i in range(skeleton.count):
        if skeleton.children(i) or np.isfinite(skeleton.end_sites[i]).all():
            continue
        p = skeleton.parents[i]
        if p < 0:
            continue
        along = skeleton.offsets[i]
        length = float(np.linalg.norm(along))
        if length == 0:
            continue
        name = canonical_segment(skeleton.names[i]) or skeleton.names[i]
        if name.endswith("foot"):
            # The sole 0.19 and the toe tip 0.40 shank lengths below and ahead of the ankle
            # (an 80 mm ankle height and 167 mm ankle-to-toe for a 417 mm shank, as in the
            # project's synthetic people; Winter's table gives 0.16 and 0.46).
            skeleton.end_sites[i] = np.array([0.0, -0.19, 0.40]) * length
        else:
            fraction = fractions["head"] if name == "head" else fractions["hand"]
            skeleton.end_sites[i] = along * fraction


def motion_to_lab(motion: Motion, up: str = "z") -> tuple[np.ndarray, np.ndarray]:
    """Joint rotations and root origin of a motion in a lab frame (inverse of the builders).

    Returns
    -------
    rotations : ndarray, shape (frames, segments, 3, 3)
        Relative rotations in the lab's axes (``Cᵀ R C``).
    root : ndarray, shape (frames, 3), metres
        World origin of the root in the lab.
    """
    turn = up_matrix(up)
    rotations = np.einsum("ji,fsjk,kl->fsil", turn, motion.rotations, turn)
    root = (motion.skeleton.offsets[0] + motion.root_translation) @ turn
    return rotations, root


def reduce_to_segments(motion: Motion, partial: bool = False,
                       joint_map: dict[str, str] | None = None) -> Motion:
    """The motion of a foreign skeleton (BVH, ASF) on our 15-segment body.

    Each body segment follows the joint :func:`map_segments` chose for it: its world
    rotation and origin come from the full skeleton's forward kinematics. Offsets between
    body segments are the mean over frames (exact when the skipped joints between them —
    collars, extra spine joints — do not move; otherwise an average pose). End sites of
    head, hands and feet are the furthest end site of the skipped subtree (head top,
    finger tip, toe tip) in the segment's frame, averaged over frames; where the rig has
    none (an End Site at the joint itself), a length in proportion to the parent segment.
    ``metadata["feet_at_joints"]`` maps the feet whose toe is such a point of the rig —
    a joint centre on the foot's bones, not on the sole — to what it is: ``"toe joint"``
    (a joint with no extent beyond it, Bandai's Toes_L: the phalanges are not in the rig)
    or ``"end site"`` (the rig's toe tip, CMU's ToeBase end site).

    Parameters
    ----------
    motion : Motion
    partial : bool
        Accept a body with pelvis and legs only (a lower-body marker set): the segments
        found, in body order; the dynamics lumps the missing ones into the pelvis.
    joint_map : dict, optional
        Body segment → joint name for joints the names do not reveal
        (:func:`mocap.body.segments.read_joint_map`); default ``motion.metadata["joint_map"]``
        (set by :func:`mocap.io.motion.read_motion`).

    Raises
    ------
    MocapError
        When a needed body segment has no joint in the skeleton (names listed).
    """
    sk = motion.skeleton
    if sk.names == BODY_SEGMENTS:
        return motion
    if partial and set(LOWER_BODY) <= set(sk.names) <= set(BODY_SEGMENTS) \
            and sk.names == [n for n in BODY_SEGMENTS if n in sk.names] \
            and sk.parents == body_parents(sk.names):
        return motion
    if joint_map is None:
        joint_map = motion.metadata.get("joint_map")
    source = motion.metadata.get("source")
    try:
        found = map_segments(sk.names, sk.parents, joint_map)
    except MocapError as error:
        raise MocapError(error.problem, source) from None
    needed = LOWER_BODY if partial else BODY_SEGMENTS
    if any(s not in found for s in needed):
        raise MocapError(describe_mapping(sk.names, found, needed), source)
    names = [s for s in BODY_SEGMENTS if s in found]
    world_r, world_p = motion.forward_kinematics()
    chosen = [found[s] for s in names]
    rotations = world_r[:, chosen]
    origins = world_p[:, chosen]
    reduced = motion_from_frames(rotations, origins, names, body_parents(names),
                                 motion.rate, up="y", metadata=dict(motion.metadata))
    reduced.root_translation = world_p[:, chosen[0]] - reduced.skeleton.offsets[0]
    reduced.start_time = motion.start_time
    # End sites of the leaves: the furthest point of the original subtree.
    ends_index, ends = motion.end_site_positions((world_r, world_p))
    everything = np.concatenate([world_p, ends], axis=1)
    owners = list(range(sk.count)) + ends_index
    joint_feet: dict[str, str] = {}
    for leaf in ("head", "l_hand", "r_hand", "l_foot", "r_foot"):
        if leaf not in found:
            continue
        j = found[leaf]
        sub = set(sk.subtree(j))
        cols = [k for k, owner in enumerate(owners) if owner in sub and (k >= sk.count or k != j)]
        if not cols:
            continue
        local = np.einsum("fji,fkj->fki", world_r[:, j], everything[:, cols] - world_p[:, j, None])
        mean = local.mean(axis=0)
        far = np.argmax(np.linalg.norm(mean, axis=1))
        if np.linalg.norm(mean[far]) > 1e-6:       # a rig with End Site OFFSET 0 has none
            reduced.skeleton.end_sites[names.index(leaf)] = mean[far]
            if leaf.endswith("foot") and "sole_calibration_m" not in motion.metadata:
                joint_feet[leaf] = "toe joint" if cols[far] < sk.count else "end site"
    # Leaves the rig gives no extent (Bandai's head and hands end at their joint): the
    # proportional default, as for marker-built skeletons.
    _default_end_sites(reduced.skeleton)
    reduced.metadata["segment_map"] = {s: sk.names[found[s]] for s in names}
    # Feet whose toe is a joint of the rig (a toe joint or the toe's end site): points on
    # the foot's bones, with the sole below them (``dynamics.humanoid.soles.joint_soles``).
    reduced.metadata["feet_at_joints"] = joint_feet
    return reduced
