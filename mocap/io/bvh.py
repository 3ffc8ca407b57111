"""BVH (Biovision hierarchy) read and write.

Reads real files: any channel order per joint (``Zrotation Xrotation Yrotation``,
``Xposition …``), position channels on any joint, ``End Site`` blocks, tabs or spaces,
Windows line ends, Mixamo's ``mixamorig:`` names. Lengths become metres: the unit is
stated by the caller or detected from the standing height of the first frame's figure
(see :func:`detect_units`).

Conventions (those of Blender's importer and of ``bvhio``):

* A rotation channel list ``A B C`` means the joint's rotation relative to its parent is
  ``R_A(a) R_B(b) R_C(c)`` (intrinsic rotations), i.e. scipy
  ``Rotation.from_euler("ABC", …)`` with upper-case axes.
* Position channels on *any* joint are that joint's local translation in its parent's
  frame on that frame: each one *replaces* the OFFSET value of its axis (they are not
  added to it). On the root this puts the joint where its channels say, whatever its
  OFFSET; on other joints (Bandai Namco, some MotionBuilder exports) the bones take the
  channels' lengths, frame by frame (``Motion.translations``).

Examples
--------
>>> from mocap.io.bvh import read_bvh, write_bvh          # doctest: +SKIP
>>> motion = read_bvh("walk.bvh")                         # doctest: +SKIP
>>> write_bvh(motion, "copy.bvh", units="m")              # doctest: +SKIP
"""
from __future__ import annotations

import io
import math
import os
import re
from pathlib import Path

import numpy as np

from mocap.rotations.angles import unwrap_columns
from mocap.atomic import atomic_path
from mocap.errors import MocapError, reading
from mocap.io.c3d.read import unique_labels
from mocap.skeleton import Motion, Skeleton, frame_rate

#: Metres per unit for the units a BVH file may use.
UNIT_SCALES = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254,
               "cmu": 0.0254 / 0.45}   # CMU ASF units converted to BVH as they are

#: Limits of what a BVH may declare (a human rig has tens, a face rig a few hundred joints).
MAX_JOINTS = 5000
MAX_DEPTH = 500
#: Most joint-frames read (frames × joints): 100 000 frames of a 200-joint rig; about
#: 2 GB of rotations and translations in memory.
MAX_JOINT_FRAMES = 20_000_000
#: Largest magnitude of any OFFSET or channel value (file units or degrees).
MAX_VALUE = 1e9
#: Frame times accepted, seconds (0.1 MHz to one frame every 100 s).
FRAME_TIME_RANGE = (1e-5, 100.0)

_CHANNEL_RE = re.compile(r"^([xyz])(position|rotation)$", re.IGNORECASE)


def detect_units(extent: float) -> str:
    """The length unit of a human figure ``extent`` file units tall.

    The extent is the standing height (or, for a lying figure, the largest side of its
    bounding box), taken as a human's 0.5–2.5 m: below 4 → metres; 15–40 → CMU ASF units
    (1/0.45 inch, as in the cgspeed BVH conversion of the CMU database: 0.85–2.26 m);
    40–100 → inches (1.02–2.54 m); 100–400 → centimetres; 400–4000 → millimetres. A rig
    without a head-top end site measures only to its head joint (about 0.87 of the
    height), which these ranges allow for.

    Raises
    ------
    ValueError
        When the extent fits none of these (a non-human figure: state the unit).
    """
    if 0.0 < extent < 4.0:
        return "m"
    if 15.0 <= extent < 40.0:
        return "cmu"
    if 40.0 <= extent < 100.0:
        return "in"
    if 100.0 <= extent < 400.0:
        return "cm"
    if 400.0 <= extent < 4000.0:
        return "mm"
    raise ValueError(f"a figure {extent:g} units tall fits no known unit")


def standing_height(points: np.ndarray) -> float:
    """The height of a figure from its joint and end-site positions, (points, 3), Y up.

    The vertical (Y) extent; when that is under a fifth of the largest side of the bounding
    box (a Z-up file or a lying figure), the largest side.
    """
    points = points[np.isfinite(points).all(axis=1)]
    if points.size == 0:
        return 0.0
    sides = np.ptp(points, axis=0)
    return float(sides[1] if sides[1] >= 0.2 * sides.max() else sides.max())


