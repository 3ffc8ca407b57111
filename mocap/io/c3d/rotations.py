"""Segment poses of markerless C3D files: the ROTATION group (Theia3D).

Markerless systems store no markers but a 4 × 4 pose per body segment and frame.
The ROTATION group says how many (USED), their names (LABELS, e.g. ``pelvis_4X4``),
the rate (RATE, or RATIO rotation frames per point frame) and the block where they
start (DATA_START, 1-based). Each pose is 16 floats (the matrix by columns) and a
reliability float, negative when the segment was not tracked in that frame, in the
file's float format; translations are in POINT:UNITS.

:func:`read_rotations` checks that the whole block is in the file (a truncated file
is refused, with the frames it holds), and gives :class:`SegmentPoses`: rotation
matrices and origins in metres, NaN where unreliable. The writer puts them back as
ezc3d's ``data["rotations"]`` (:meth:`SegmentPoses.write_to`).

:func:`segment_parents` guesses the hierarchy from the segment names (pelvis → thigh →
shank → foot → toes, pelvis → torso → neck → head, torso → clavicle → upper arm →
forearm → hand) for joint angles without a marker set (``mocap angles
--from-rotations``).
"""
from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field

import numpy as np

from mocap.errors import MocapError
from mocap.io.text_table import read_text
from mocap.tomlfile import parse_toml

BLOCK = 512


@dataclass
class SegmentPoses:
    """Poses of body segments over time, in the lab.

    Attributes
    ----------
    labels : list of str
        Segment names (the ``_4X4`` suffix of Theia labels removed).
    rotations : ndarray, shape (frames, segments, 3, 3)
        Segment orientation in the lab (columns: the segment's axes); NaN where the
        segment was not tracked.
    positions : ndarray, shape (frames, segments, 3), metres
        Segment origin in the lab; NaN where not tracked.
    rate : float
        Hz.
    stored_labels : list of str
        Labels as stored in the file (written back unchanged).
    """

    labels: list[str]
    rotations: np.ndarray
    positions: np.ndarray
    rate: float
    stored_labels: list[str] = field(default_factory=list)

    @property
    def frames(self) -> int:
        """Number of frames."""
        return int(self.rotations.shape[0])

    def rotated(self, turn: np.ndarray) -> "SegmentPoses":
        """The poses in a lab turned by the rotation ``turn`` (3, 3)."""
        return SegmentPoses(list(self.labels), np.einsum("ij,fsjk->fsik", turn, self.rotations),
                            self.positions @ turn.T, self.rate, list(self.stored_labels))

    def matrices(self, units_per_metre: float = 1000.0) -> np.ndarray:
        """4 × 4 poses as ezc3d stores them, shape (4, 4, segments, frames), translations
        in the file's unit (``units_per_metre``)."""
        out = np.zeros((4, 4, len(self.labels), self.frames))
        out[:3, :3] = self.rotations.transpose(2, 3, 1, 0)
        out[:3, 3] = (self.positions * units_per_metre).transpose(2, 1, 0)
        out[3, 3] = 1.0
        return out

    def write_to(self, c3d, units_per_metre: float = 1000.0) -> list[str]:
        """Put the poses into an ezc3d object about to be written; returns notes."""
        frames = c3d["data"]["points"].shape[2]
        if self.frames % max(frames, 1):
            return [f"ROTATION ({self.frames} pose frames for {frames} point frames)"]
        c3d["data"]["rotations"] = self.matrices(units_per_metre)
        c3d.add_parameter("ROTATION", "LABELS", list(self.stored_labels or self.labels))
        c3d.add_parameter("ROTATION", "RATE", [float(self.rate)])
        return []


