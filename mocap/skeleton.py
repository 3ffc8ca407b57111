"""Skeletons and motions: the :class:`Motion` container and its builders.

A :class:`Skeleton` is the constant description of an articulated figure (segment names,
parent indices, offsets of each segment origin in its parent's frame, end sites of leaf
segments). A :class:`Motion` animates a skeleton: root translation and one rotation per
joint per frame, relative to the parent (the root's relative to the world).

Conventions (those of BVH, so a :class:`Motion` is one step from a BVH file):

* world Y is up, the floor is the plane y = 0; our neutral pose faces +Z with the figure's
  left along +X (so X × Y = Z);
* lengths in metres; rotations are 3 × 3 matrices acting on column vectors;
* a joint's frame is the identity in the skeleton's rest pose, so a joint's world position
  is ``p_parent + G_parent @ offset`` with ``G_parent`` the parent's world rotation, and the
  root's world position is ``offsets[0] + root_translation`` (BVH semantics: channel values
  are added to the root's OFFSET).

Builders: :func:`motion_from_trial` (segment frames of a marker trial, Z-up lab converted to
Y up), :func:`motion_from_angles` (joint angles on a skeleton) and :func:`reduce_to_segments`
(a BVH/ASF skeleton with any joint names onto the 15 segments of our body model).
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from mocap.errors import MocapError

#: The 15 segments of the project's body model, in model order (parents first).
BODY_SEGMENTS = [
    "pelvis", "thorax", "head",
    "l_upperarm", "l_forearm", "l_hand",
    "r_upperarm", "r_forearm", "r_hand",
    "l_thigh", "l_shank", "l_foot",
    "r_thigh", "r_shank", "r_foot",
]
#: Parent of each body segment (index into BODY_SEGMENTS, -1 for the root).
BODY_PARENTS = [-1, 0, 1, 1, 3, 4, 1, 6, 7, 0, 9, 10, 0, 12, 13]

#: Rotation taking vectors of a Z-up lab (X anterior, Y left, Z up) into our Y-up frame
#: (X left, Y up, Z anterior): a cyclic permutation of the axes.
Z_UP_TO_Y_UP = np.array([[0.0, 1.0, 0.0],
                         [0.0, 0.0, 1.0],
                         [1.0, 0.0, 0.0]])


@dataclass
class Skeleton:
    """The constant description of an articulated figure.

    Attributes
    ----------
    names : list of str
        Segment (joint) names; a segment's origin is its proximal joint.
    parents : list of int
        Parent index of each segment, -1 for the root; parents come before children.
    offsets : ndarray, shape (segments, 3), float, metres
        Origin of each segment in its parent's frame (the root's: its rest position).
    end_sites : ndarray, shape (segments, 3), float, metres
        Distal end of each leaf segment in its own frame (BVH "End Site"); NaN rows for
        segments without an end site.
    """

    names: list[str]
    parents: list[int]
    offsets: np.ndarray
    end_sites: np.ndarray | None = None

    def __post_init__(self) -> None:
        self.names = [str(n) for n in self.names]
        self.parents = [int(p) for p in self.parents]
        self.offsets = np.asarray(self.offsets, dtype=float).reshape(-1, 3)
        count = len(self.names)
        if len(self.parents) != count or self.offsets.shape[0] != count:
            raise ValueError(f"{count} names, {len(self.parents)} parents and "
                             f"{self.offsets.shape[0]} offsets")
        for index, parent in enumerate(self.parents):
            if parent >= index or (parent < 0 and index != 0):
                raise ValueError(f"segment {self.names[index]!r}: parent {parent} must come "
                                 "before it (only segment 0 is the root)")
        if self.end_sites is None:
            self.end_sites = np.full((count, 3), np.nan)
        self.end_sites = np.asarray(self.end_sites, dtype=float).reshape(count, 3)

    @property
    def count(self) -> int:
        """Number of segments."""
        return len(self.names)

    def index(self, name: str) -> int:
        """Index of segment ``name`` (KeyError if absent)."""
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(name) from None

    def children(self, index: int) -> list[int]:
        """Indices of the direct children of segment ``index``."""
        return [i for i, p in enumerate(self.parents) if p == index]

    def subtree(self, index: int) -> list[int]:
        """Indices of segment ``index`` and all its descendants (parents first)."""
        inside = {index}
        for i in range(index + 1, self.count):
            if self.parents[i] in inside:
                inside.add(i)
        return sorted(inside)

    def rest_positions(self) -> np.ndarray:
        """World positions of the segment origins in the rest pose, shape (segments, 3)."""
        positions = np.zeros((self.count, 3))
        for i, p in enumerate(self.parents):
            positions[i] = self.offsets[i] if p < 0 else positions[p] + self.offsets[i]
        return positions

    def lengths(self) -> np.ndarray:
        """Length of each segment (metres), shape (segments,).

        The distance from its origin to its first child's origin, or to its end site for a
        leaf; 0 when neither exists.
        """
        result = np.zeros(self.count)
        for i in range(self.count):
            kids = self.children(i)
            if kids:
                result[i] = np.linalg.norm(self.offsets[kids[0]])
            elif np.isfinite(self.end_sites[i]).all():
                result[i] = np.linalg.norm(self.end_sites[i])
        return result


@dataclass
class Motion:
    """An animated skeleton.

    Attributes
    ----------
    skeleton : Skeleton
    root_translation : ndarray, shape (frames, 3), float, metres
        Added to ``skeleton.offsets[0]`` to give the root's world position.
    rotations : ndarray, shape (frames, segments, 3, 3), float
        Rotation of each segment relative to its parent; the root's relative to the world.
    rate : float
        Frames per second (Hz).
    metadata : dict
        Provenance: source path and format, BVH channel layout, unit detected, name map.

    Examples
    --------
    >>> from mocap.skeleton import default_skeleton, Motion
    >>> motion = Motion.still(default_skeleton(), frames=10, rate=100.0)
    >>> motion.frames
    10
    """

    skeleton: Skeleton
    root_translation: np.ndarray
    rotations: np.ndarray
    rate: float
    metadata: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.root_translation = np.asarray(self.root_translation, dtype=float).reshape(-1, 3)
        self.rotations = np.asarray(self.rotations, dtype=float)
        frames = self.root_translation.shape[0]
        expected = (frames, self.skeleton.count, 3, 3)
        if self.rotations.shape != expected:
            raise ValueError(f"rotations must have shape {expected}, got {self.rotations.shape}")
        self.rate = float(self.rate)
        if not self.rate > 0:
            raise ValueError(f"rate must be positive, got {self.rate}")

    # -- basic properties -------------------------------------------------------------
    @property
    def frames(self) -> int:
        """Number of frames."""
        return int(self.root_translation.shape[0])

    @property
    def names(self) -> list[str]:
        """Segment names (those of the skeleton)."""
        return self.skeleton.names

    @property
    def times(self) -> np.ndarray:
        """Time of each frame in seconds from the first, shape (frames,)."""
        return np.arange(self.frames) / self.rate

    @property
    def duration(self) -> float:
        """Seconds from the first to the last frame."""
        return max(self.frames - 1, 0) / self.rate

    @classmethod
    def still(cls, skeleton: Skeleton, frames: int, rate: float,
              root_translation: np.ndarray | None = None) -> "Motion":
        """A motion holding the rest pose for ``frames`` frames.

        Parameters
        ----------
        root_translation : ndarray, shape (3,) or (frames, 3), optional
            Default: zero (the root stays at ``skeleton.offsets[0]``).
        """
        translation = np.zeros((frames, 3)) if root_translation is None else \
            np.broadcast_to(np.asarray(root_translation, float), (frames, 3)).copy()
        rotations = np.broadcast_to(np.eye(3), (frames, skeleton.count, 3, 3)).copy()
        return cls(skeleton, translation, rotations, rate)

    # -- kinematics -------------------------------------------------------------------
    def forward_kinematics(self) -> tuple[np.ndarray, np.ndarray]:
        """World rotations and origins of every segment.

        Returns
        -------
        rotations : ndarray, shape (frames, segments, 3, 3)
            World rotation of each segment frame.
        positions : ndarray, shape (frames, segments, 3), metres
            World position of each segment origin.
        """
        sk = self.skeleton
        world_r = np.empty_like(self.rotations)
        world_p = np.empty((self.frames, sk.count, 3))
        # Loop over the (few) segments, vectorised over frames.
        for i, p in enumerate(sk.parents):
            if p < 0:
                world_r[:, i] = self.rotations[:, i]
                world_p[:, i] = sk.offsets[i] + self.root_translation
            else:
                world_r[:, i] = world_r[:, p] @ self.rotations[:, i]
                world_p[:, i] = world_p[:, p] + world_r[:, p] @ sk.offsets[i]
        return world_r, world_p

    def end_site_positions(self, world: tuple[np.ndarray, np.ndarray] | None = None
                           ) -> tuple[list[int], np.ndarray]:
        """World positions of the end sites.

        Returns
        -------
        segments : list of int
            The segments that have an end site.
        positions : ndarray, shape (frames, len(segments), 3), metres
        """
        world_r, world_p = self.forward_kinematics() if world is None else world
        ends = self.skeleton.end_sites
        which = [i for i in range(self.skeleton.count) if np.isfinite(ends[i]).all()]
        if not which:
            return [], np.zeros((self.frames, 0, 3))
        pos = world_p[:, which] + np.einsum("fsij,sj->fsi", world_r[:, which], ends[which])
        return which, pos

    def all_points(self) -> np.ndarray:
        """Segment origins followed by end sites, shape (frames, points, 3), metres."""
        world = self.forward_kinematics()
        _, ends = self.end_site_positions(world)
        return np.concatenate([world[1], ends], axis=1)

    # -- editing ----------------------------------------------------------------------
    def slice(self, start: int = 0, stop: int | None = None, step: int = 1) -> "Motion":
        """Frames ``start:stop:step`` (the rate divides by ``step``)."""
        return replace(self, root_translation=self.root_translation[start:stop:step].copy(),
                       rotations=self.rotations[start:stop:step].copy(),
                       rate=self.rate / step, metadata=dict(self.metadata))

    def scaled(self, factor: float) -> "Motion":
        """The same motion with every length multiplied by ``factor``."""
        sk = self.skeleton
        skeleton = Skeleton(sk.names, sk.parents, sk.offsets * factor, sk.end_sites * factor)
        return replace(self, skeleton=skeleton, root_translation=self.root_translation * factor,
                       metadata=dict(self.metadata))

    def rotation_vectors(self) -> np.ndarray:
        """Joint rotations as rotation vectors (axis × angle, radians), (frames, segments, 3)."""
        flat = Rotation.from_matrix(self.rotations.reshape(-1, 3, 3)).as_rotvec()
        return flat.reshape(self.frames, self.skeleton.count, 3)

    def joint_angles(self, sequence: str = "ZXY") -> np.ndarray:
        """Euler angles of every joint rotation in the motion's own (Y-up) axes.

        Parameters
        ----------
        sequence : str
            scipy convention (upper case intrinsic, lower case extrinsic).

        Returns
        -------
        ndarray, shape (frames, segments, 3), degrees, unwrapped over time.
        """
        flat = Rotation.from_matrix(self.rotations.reshape(-1, 3, 3)).as_euler(
            sequence, degrees=True)
        angles = flat.reshape(self.frames, self.skeleton.count, 3)
        return np.unwrap(angles, period=360.0, axis=0)


def frame_rate(frame_time: float) -> float:
    """Frames per second for a frame time, snapped to a whole number of Hz when the frame
    time is that rate rounded to a file's few decimals (0.033333 s → 30 Hz)."""
    rate = 1.0 / frame_time
    whole = round(rate)
    if whole > 0 and abs(1.0 / whole - frame_time) <= 5e-6 * max(1.0, frame_time * 100):
        return float(whole)
    return rate