class _Tokens:
    """Whitespace tokens of the hierarchy with a cursor and good error messages."""

    def __init__(self, text: str, path: str | None):
        self.items = text.split()
        self.at = 0
        self.path = path

    def next(self, what: str) -> str:
        if self.at >= len(self.items):
            raise MocapError(f"BVH hierarchy ends early: expected {what}", self.path)
        token = self.items[self.at]
        self.at += 1
        return token

    def expect(self, word: str) -> None:
        token = self.next(repr(word))
        if token.upper() != word.upper():
            raise MocapError(f"BVH hierarchy: expected {word!r}, found {token!r}", self.path)

    def number(self, what: str) -> float:
        token = self.next(what)
        try:
            value = float(token)
        except ValueError:
            raise MocapError(f"BVH hierarchy: {what} should be a number, found {token!r}",
                             self.path) from None
        if not (math.isfinite(value) and abs(value) <= MAX_VALUE):
            raise MocapError(f"BVH hierarchy: {what} must be finite and within ±{MAX_VALUE:g},"
                             f" found {token!r}", self.path)
        return value

    def peek(self) -> str:
        return self.items[self.at] if self.at < len(self.items) else ""


def _parse_hierarchy(text: str, path: str | None):
    """Names, parents, offsets, end sites and channels of a BVH hierarchy section.

    Iterative (a stack, no recursion), so deep hierarchies cannot overflow Python's stack;
    more than :data:`MAX_JOINTS` joints or nesting deeper than :data:`MAX_DEPTH` is refused.
    """
    tokens = _Tokens(text, path)
    tokens.expect("HIERARCHY")
    names: list[str] = []
    parents: list[int] = []
    offsets: list[list[float]] = []
    ends: dict[int, list[float]] = {}
    channels: list[list[str]] = []

    def offset() -> list[float]:
        tokens.expect("OFFSET")
        return [tokens.number("an OFFSET value") for _ in range(3)]

    def start_joint(parent: int) -> int:
        name = tokens.next("a joint name")
        if len(names) >= MAX_JOINTS:
            raise MocapError(f"BVH hierarchy has more than {MAX_JOINTS} joints (the limit)",
                             path)
        tokens.expect("{")
        index = len(names)
        names.append(name)
        parents.append(parent)
        offsets.append(offset())
        joint_channels: list[str] = []
        if tokens.peek().upper() == "CHANNELS":
            tokens.next("CHANNELS")
            count = tokens.number("the channel count")
            if count != int(count) or not 0 <= count <= 6:
                raise MocapError(f"BVH joint {name!r}: channel count must be 0 to 6, found "
                                 f"{count:g}", path)
            for _ in range(int(count)):
                channel = tokens.next("a channel name")
                if not _CHANNEL_RE.match(channel):
                    raise MocapError(f"BVH joint {name!r}: unknown channel {channel!r}", path)
                joint_channels.append(channel[0].upper() + channel[1:].lower())
            if len(set(joint_channels)) != len(joint_channels):
                raise MocapError(f"BVH joint {name!r} repeats a channel", path)
        channels.append(joint_channels)
        return index

    word = tokens.next("ROOT")
    if word.upper() != "ROOT":
        raise MocapError(f"BVH hierarchy: expected ROOT, found {word!r}", path)
    stack = [start_joint(-1)]
    while stack:
        word = tokens.next(f"JOINT, End Site or '}}' in joint {names[stack[-1]]!r}")
        upper = word.upper()
        if upper == "}":
            stack.pop()
        elif upper == "JOINT":
            if len(stack) >= MAX_DEPTH:
                raise MocapError(f"BVH hierarchy nests joints deeper than {MAX_DEPTH} (the "
                                 "limit)", path)
            stack.append(start_joint(stack[-1]))
        elif upper in ("END", "ENDSITE"):
            if upper == "END":
                tokens.expect("Site")
            tokens.expect("{")
            ends[stack[-1]] = offset()
            tokens.expect("}")
        else:
            raise MocapError(f"BVH joint {names[stack[-1]]!r}: unexpected {word!r}", path)
    if tokens.peek().upper() == "ROOT":
        raise MocapError("BVH files with several ROOT joints are not supported", path)
    if tokens.peek():
        raise MocapError(f"BVH hierarchy: unexpected {tokens.peek()!r} after the root joint",
                         path)
    end_sites = np.full((len(names), 3), np.nan)
    for index, value in ends.items():
        end_sites[index] = value
    return names, parents, np.array(offsets, float), end_sites, channels