def read_rotations(layout, decode_floats, metres_per_unit: float = 1e-3) -> SegmentPoses | None:
    """The ROTATION group's poses of a checked C3D file, or None without one.

    Parameters
    ----------
    layout : C3DLayout
        From :func:`mocap.io.c3d.layout.inspect_c3d`.
    decode_floats : callable
        ``decode_floats(raw, processor)`` of the C3D reader.
    metres_per_unit : float
        The file's length unit (POINT:UNITS) in metres.

    Raises
    ------
    MocapError
        When the rotation block is cut short (a truncated file) or its parameters
        are not usable.
    """
    group = layout.parameters.get("ROTATION")
    if not group:
        return None
    used = _count(group.get("USED"))
    if not used:
        return None
    start = _count(group.get("DATA_START"))
    ratio = _count(group.get("RATIO")) or 1
    if not start or start < layout.data_block:
        raise MocapError(f"damaged or unsupported C3D file: ROTATION:DATA_START "
                         f"{start} is not a block of the data section", layout.path)
    frames = layout.frames * ratio
    size = frames * used * 17 * 4
    offset = (start - 1) * BLOCK
    if offset + size > layout.file_size:
        held = max(layout.file_size - offset, 0) // (used * 17 * 4)
        raise MocapError(f"damaged or unsupported C3D file: truncated: the ROTATION block "
                         f"announces {frames} frames of {used} segment poses "
                         f"({size} bytes from byte {offset}) but the file holds "
                         f"{held} complete frames", layout.path)
    with open(layout.path, "rb") as handle:
        handle.seek(offset)
        raw = handle.read(size)
    values = decode_floats(raw, layout.processor).reshape(frames, used, 17)
    matrices = values[:, :, :16].reshape(frames, used, 4, 4).swapaxes(2, 3)   # by columns
    invalid = ~(values[:, :, 16] >= 0) | ~np.isfinite(values[:, :, :16]).all(axis=2)
    rotations = matrices[:, :, :3, :3].copy()
    positions = matrices[:, :, :3, 3].copy()
    rotations[invalid] = np.nan
    positions[invalid] = np.nan
    labels = _strings(group.get("LABELS"))[:used]
    labels += [f"segment{i + 1}" for i in range(len(labels), used)]
    rate = group.get("RATE")
    rate = float(rate.reshape(-1)[0]) if isinstance(rate, np.ndarray) and rate.size \
        else layout.rate * ratio
    return SegmentPoses([re.sub(r"_4x4$", "", label, flags=re.I) for label in labels],
                        rotations, positions * metres_per_unit, rate, labels)


def _count(value) -> int:
    if isinstance(value, np.ndarray) and value.size:
        number = float(value.reshape(-1)[0])
        if math.isfinite(number) and number > 0:
            return int(number) & 0xFFFF if np.issubdtype(value.dtype, np.integer) \
                else int(number)
    return 0


def _strings(value) -> list[str]:
    if isinstance(value, str):
        return [value.strip()] if value.strip() else []
    if isinstance(value, list):
        return [str(v).strip() for v in value]
    return []


# ---------------------------------------------------------------- hierarchy from names

#: Kind of segment → words that name it (after a side prefix l_/r_/left/right).
_KINDS = {
    "pelvis": ("pelvis", "hips", "hip", "root", "sacrum"),
    "torso": ("torso", "thorax", "trunk", "chest", "spine", "abdomen", "lumbar"),
    "neck": ("neck",),
    "head": ("head", "skull"),
    "clavicle": ("clavicle", "clav", "shoulder", "scapula"),
    "upperarm": ("uarm", "upperarm", "humerus", "arm"),
    "forearm": ("larm", "forearm", "lowerarm", "radius", "ulna"),
    "hand": ("hand", "wrist"),
    "thigh": ("thigh", "femur", "upperleg", "upleg"),
    "shank": ("shank", "shin", "tibia", "lowerleg", "leg", "calf"),
    "foot": ("foot", "calcn", "ankle"),
    "toes": ("toes", "toe", "forefoot"),
}
#: Parent kinds, nearest first (the first one present is the parent).
_PARENT_KINDS = {
    "pelvis": (), "torso": ("pelvis",), "neck": ("torso", "pelvis"),
    "head": ("neck", "torso", "pelvis"), "clavicle": ("torso", "pelvis"),
    "upperarm": ("clavicle", "torso", "pelvis"), "forearm": ("upperarm",),
    "hand": ("forearm",), "thigh": ("pelvis",), "shank": ("thigh",), "foot": ("shank",),
    "toes": ("foot",),
}
_SIDED = {"clavicle", "upperarm", "forearm", "hand", "thigh", "shank", "foot", "toes"}
#: Names of the lab itself (Theia's ``worldbody``): not a segment.
WORLD_NAMES = ("worldbody", "world", "ground", "lab")


def _kind(name: str) -> tuple[str | None, str]:
    key = re.sub(r"[^a-z0-9]", "", name.lower())
    for side, prefixes in (("l", ("left", "l")), ("r", ("right", "r"))):
        for prefix in prefixes:
            rest = key[len(prefix):]
            if key.startswith(prefix):
                for kind, words in _KINDS.items():
                    if kind in _SIDED and rest in words:
                        return kind, side
    for kind, words in _KINDS.items():
        if kind not in _SIDED and key in words:
            return kind, ""
    return None, ""