# ----------------------------------------------------------------------------------------
# A default body
# ----------------------------------------------------------------------------------------
def default_skeleton(height: float = 1.75) -> Skeleton:
    """The 15-segment body in its neutral standing pose (arms hanging), Y up, facing +Z.

    Segment lengths are fractions of ``height`` from Winter's anthropometric table (2009,
    Fig. 4.1); the rest pose stands with the soles on y = 0 when the root translation is 0.

    Parameters
    ----------
    height : float
        Standing height in metres.
    """
    h = float(height)
    # Positions (x left, y up, z anterior) of each segment's origin in the rest pose.
    hip_y, knee_y, ankle_y = 0.530 * h, 0.285 * h, 0.039 * h
    hip_x, shoulder_x = 0.05 * h, 0.129 * h
    origin = {
        "pelvis": (0.0, hip_y + 0.02 * h, 0.0),
        "thorax": (0.0, 0.720 * h, 0.0),
        "head": (0.0, 0.870 * h, 0.0),
        "l_upperarm": (shoulder_x, 0.818 * h, 0.0),
        "l_forearm": (shoulder_x, 0.818 * h - 0.186 * h, 0.0),
        "l_hand": (shoulder_x, 0.818 * h - 0.186 * h - 0.146 * h, 0.0),
        "l_thigh": (hip_x, hip_y, 0.0),
        "l_shank": (hip_x, knee_y, 0.0),
        "l_foot": (hip_x, ankle_y, 0.0),
    }
    for name in list(origin):
        if name.startswith("l_"):
            x, y, z = origin[name]
            origin["r_" + name[2:]] = (-x, y, z)
    rest = np.array([origin[n] for n in BODY_SEGMENTS])
    offsets = rest.copy()
    for i, p in enumerate(BODY_PARENTS):
        if p >= 0:
            offsets[i] = rest[i] - rest[p]
    ends = np.full((15, 3), np.nan)
    ends[BODY_SEGMENTS.index("head")] = (0.0, h - 0.870 * h, 0.0)
    ends[BODY_SEGMENTS.index("l_hand")] = (0.0, -0.108 * h, 0.0)
    ends[BODY_SEGMENTS.index("r_hand")] = (0.0, -0.108 * h, 0.0)
    foot = (0.0, -ankle_y, 0.152 * h - 0.039 * h)   # toe on the floor, ahead of the ankle
    ends[BODY_SEGMENTS.index("l_foot")] = foot
    ends[BODY_SEGMENTS.index("r_foot")] = foot
    return Skeleton(list(BODY_SEGMENTS), list(BODY_PARENTS), offsets, ends)