def _parse_motion(text: str, channel_count: int, path: str | None):
    """Values (frames, channels), frame time, its text and the frame count stated.

    Every motion line must hold one value per channel; fewer complete lines than the
    header states is a truncated file; lines beyond it are ignored (as bvhio and Blender
    do) with a warning.
    """
    frames_match = re.search(r"Frames\s*:\s*(\S+)", text, re.IGNORECASE)
    time_match = re.search(r"Frame\s+Time\s*:\s*(\S+)", text, re.IGNORECASE)
    if not frames_match or not time_match or time_match.start() < frames_match.end():
        raise MocapError("BVH MOTION section lacks 'Frames:' and then 'Frame Time:'", path)
    try:
        stated = int(frames_match.group(1))
    except ValueError:
        raise MocapError(f"BVH 'Frames:' must be a whole number, found "
                         f"{frames_match.group(1)!r}", path) from None
    time_text = time_match.group(1)
    try:
        frame_time = float(time_text)
    except ValueError:
        raise MocapError(f"BVH 'Frame Time:' must be a number, found {time_text!r}",
                         path) from None
    low, high = FRAME_TIME_RANGE
    if not low <= frame_time <= high:       # also NaN and inf
        raise MocapError(f"BVH frame time must be {low:g} to {high:g} s, found {time_text}",
                         path)
    if stated <= 0:
        raise MocapError(f"BVH file states {stated} frames: nothing to read", path)
    if channel_count == 0:
        raise MocapError("BVH hierarchy declares no channels: nothing moves", path)
    lines = [line for line in text[time_match.end():].splitlines() if line.strip()]
    warnings = []
    if len(lines) < stated:
        raise MocapError(f"BVH motion section is truncated: the header states {stated} "
                         f"frames, the file holds {len(lines)} lines", path)
    if len(lines) > stated:
        warnings.append(f"{len(lines) - stated} motion lines after the {stated} frames the "
                        "header states were ignored")
        lines = lines[:stated]
    rows = [line.split() for line in lines]
    counts = np.fromiter(map(len, rows), int, len(rows))
    wrong = np.flatnonzero(counts != channel_count)
    if wrong.size:
        k = int(wrong[0])
        raise MocapError(f"BVH motion line {k + 1} has {counts[k]} values, the hierarchy "
                         f"declares {channel_count} channels", path)
    try:
        values = np.array(rows, dtype=float)
    except ValueError:
        bad = next((t for row in rows for t in row if not _is_number(t)), "?")
        raise MocapError(f"BVH motion data holds a non-number {bad!r}", path) from None
    finite = np.isfinite(values) & (np.abs(values) <= MAX_VALUE)
    if not finite.all():
        frame, column = (int(v[0]) for v in np.nonzero(~finite))
        raise MocapError(f"BVH motion data holds {values[frame, column]} on frame "
                         f"{frame + 1}, channel {column + 1} (values must be finite and "
                         f"within ±{MAX_VALUE:g})", path)
    return values, frame_time, time_text, stated, warnings


def _is_number(token: str) -> bool:
    try:
        float(token)
        return True
    except ValueError:
        return False