def segment_parents(labels: list[str], path=None) -> dict[str, str | None]:
    """Parent of each segment guessed from the names (``None`` for the root).

    Raises
    ------
    MocapError
        When a name is not recognised or there is no pelvis, with how to give the
        hierarchy instead (a TOML file with a ``[parents]`` table).
    """
    kinds = {}
    for label in labels:
        if label.lower() in WORLD_NAMES:
            continue
        kind, side = _kind(label)
        if kind is None:
            raise MocapError(f"cannot tell the parent of segment {label!r} from its name; "
                             f"give the hierarchy with --segments FILE.toml "
                             f"([parents] {label} = \"<parent>\")", path)
        kinds[label] = (kind, side)
    by_kind = {(kind, side): label for label, (kind, side) in kinds.items()}
    roots = [label for label, (kind, _) in kinds.items() if kind == "pelvis"]
    if len(roots) != 1:
        raise MocapError(f"the segments name {len(roots)} pelvis segments; the root must be "
                         f"one (give the hierarchy with --segments FILE.toml)", path)
    parents: dict[str, str | None] = {}
    for label, (kind, side) in kinds.items():
        parent = None
        for parent_kind in _PARENT_KINDS[kind]:
            parent = by_kind.get((parent_kind, side)) or by_kind.get((parent_kind, ""))
            if parent:
                break
        if parent is None and kind != "pelvis":
            raise MocapError(f"segment {label!r} has no {'/'.join(_PARENT_KINDS[kind])} to "
                             f"hang from; give the hierarchy with --segments FILE.toml", path)
        parents[label] = parent
    return parents


def load_parents(path: str | os.PathLike) -> dict[str, str | None]:
    """A ``[parents]`` table from a TOML file: ``child = "parent"`` (``""`` for the root)."""
    document = parse_toml(read_text(path, "hierarchy file"), path, "hierarchy file")
    table = document.get("parents")
    if not isinstance(table, dict) or not table or \
            not all(isinstance(v, str) for v in table.values()):
        raise MocapError('needs a [parents] table of child = "parent" names ("" for the '
                         'root)', path)
    return {child: (parent or None) for child, parent in table.items()}


def poses_motion(poses: SegmentPoses, parents: dict[str, str | None], path=None):
    """A :class:`~mocap.skeleton.Motion` of the segments in ``parents`` (Z-up lab poses).

    Segments are ordered parents first; the root's pose is relative to the lab.
    """
    from mocap.body.retarget import motion_from_frames

    missing = [name for name in parents if name not in poses.labels]
    missing += [p for p in parents.values() if p and p not in parents]
    if missing:
        raise MocapError(f"the hierarchy names segments the file does not have: "
                         f"{', '.join(sorted(set(missing)))} (it has "
                         f"{', '.join(poses.labels)})", path)
    order: list[str] = []
    pending = dict(parents)
    while pending:
        ready = [name for name, parent in pending.items() if parent is None or parent in order]
        if not ready:
            raise MocapError("the hierarchy has a cycle: " + ", ".join(pending), path)
        for name in ready:
            order.append(name)
            del pending[name]
    if sum(parents[name] is None for name in order) != 1:
        raise MocapError("the hierarchy needs exactly one root", path)
    columns = [poses.labels.index(name) for name in order]
    parent_index = [order.index(parents[name]) if parents[name] else -1 for name in order]
    return motion_from_frames(poses.rotations[:, columns], poses.positions[:, columns],
                              order, parent_index, poses.rate, up="z")


def rotation_angles(trial, sequence: str = "ZXY", segments: str | os.PathLike | None = None):
    """Joint angles from a trial's segment poses (``mocap angles --from-rotations``).

    Parameters
    ----------
    trial : Trial
        With ``trial.poses`` (a C3D file's ROTATION group).
    sequence : str
        scipy Euler sequence.
    segments : path, optional
        TOML file with a ``[parents]`` table; default: :func:`segment_parents` of the
        names.

    Returns
    -------
    JointAngles
        One row of angles per segment relative to its parent (the root relative to the
        lab), degrees, as ``mocap angles`` writes them from markers (the one motion →
        angles code, :func:`mocap.body.angles.motion_joint_angles`); NaN where the segment
        or its parent was not tracked.
    """
    from mocap.body.angles import motion_joint_angles

    poses = trial.poses
    if poses is None:
        raise MocapError("the file has no segment poses (no ROTATION group): use "
                         "--markerset with its markers", trial.path)
    parents = load_parents(segments) if segments else segment_parents(poses.labels, trial.path)
    motion = poses_motion(poses, parents, trial.path)
    angles = motion_joint_angles(motion, sequence, body=False)
    tracked = np.isfinite(poses.rotations).all(axis=(2, 3))
    column = {name: poses.labels.index(name) for name in motion.names}
    for k, name in enumerate(motion.names):
        parent = motion.skeleton.parents[k]
        seen = tracked[:, column[name]]
        if parent >= 0:
            seen = seen & tracked[:, column[motion.names[parent]]]
        angles.values[~seen, k] = np.nan
    return angles