# ----------------------------------------------------------------------------------------
# From marker trials and joint angles
# ----------------------------------------------------------------------------------------
def _up_matrix(up: str) -> np.ndarray:
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
    """A :class:`Motion` from world segment frames (as given by ``mocap.frames``).

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
    turn = _up_matrix(up)
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
    markerset : mocap.markersets.model.MarkerSet or str
        A marker set or the name/path of one (``load_markerset``).
    up : {"z", "y"}

    Returns
    -------
    Motion
    """
    from mocap.frames import segment_frames
    from mocap.markersets.model import load_markerset

    if isinstance(markerset, str):
        markerset = load_markerset(markerset)
    rotations, origins = segment_frames(trial, markerset)
    motion = motion_from_frames(rotations, origins, list(markerset.segment_names),
                                list(markerset.parent_index), trial.rate, up=up,
                                metadata={"source": trial.path, "format": trial.format})
    turn = _up_matrix(up)
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


def motion_from_angles(angles, skeleton: Skeleton | None = None,
                       root_translation: np.ndarray | None = None, up: str = "z") -> Motion:
    """A :class:`Motion` from joint angles (``mocap.angles.JointAngles``) on a skeleton.

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
    turn = _up_matrix(up)
    values = np.asarray(angles.values, dtype=float)
    frames = values.shape[0]
    times = np.asarray(getattr(angles, "times", np.arange(frames) / 100.0), float)
    rate = frame_rate(float(np.median(np.diff(times)))) if times.size > 1 else 100.0
    rotations = np.broadcast_to(np.eye(3), (frames, skeleton.count, 3, 3)).copy()
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


def motion_to_lab(motion: Motion, up: str = "z") -> tuple[np.ndarray, np.ndarray]:
    """Joint rotations and root origin of a motion in a lab frame (inverse of the builders).

    Returns
    -------
    rotations : ndarray, shape (frames, segments, 3, 3)
        Relative rotations in the lab's axes (``Cᵀ R C``).
    root : ndarray, shape (frames, 3), metres
        World origin of the root in the lab.
    """
    turn = _up_matrix(up)
    rotations = np.einsum("ji,fsjk,kl->fsil", turn, motion.rotations, turn)
    root = (motion.skeleton.offsets[0] + motion.root_translation) @ turn
    return rotations, root


# ----------------------------------------------------------------------------------------
# Joint names of other tools onto our segments
# ----------------------------------------------------------------------------------------
_SIDE_WORDS = {"l": ("left", "l"), "r": ("right", "r")}
#: For each limb segment, the names (after the side word) that mean it, best first.
_LIMB_WORDS = {
    "upperarm": ("upperarm", "arm", "humerus", "shoulder", "uparm"),
    "forearm": ("forearm", "lowerarm", "lowarm", "radius", "elbow"),
    "hand": ("hand", "wrist"),
    "thigh": ("upleg", "thigh", "femur", "upperleg", "hip"),
    "shank": ("leg", "shin", "tibia", "lowerleg", "lowleg", "knee", "calf"),
    "foot": ("foot", "ankle"),
}
_CENTRAL_WORDS = {
    "pelvis": ("hips", "pelvis", "root", "hip"),
    "head": ("head",),
}


def _normalise(name: str) -> str:
    """Lower case, namespace ('mixamorig:') dropped, separators removed."""
    name = name.split(":")[-1].split("|")[-1]
    return re.sub(r"[^a-z0-9]", "", name.lower())


def canonical_segment(name: str) -> str | None:
    """Our body segment for one joint name of another tool, or None.

    Knows BVH conventions (CMU/Motionbuilder: Hips, LeftUpLeg, LeftLeg, LeftFoot, LeftArm,
    LeftForeArm, LeftHand; others: LeftThigh, LeftShin, LeftHip/LeftKnee/LeftAnkle,
    LeftShoulder/LeftElbow/LeftWrist; Mixamo's ``mixamorig:`` prefix) and ASF bones
    (lfemur, ltibia, lfoot, lhumerus, lradius, lwrist). Ambiguous names ("LeftShoulder"
    is the clavicle when "LeftArm" exists) are settled by :func:`map_segments`.
    """
    key = _normalise(name)
    if key in _BODY_KEYS:
        return _BODY_KEYS[key]
    for segment, words in _CENTRAL_WORDS.items():
        if key in words:
            return segment
    for side, prefixes in _SIDE_WORDS.items():
        for prefix in prefixes:
            if key.startswith(prefix):
                rest = key[len(prefix):]
                for limb, words in _LIMB_WORDS.items():
                    if rest in words:
                        return f"{side}_{limb}"
    return None


_BODY_KEYS = {_normalise(n): n for n in BODY_SEGMENTS}


def map_segments(names: list[str], parents: list[int]) -> dict[str, int]:
    """Which joint of a foreign skeleton stands for each of our body segments.

    Each limb segment takes the candidate whose name is the best match (order of
    ``_LIMB_WORDS``); the thorax is the spine joint where the two arms branch (lowest
    common ancestor of the upper arms), so trunk joints between pelvis and thorax are
    folded into the thorax.

    Returns
    -------
    dict
        Body segment name → joint index; only the segments found.
    """
    best: dict[str, tuple[int, int]] = {}
    for index, name in enumerate(names):
        key = _normalise(name)
        segment = canonical_segment(name)
        if segment is None:
            continue
        if segment in _BODY_KEYS.values() and key in _BODY_KEYS:
            rank = -1
        elif segment in ("pelvis", "head"):
            rank = _CENTRAL_WORDS[segment].index(key)
            if segment == "pelvis" and parents[index] >= 0 and key != "pelvis":
                rank += 10       # a 'hip' below the root is not the pelvis
        else:
            limb = segment[2:]
            prefix = next(p for p in _SIDE_WORDS[segment[0]] if key.startswith(p))
            rank = _LIMB_WORDS[limb].index(key[len(prefix):])
        if segment not in best or rank < best[segment][0]:
            best[segment] = (rank, index)
    found = {segment: index for segment, (rank, index) in best.items()}
    if "pelvis" not in found:
        found["pelvis"] = 0
    if "thorax" not in found and "l_upperarm" in found and "r_upperarm" in found:
        found["thorax"] = _common_ancestor(parents, found["l_upperarm"], found["r_upperarm"])
    # A limb joint that is an ancestor of a better-ranked upper arm (a clavicle named
    # 'LeftShoulder') must not be used twice: the ranks above already ensure that.
    return found


def _common_ancestor(parents: list[int], a: int, b: int) -> int:
    chain = set()
    while a >= 0:
        chain.add(a)
        a = parents[a]
    while b not in chain:
        b = parents[b]
    return b


#: The segments every body needs: pelvis and both legs (the rest may be lumped).
LOWER_BODY = ["pelvis", "l_thigh", "l_shank", "l_foot", "r_thigh", "r_shank", "r_foot"]


def body_parents(names: list[str]) -> list[int]:
    """Parent indices of a subset of BODY_SEGMENTS (in body order): the nearest present
    ancestor of each segment in the full body, -1 for the root."""
    result = []
    for name in names:
        parent = BODY_PARENTS[BODY_SEGMENTS.index(name)]
        while parent >= 0 and BODY_SEGMENTS[parent] not in names:
            parent = BODY_PARENTS[parent]
        result.append(names.index(BODY_SEGMENTS[parent]) if parent >= 0 else -1)
    return result


def reduce_to_segments(motion: Motion, partial: bool = False) -> Motion:
    """The motion of a foreign skeleton (BVH, ASF) on our 15-segment body.

    Each body segment follows the joint :func:`map_segments` chose for it: its world
    rotation and origin come from the full skeleton's forward kinematics. Offsets between
    body segments are the mean over frames (exact when the skipped joints between them —
    collars, extra spine joints — do not move; otherwise an average pose). End sites of
    head, hands and feet are the furthest end site of the skipped subtree (head top,
    finger tip, toe tip) in the segment's frame, averaged over frames.

    Parameters
    ----------
    motion : Motion
    partial : bool
        Accept a body with pelvis and legs only (a lower-body marker set): the segments
        found, in body order; the dynamics lumps the missing ones into the pelvis.

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
    found = map_segments(sk.names, sk.parents)
    needed = LOWER_BODY if partial else BODY_SEGMENTS
    missing = [s for s in needed if s not in found]
    if missing:
        raise MocapError("cannot map the skeleton onto the body model: no joint for "
                         + ", ".join(missing) + f" (joints: {', '.join(sk.names)})",
                         motion.metadata.get("source"))
    names = [s for s in BODY_SEGMENTS if s in found]
    world_r, world_p = motion.forward_kinematics()
    chosen = [found[s] for s in names]
    rotations = world_r[:, chosen]
    origins = world_p[:, chosen]
    reduced = motion_from_frames(rotations, origins, names, body_parents(names),
                                 motion.rate, up="y", metadata=dict(motion.metadata))
    reduced.root_translation = world_p[:, chosen[0]] - reduced.skeleton.offsets[0]
    # End sites of the leaves: the furthest point of the original subtree.
    ends_index, ends = motion.end_site_positions((world_r, world_p))
    everything = np.concatenate([world_p, ends], axis=1)
    owners = list(range(sk.count)) + ends_index
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
        reduced.skeleton.end_sites[names.index(leaf)] = mean[far]
    reduced.metadata["segment_map"] = {s: sk.names[found[s]] for s in names}
    return reduced


# ----------------------------------------------------------------------------------------
# Motion files of any kind
# ----------------------------------------------------------------------------------------
#: Marker-trial suffixes :func:`load_motion` turns into motions with a marker set.
MARKER_SUFFIXES = (".c3d", ".trc", ".csv")
#: Suffixes :func:`load_motion` reads directly as motions.
MOTION_SUFFIXES = (".bvh", ".amc")


def _find_asf(amc: Path) -> Path:
    candidates = [amc.with_suffix(".asf"), amc.with_suffix(".ASF")]
    subject = amc.stem.split("_")[0]
    candidates += [amc.with_name(subject + ".asf"), amc.with_name(subject + ".ASF")]
    for candidate in candidates:
        if candidate.exists():
            return candidate
    found = sorted(amc.parent.glob("*.[aA][sS][fF]"))
    if len(found) == 1:
        return found[0]
    raise MocapError("no ASF skeleton found beside this AMC motion; give it with --asf", amc)


def _is_angle_csv(path: Path) -> bool:
    try:
        with open(path, encoding="utf-8", errors="replace") as handle:
            header = handle.readline().strip()
    except OSError:
        return False
    columns = [c.strip() for c in header.split(",")]
    return (len(columns) >= 4 and columns[0] == "time"
            and all(re.fullmatch(r"[^.]+\.[XYZxyz]2?", c) for c in columns[1:]))


def load_motion(path: str | os.PathLike, asf: str | None = None,
                markerset: str | None = None, units: str | None = None,
                rate: float = 120.0) -> Motion:
    """A :class:`Motion` from any motion file: BVH, ASF/AMC, joint angles or markers.

    Parameters
    ----------
    path : BVH, AMC, joint-angle CSV, or marker trial (C3D/TRC/CSV)
    asf : ASF skeleton for an AMC (default: found beside it)
    markerset : marker set for a marker trial
    units : length unit of a BVH/ASF (default: detected)
    rate : frame rate of an AMC, Hz

    Raises
    ------
    MocapError
        Missing or unreadable file, unknown suffix, a marker trial without a marker set.
    """
    path = Path(path)
    if not path.exists():
        raise MocapError("file not found", path)
    if path.is_dir():
        raise MocapError("is a directory, not a motion file", path)
    suffix = path.suffix.lower()
    if suffix == ".bvh":
        from mocap.io.bvh import read_bvh
        return read_bvh(path, units=units)
    if suffix == ".amc":
        from mocap.io.asfamc import read_asf_amc
        skeleton = Path(asf) if asf else _find_asf(path)
        if not skeleton.exists():
            raise MocapError("ASF file not found", skeleton)
        return read_asf_amc(skeleton, path, rate=rate, units=units)
    if suffix == ".asf":
        raise MocapError("an ASF file is the skeleton only: give the AMC motion (and this "
                         "file with --asf)", path)
    if suffix == ".csv" and _is_angle_csv(path):
        from mocap.angles import read_angles_csv
        angles = read_angles_csv(path)
        foreign = [s for s in angles.segments if s not in BODY_SEGMENTS]
        if foreign:
            raise MocapError("a joint-angle CSV carries no skeleton, so it plays only on the "
                             "15-segment body (pelvis, thorax, …); it has other segments: "
                             + ", ".join(foreign[:6]) + (" …" if len(foreign) > 6 else "")
                             + " (export with --body to get one)", path)
        return motion_from_angles(angles)
    if suffix in MARKER_SUFFIXES:
        if not markerset:
            raise MocapError("a marker trial needs --markerset (e.g. synthetic15) to build "
                             "the skeleton", path)
        from mocap.io import read
        from mocap.markersets.model import load_markerset
        return motion_from_trial(read(path), load_markerset(markerset))
    raise MocapError("unknown motion file type: use .bvh, .amc, a joint-angle .csv, or a "
                     ".c3d/.trc/.csv marker trial with --markerset", path)


def motion_joint_angles(motion: Motion, sequence: str = "ZXY", body: bool = True):
    """Joint angles of a motion as ``mocap.angles.JointAngles`` (DESIGN 3.2 convention).

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
    from mocap.angles import JointAngles, matrices_to_angles, unwrap_angles

    if body:
        motion = reduce_to_segments(motion)
    rotations, _ = motion_to_lab(motion)
    values = unwrap_angles(matrices_to_angles(rotations, sequence), sequence)
    return JointAngles(motion.times, values, list(motion.names), sequence,
                       list(motion.skeleton.parents))