def read_bvh(path: str | os.PathLike, units: str | None = None) -> Motion:
    """Read a BVH file into a :class:`~mocap.skeleton.Motion` (metres, Y up).

    Parameters
    ----------
    path : str or PathLike
    units : {"m", "cm", "mm", "in", "cmu"}, optional
        Length unit of the file; detected from the standing height of the first frame's
        figure (OFFSETs and position channels together) when not given
        (``motion.metadata["units"]``, ``["units_detected"]`` and ``["height_file_units"]``).

    Returns
    -------
    Motion
        Skeleton with the file's joint names and OFFSETs; ``translations`` per frame when
        non-root joints have position channels; ``metadata["bvh_channels"]`` keeps each
        joint's channel list so :func:`write_bvh` can write the same layout.

    Raises
    ------
    MocapError
        Unreadable file, malformed hierarchy, motion lines that disagree with the channels,
        a truncated motion section, non-finite values, an unknown unit.
    """
    from scipy.spatial.transform import Rotation   # deferred: 0.4 s to import
    path = os.fspath(path)
    with reading(path, "BVH file"):
        # utf-8-sig: a byte-order mark (as Windows editors write) is not part of the text
        text = Path(path).read_text(encoding="utf-8-sig", errors="replace")
    if not text.lstrip().upper().startswith("HIERARCHY"):
        raise MocapError("not a BVH file: it does not start with HIERARCHY", path)
    split = re.search(r"^\s*MOTION\s*$", text, re.MULTILINE | re.IGNORECASE)
    if not split:
        raise MocapError("not a BVH file: no MOTION section", path)
    names, parents, offsets, end_sites, channels = _parse_hierarchy(text[:split.start()], path)
    total = sum(len(c) for c in channels)
    values, frame_time, time_text, stated, warnings = _parse_motion(
        text[split.end():], total, path)
    # a repeated joint name would make joints unaddressable (and merge their channel lists)
    names, notes = unique_labels(names)
    warnings += [f"joint names: {note}" for note in notes]
    frames = values.shape[0]
    if frames * len(names) > MAX_JOINT_FRAMES:
        raise MocapError(f"BVH motion of {frames} frames × {len(names)} joints is beyond the "
                         f"limit of {MAX_JOINT_FRAMES:,} joint-frames; cut it into parts", path)

    # Split the channel block per joint: local translations (OFFSET replaced axis by axis
    # by position channels) and rotations.
    local = np.broadcast_to(offsets, (frames, len(names), 3)).copy()
    rotations = np.empty((frames, len(names), 3, 3))
    column = 0
    for j, joint_channels in enumerate(channels):
        block = values[:, column: column + len(joint_channels)]
        column += len(joint_channels)
        axes = ""
        angles = []
        for k, channel in enumerate(joint_channels):
            if channel.endswith("position"):
                local[:, j, "XYZ".index(channel[0])] = block[:, k]
            else:
                axes += channel[0]
                angles.append(block[:, k])
        if axes:
            rotations[:, j] = Rotation.from_euler(axes, np.stack(angles, axis=1),
                                                  degrees=True).as_matrix()
        else:
            rotations[:, j] = np.eye(3)
    moving = any(c.endswith("position") for joint in channels[1:] for c in joint)

    def motion(scale: float, first: int | None = None) -> Motion:
        cut = slice(None) if first is None else slice(0, first)
        skeleton = Skeleton(names, parents, offsets * scale, end_sites * scale)
        return Motion(skeleton, (local[cut, 0] - offsets[0]) * scale, rotations[cut],
                      frame_rate(frame_time), translations=local[cut] * scale if moving
                      else None)

    # Units: from the standing height of the first frame's figure unless stated.
    height = standing_height(motion(1.0, first=1).all_points()[0])
    detected = units is None
    if units is None:
        try:
            units = detect_units(height)
        except ValueError as error:
            raise MocapError(f"{error}; give the unit (units= cm, m, mm, in or cmu)",
                             path) from None
    if units not in UNIT_SCALES:
        raise MocapError(f"unknown BVH unit {units!r}: use one of {', '.join(UNIT_SCALES)}",
                         path)
    result = motion(UNIT_SCALES[units])
    result.metadata = {
        "source": path, "format": "bvh", "units": units, "units_detected": detected,
        "height_file_units": height,
        "bvh_channels": {n: list(c) for n, c in zip(names, channels)},
        "frames_stated": stated, "frame_time": frame_time, "frame_time_text": time_text,
        "warnings": warnings,
    }
    return result


def units_note(motion: Motion) -> str | None:
    """One line for the user saying which length unit a BVH/ASF motion was read in."""
    units = motion.metadata.get("units")
    if not units:
        return None
    height = motion.metadata.get("height_file_units")
    how = "detected" if motion.metadata.get("units_detected") else "as given"
    if motion.metadata.get("units_detected") and height is not None:
        how = f"detected from a standing height of {height:.4g} file units"
    return f"units: {units} ({how}; units= overrides)"


