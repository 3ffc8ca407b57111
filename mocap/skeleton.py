"""Skeletons and motions: the :class:`Skeleton` and :class:`Motion` containers and forward
kinematics.

A :class:`Skeleton` is the constant description of an articulated figure (segment names,
parent indices, offsets of each segment origin in its parent's frame, end sites of leaf
segments). A :class:`Motion` animates a skeleton: root translation and one rotation per
joint per frame, relative to the parent (the root's relative to the world).

Conventions (those of BVH, so a :class:`Motion` is one step from a BVH file):

* world Y is up, the floor is the plane y = 0; our neutral pose faces +Z with the figure's
  left along +X (so X × Y = Z);
* lengths in metres; rotations are 3 × 3 matrices acting on column vectors;
* a joint's frame is the identity in the skeleton's rest pose, so a joint's world position
  is ``p_parent + G_parent @ t`` with ``G_parent`` the parent's world rotation and ``t`` the
  joint's local translation: its ``offset``, or, when the motion animates it (a BVH joint
  with position channels), ``Motion.translations[frame, joint]``; the root's world position
  is ``offsets[0] + root_translation``.

Where the rest lives: the 15-segment body and joint-name mapping in
:mod:`mocap.body.segments`; motions built from marker trials, world frames and foreign
skeletons in :mod:`mocap.body.retarget`; motions ↔ joint angles in :mod:`mocap.body.angles`;
reading any motion file in :mod:`mocap.io.motion`.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from mocap.errors import MocapError


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

    def transform_root(self) -> bool:
        """Whether the root (segment 0) is a transform node rather than a body part: it has
        one child and no end site (a BVH's ``joint_Root`` above ``Hips``, which stays at the
        floor origin in bandai2's captures and travels 4.3 m from the hips in clips
        synthesised on that rig). The line from it to its child is no bone.

        >>> Skeleton(["root", "hips", "leg"], [-1, 0, 1], np.zeros((3, 3))).transform_root()
        True
        >>> Skeleton(["hips", "l", "r"], [-1, 0, 0], np.zeros((3, 3))).transform_root()
        False
        """
        return self.count > 1 and self.parents.count(0) == 1 and \
            not np.isfinite(self.end_sites[0]).all()

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
    translations : ndarray, shape (frames, segments, 3), float, metres, optional
        Local translation of each non-root segment per frame, in its parent's frame,
        *replacing* ``skeleton.offsets`` (BVH position channels on a joint, as Blender and
        bvhio read them); row 0 is unused (the root moves by ``root_translation``).
        None: every segment keeps its offset.
    start_time : float, seconds
        Time of the first frame on the source's clock (a marker trial's
        :meth:`~mocap.trial.Trial.time_base`: a C3D's (first_frame − 1) / rate, a TRC's
        first Time); 0 for a BVH. ``times`` count from the first frame; the OpenSim files
        (:mod:`mocap.io.opensim_models`) carry ``start_time + times``.

    Examples
    --------
    >>> from mocap.body.segments import default_skeleton
    >>> from mocap.skeleton import Motion
    >>> motion = Motion.still(default_skeleton(), frames=10, rate=100.0)
    >>> motion.frames
    10
    """

    skeleton: Skeleton
    root_translation: np.ndarray
    rotations: np.ndarray
    rate: float
    metadata: dict = field(default_factory=dict)
    translations: np.ndarray | None = None
    start_time: float = field(default=0.0, kw_only=True)

    def __post_init__(self) -> None:
        self.root_translation = np.asarray(self.root_translation, dtype=float).reshape(-1, 3)
        self.rotations = np.asarray(self.rotations, dtype=float)
        frames = self.root_translation.shape[0]
        expected = (frames, self.skeleton.count, 3, 3)
        if self.rotations.shape != expected:
            raise ValueError(f"rotations must have shape {expected}, got {self.rotations.shape}")
        if self.translations is not None:
            self.translations = np.asarray(self.translations, dtype=float)
            if self.translations.shape != expected[:3]:
                raise ValueError(f"translations must have shape {expected[:3]}, got "
                                 f"{self.translations.shape}")
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
                if self.translations is None:
                    world_p[:, i] = world_p[:, p] + world_r[:, p] @ sk.offsets[i]
                else:
                    world_p[:, i] = world_p[:, p] + np.einsum(
                        "fij,fj->fi", world_r[:, p], self.translations[:, i])
        return world_r, world_p

    def local_translations(self) -> np.ndarray:
        """Local translation of every non-root segment per frame, (frames, segments, 3), m.

        ``translations`` when the motion animates them, else the offsets repeated; row 0
        holds the root's world position ``offsets[0] + root_translation``.
        """
        if self.translations is None:
            result = np.broadcast_to(self.skeleton.offsets,
                                     (self.frames, self.skeleton.count, 3)).copy()
        else:
            result = self.translations.copy()
        result[:, 0] = self.skeleton.offsets[0] + self.root_translation
        return result

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
        moved = None if self.translations is None else \
            self.translations[start:stop:step].copy()
        return replace(self, root_translation=self.root_translation[start:stop:step].copy(),
                       rotations=self.rotations[start:stop:step].copy(),
                       rate=self.rate / step, metadata=dict(self.metadata), translations=moved)

    def scaled(self, factor: float) -> "Motion":
        """The same motion with every length multiplied by ``factor``."""
        sk = self.skeleton
        skeleton = Skeleton(sk.names, sk.parents, sk.offsets * factor, sk.end_sites * factor)
        moved = None if self.translations is None else self.translations * factor
        return replace(self, skeleton=skeleton, root_translation=self.root_translation * factor,
                       metadata=dict(self.metadata), translations=moved)

    def resampled(self, rate: float) -> "Motion":
        """The motion at another frame rate over the same time span (Hz).

        Rotations are interpolated by slerp, translations linearly; the last frame is the
        last one inside the original span.
        """
        if not (np.isfinite(rate) and rate > 0):
            raise MocapError(f"the frame rate must be positive and finite, got {rate}")
        frames = int(np.floor(self.duration * rate + 1e-9)) + 1
        # the last time may pass the span's end by a rounding error (6.8666…7 > 6.8666…45)
        times = np.minimum(np.arange(frames) / rate, self.times[-1])
        if self.frames == 1:
            index = np.zeros(frames, int)
            return replace(self.slice(0, 1), rate=float(rate),
                           root_translation=self.root_translation[index],
                           rotations=self.rotations[index],
                           translations=None if self.translations is None
                           else self.translations[index])
        from scipy.spatial.transform import Rotation, Slerp   # deferred: 0.4 s to import
        rotations = np.stack([Slerp(self.times, Rotation.from_matrix(self.rotations[:, s]))(
            times).as_matrix() for s in range(self.skeleton.count)], axis=1)

        def linear(values: np.ndarray) -> np.ndarray:
            flat = values.reshape(self.frames, -1)
            return np.stack([np.interp(times, self.times, flat[:, k])
                             for k in range(flat.shape[1])], axis=1).reshape(
                (frames,) + values.shape[1:])

        moved = None if self.translations is None else linear(self.translations)
        return replace(self, root_translation=linear(self.root_translation),
                       rotations=rotations, rate=float(rate), metadata=dict(self.metadata),
                       translations=moved)

    def rotation_vectors(self) -> np.ndarray:
        """Joint rotations as rotation vectors (axis × angle, radians), (frames, segments, 3)."""
        from scipy.spatial.transform import Rotation   # deferred: 0.4 s to import
        flat = Rotation.from_matrix(self.rotations.reshape(-1, 3, 3)).as_rotvec()
        return flat.reshape(self.frames, self.skeleton.count, 3)


def frame_rate(frame_time: float) -> float:
    """Frames per second for a frame time, snapped to a whole number of Hz when the frame
    time is that rate rounded to a file's few decimals (0.033333 s → 30 Hz)."""
    rate = 1.0 / frame_time
    whole = round(rate)
    if whole > 0 and abs(1.0 / whole - frame_time) <= 5e-6 * max(1.0, frame_time * 100):
        return float(whole)
    return rate