# ----------------------------------------------------------------------------------------
# Writing
# ----------------------------------------------------------------------------------------
def _joint_channels(motion: Motion, rotation_order: str) -> list[list[str]]:
    """Channel list per joint: the file's own when the motion came from BVH.

    Joints without a known layout get rotations in ``rotation_order`` (and the root
    position channels); a joint the motion translates (the root away from its OFFSET,
    another joint away from its offset) gets the position channels its layout lacks.
    """
    kept = motion.metadata.get("bvh_channels") or {}
    sk = motion.skeleton
    axes_moved = np.zeros((sk.count, 3), bool)        # joint, axis: away from the offset
    if motion.translations is not None and motion.frames:
        axes_moved = np.abs(motion.translations - sk.offsets).max(axis=0) > 1e-12
    if motion.frames:
        axes_moved[0] = np.abs(motion.root_translation).max(axis=0) > 1e-12
    moved = axes_moved.any(axis=1)
    position = ["Xposition", "Yposition", "Zposition"]
    result = []
    for j, name in enumerate(sk.names):
        channels = kept.get(name)
        rotation = [f"{a}rotation" for a in rotation_order]
        if channels is None:
            channels = (position if j == 0 or moved[j] else []) + rotation
        else:
            # Axes the motion moves this joint along but the file's layout has no channel for.
            lacking = [p for k, p in enumerate(position) if axes_moved[j, k]
                       and p not in channels]
            channels = lacking + list(channels)
        result.append(list(channels))
    return result


def _frame_time_text(motion: Motion, round_rate: bool) -> str:
    """The 'Frame Time:' value: the file's own text when the rate is unchanged, else the
    shortest decimal giving the rate back exactly."""
    text = motion.metadata.get("frame_time_text")
    stored = motion.metadata.get("frame_time")
    if not round_rate and text and stored and frame_rate(float(stored)) == motion.rate:
        return str(text)
    return repr(1.0 / motion.rate)


_AXES = {"X": np.array([1.0, 0.0, 0.0]), "Y": np.array([0.0, 1.0, 0.0]),
          "Z": np.array([0.0, 0.0, 1.0])}


def _euler_columns(rotations: np.ndarray, axes: str) -> list[np.ndarray]:
    """Angles (degrees, unwrapped over frames) of rotations (frames, 3, 3) about ``axes``
    (1 to 3 of X, Y, Z, intrinsic: R = R_A(a) R_B(b) …)."""
    from scipy.spatial.transform import Rotation   # deferred: 0.4 s to import
    if len(axes) == 3:
        euler = Rotation.from_matrix(rotations).as_euler(axes, degrees=True)
        result = [euler[:, k] for k in range(3)]
    elif len(axes) == 2:
        first, second = _AXES[axes[0]], _AXES[axes[1]]
        moved = rotations @ second                    # R e_B = R_A(a) e_B
        a = np.arctan2(np.cross(second, moved) @ first, moved @ second)
        rest = Rotation.from_rotvec(-a[:, None] * first) * Rotation.from_matrix(rotations)
        b = rest.as_rotvec() @ second
        result = [np.degrees(a), np.degrees(b)]
    else:
        result = [np.degrees(Rotation.from_matrix(rotations).as_rotvec() @ _AXES[axes])]
    unwrapped = unwrap_columns(np.stack(result, axis=1))
    return [unwrapped[:, k] for k in range(len(result))]


def _holds(rotations: np.ndarray, axes: str, tolerance: float = 1e-9) -> bool:
    """Whether rotations (frames, 3, 3) are rotations about ``axes`` only (in that order)."""
    if not axes:
        return bool(np.abs(rotations - np.eye(3)).max() <= tolerance)
    from scipy.spatial.transform import Rotation   # deferred: 0.4 s to import
    rebuilt = np.broadcast_to(np.eye(3), rotations.shape).copy()
    for axis, angle in zip(axes, _euler_columns(rotations, axes)):
        rebuilt = rebuilt @ Rotation.from_rotvec(np.radians(angle)[:, None] * _AXES[axis]
                                                 ).as_matrix()
    return bool(np.abs(rebuilt - rotations).max() <= tolerance)


def write_bvh(motion: Motion, path: str | os.PathLike, units: str = "cm",
              precision: int = 6, rotation_order: str = "ZXY",
              round_rate: bool = False) -> None:
    """Write a motion as a BVH file (all-or-nothing).

    The root's position channels hold its world position (its OFFSET is its rest
    position, which Blender and bvhio replace by the channels); joints the motion
    translates per frame keep position channels with their local translations.

    Parameters
    ----------
    motion : Motion
    path : str or PathLike
    units : {"cm", "m", "mm", "in", "cmu"}
        Length unit written (centimetres are what most animation tools expect; Blender
        works in metres).
    precision : int
        Decimals of every number written (0–15).
    rotation_order : str
        Rotation channel order (e.g. ``"ZXY"``) for joints whose layout is not already
        known from a BVH the motion was read from.
    round_rate : bool
        Resample the motion to the nearest whole frame rate (Hz) first; by default the
        rate is kept exactly.
    """
    if units not in UNIT_SCALES:
        raise MocapError(f"unknown BVH unit {units!r}: use one of {', '.join(UNIT_SCALES)}")
    if not (isinstance(precision, int) and 0 <= precision <= 15):
        raise MocapError(f"BVH precision must be 0 to 15 decimals, got {precision!r}")
    order = rotation_order.upper()
    if sorted(order) != ["X", "Y", "Z"]:
        raise MocapError(f"rotation order must be a permutation of XYZ, got {rotation_order!r}")
    if round_rate and motion.rate != round(motion.rate):
        motion = motion.resampled(float(max(1, round(motion.rate))))
    scale = 1.0 / UNIT_SCALES[units]
    sk = motion.skeleton
    channels = _joint_channels(motion, order)
    for j, joint_channels in enumerate(channels):
        axes = "".join(c[0] for c in joint_channels if c.endswith("rotation"))
        if len(axes) < 3 and not _holds(motion.rotations[:, j], axes):
            channels[j] = joint_channels + [f"{a}rotation" for a in order if a not in axes]
    fmt = f"%.{precision}f"

    def number(x: float) -> str:
        text = fmt % x
        return fmt % 0.0 if float(text) == 0 else text

    kids: list[list[int]] = [[] for _ in range(sk.count)]
    for j, p in enumerate(sk.parents):
        if p >= 0:
            kids[p].append(j)
    lines = ["HIERARCHY"]
    # Depth-first without recursion: ("open", joint, depth) / ("close", joint, depth).
    stack: list[tuple[str, int, int]] = [("open", 0, 0)]
    while stack:
        action, j, depth = stack.pop()
        pad = "  " * depth
        if action == "close":
            lines.append(f"{pad}}}")
            continue
        kind = "ROOT" if sk.parents[j] < 0 else "JOINT"
        lines.append(f"{pad}{kind} {sk.names[j]}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET " + " ".join(number(v * scale) for v in sk.offsets[j]))
        lines.append(f"{pad}  CHANNELS {len(channels[j])} " + " ".join(channels[j]))
        if not kids[j]:
            end = sk.end_sites[j]
            end = np.zeros(3) if not np.isfinite(end).all() else end
            lines += [f"{pad}  End Site", f"{pad}  {{",
                      f"{pad}    OFFSET " + " ".join(number(v * scale) for v in end),
                      f"{pad}  }}"]
        stack.append(("close", j, depth))
        stack.extend(("open", k, depth + 1) for k in reversed(kids[j]))
    lines += ["MOTION", f"Frames: {motion.frames}",
              f"Frame Time: {_frame_time_text(motion, round_rate)}"]

    local = motion.local_translations()
    columns = []
    for j, joint_channels in enumerate(channels):
        axes = "".join(c[0] for c in joint_channels if c.endswith("rotation"))
        angles = dict(zip(axes, _euler_columns(motion.rotations[:, j], axes))) if axes else {}
        for channel in joint_channels:
            if channel.endswith("rotation"):
                columns.append(angles[channel[0]])
            else:
                columns.append(local[:, j, "XYZ".index(channel[0])] * scale)
    table = np.stack(columns, axis=1) if columns else np.zeros((motion.frames, 0))
    table[np.abs(table) < 0.5 * 10.0 ** -precision] = 0.0     # no "-0.000000"
    if not np.isfinite(table).all():
        raise MocapError("the motion holds non-finite values: nothing written", path)
    buffer = io.StringIO()
    np.savetxt(buffer, table, fmt=fmt, delimiter=" ")
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n" + buffer.getvalue(), encoding="utf-8")
