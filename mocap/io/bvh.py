"""BVH (Biovision hierarchy) read and write.

Reads real files: any channel order per joint (``Zrotation Xrotation Yrotation``,
``Xposition …``), position channels on any joint, ``End Site`` blocks, tabs or spaces,
Windows line ends, Mixamo's ``mixamorig:`` names. Lengths become metres: the unit is
stated by the caller or detected from the size of the figure (see :func:`detect_units`).

A rotation channel list ``A B C`` means the joint's rotation relative to its parent is
``R_A(a) R_B(b) R_C(c)`` (intrinsic rotations, the order animation tools use), i.e. scipy
``Rotation.from_euler("ABC", …)`` with upper-case axes.

Examples
--------
>>> from mocap.io.bvh import read_bvh, write_bvh          # doctest: +SKIP
>>> motion = read_bvh("walk.bvh")                         # doctest: +SKIP
>>> write_bvh(motion, "copy.bvh")                         # doctest: +SKIP
"""
from __future__ import annotations

import io
import os
import re
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.angles import unwrap_columns
from mocap.atomic import atomic_path
from mocap.errors import MocapError
from mocap.skeleton import Motion, Skeleton, frame_rate

#: Metres per unit for the units a BVH file may use.
UNIT_SCALES = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254,
               "cmu": 0.0254 / 0.45}   # CMU ASF units converted to BVH as they are

_CHANNEL_RE = re.compile(r"^([xyz])(position|rotation)$", re.IGNORECASE)


def detect_units(extent: float) -> str:
    """The length unit of a figure whose rest pose spans ``extent`` file units.

    The extent is the largest side of the rest pose's bounding box (standing height or arm
    span), taken as a human's 0.5–2.5 m: below 4 → metres; 15–55 → CMU ASF units
    (1/0.45 inch, as in the cgspeed BVH conversion of the CMU database); 55–100 → inches;
    100–400 → centimetres; 400–4000 → millimetres.

    Raises
    ------
    ValueError
        When the extent fits none of these (a non-human figure: state the unit).
    """
    if 0.0 < extent < 4.0:
        return "m"
    if 15.0 <= extent < 55.0:
        return "cmu"
    if 55.0 <= extent < 100.0:
        return "in"
    if 100.0 <= extent < 400.0:
        return "cm"
    if 400.0 <= extent < 4000.0:
        return "mm"
    raise ValueError(f"a figure {extent:g} units tall fits no known unit")


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
            return float(token)
        except ValueError:
            raise MocapError(f"BVH hierarchy: {what} should be a number, found {token!r}",
                             self.path) from None

    def peek(self) -> str:
        return self.items[self.at] if self.at < len(self.items) else ""


def _parse_hierarchy(text: str, path: str | None):
    """Names, parents, offsets, end sites and channels of a BVH hierarchy section."""
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

    def joint(parent: int) -> None:
        name = tokens.next("a joint name")
        tokens.expect("{")
        index = len(names)
        names.append(name)
        parents.append(parent)
        offsets.append(offset())
        joint_channels: list[str] = []
        if tokens.peek().upper() == "CHANNELS":
            tokens.next("CHANNELS")
            count = int(tokens.number("the channel count"))
            for _ in range(count):
                channel = tokens.next("a channel name")
                if not _CHANNEL_RE.match(channel):
                    raise MocapError(f"BVH joint {name!r}: unknown channel {channel!r}", path)
                joint_channels.append(channel[0].upper() + channel[1:].lower())
        channels.append(joint_channels)
        while True:
            word = tokens.next("JOINT, End Site or '}'")
            upper = word.upper()
            if upper == "}":
                return
            if upper == "JOINT":
                joint(index)
            elif upper in ("END", "ENDSITE"):
                if upper == "END":
                    tokens.expect("Site")
                tokens.expect("{")
                ends[index] = offset()
                tokens.expect("}")
            else:
                raise MocapError(f"BVH joint {name!r}: unexpected {word!r}", path)

    word = tokens.next("ROOT")
    if word.upper() != "ROOT":
        raise MocapError(f"BVH hierarchy: expected ROOT, found {word!r}", path)
    joint(-1)
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
    """Frame count, frame time and the (frames, channels) values of the MOTION section."""
    frames_match = re.search(r"Frames\s*:\s*(\d+)", text, re.IGNORECASE)
    time_match = re.search(r"Frame\s+Time\s*:\s*([-+0-9.eE]+)", text, re.IGNORECASE)
    if not frames_match or not time_match:
        raise MocapError("BVH MOTION section lacks 'Frames:' or 'Frame Time:'", path)
    stated = int(frames_match.group(1))
    frame_time = float(time_match.group(1))
    if not frame_time > 0:
        raise MocapError(f"BVH frame time must be positive, found {frame_time:g}", path)
    body = text[time_match.end():]
    try:
        values = np.array(body.split(), dtype=float)
    except ValueError:
        bad = next(t for t in body.split() if not _is_number(t))
        raise MocapError(f"BVH motion data holds a non-number {bad!r}", path) from None
    if channel_count == 0:
        return np.zeros((stated, 0)), frame_time, stated
    complete = values.size // channel_count
    if values.size % channel_count and complete < stated:
        raise MocapError(f"BVH motion data is truncated: {values.size} values is not a whole "
                         f"number of frames of {channel_count} channels", path)
    frames = min(complete, stated) if stated else complete
    if frames == 0:
        raise MocapError("BVH file has no frames", path)
    return values[: frames * channel_count].reshape(frames, channel_count), frame_time, stated


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
        Length unit of the file; detected from the figure's size when not given
        (``motion.metadata["units"]`` and ``["units_detected"]`` say which).

    Returns
    -------
    Motion
        Skeleton with the file's joint names; ``metadata["bvh_channels"]`` keeps each
        joint's channel list so :func:`write_bvh` can write the same layout.

    Raises
    ------
    MocapError
        Unreadable file, malformed hierarchy, truncated motion data, unknown unit.
    """
    path = os.fspath(path)
    try:
        text = Path(path).read_text(encoding="utf-8", errors="replace")
    except OSError as error:
        raise MocapError(f"cannot read BVH file: {error.strerror or error}", path) from None
    split = re.search(r"^\s*MOTION\s*$", text, re.MULTILINE | re.IGNORECASE)
    if not split:
        raise MocapError("not a BVH file: no MOTION section", path)
    if not text.lstrip().upper().startswith("HIERARCHY"):
        raise MocapError("not a BVH file: it does not start with HIERARCHY", path)
    names, parents, offsets, end_sites, channels = _parse_hierarchy(text[:split.start()], path)
    total = sum(len(c) for c in channels)
    values, frame_time, stated = _parse_motion(text[split.end():], total, path)
    frames = values.shape[0]

    # Split the channel block per joint.
    translation = np.zeros((frames, len(names), 3))
    rotations = np.empty((frames, len(names), 3, 3))
    column = 0
    for j, joint_channels in enumerate(channels):
        block = values[:, column: column + len(joint_channels)]
        column += len(joint_channels)
        axes = ""
        angles = []
        for k, channel in enumerate(joint_channels):
            axis = "XYZ".index(channel[0])
            if channel.endswith("position"):
                translation[:, j, axis] = block[:, k]
            else:
                axes += channel[0]
                angles.append(block[:, k])
        if axes:
            if len(set(axes)) != len(axes):
                raise MocapError(f"BVH joint {names[j]!r} repeats a rotation channel", path)
            rotations[:, j] = Rotation.from_euler(axes, np.stack(angles, axis=1),
                                                  degrees=True).as_matrix()
        else:
            rotations[:, j] = np.eye(3)

    # Units: from the rest pose's size unless stated.
    detected = units is None
    if units is None:
        skeleton = Skeleton(names, parents, offsets, end_sites)
        rest = Motion.still(skeleton, 1, 1.0).all_points()[0]
        extent = float(np.ptp(rest, axis=0).max())
        try:
            units = detect_units(extent)
        except ValueError as error:
            raise MocapError(f"{error}; give the unit (units='cm', 'm', 'mm', 'in')",
                             path) from None
    if units not in UNIT_SCALES:
        raise MocapError(f"unknown BVH unit {units!r}: use one of {', '.join(UNIT_SCALES)}",
                         path)
    scale = UNIT_SCALES[units]

    # Position channels of non-root joints: fold their mean into the offset.
    moved = 0.0
    for j in range(1, len(names)):
        if any(c.endswith("position") for c in channels[j]):
            mean = translation[:, j].mean(axis=0)
            offsets[j] = offsets[j] + mean
            moved = max(moved, float(np.abs(translation[:, j] - mean).max()) * scale)
    skeleton = Skeleton(names, parents, offsets * scale, end_sites * scale)
    metadata = {
        "source": path, "format": "bvh", "units": units, "units_detected": detected,
        "bvh_channels": {n: list(c) for n, c in zip(names, channels)},
        "frames_stated": stated, "frame_time": frame_time,
    }
    if moved > 0:
        metadata["joint_translation_dropped_m"] = moved
    return Motion(skeleton, translation[:, 0] * scale, rotations, frame_rate(frame_time),
                  metadata)


def _joint_channels(motion: Motion, rotation_order: str) -> list[list[str]]:
    """Channel list per joint: the file's own when the motion came from BVH."""
    kept = motion.metadata.get("bvh_channels") or {}
    result = []
    for j, name in enumerate(motion.skeleton.names):
        channels = kept.get(name)
        if channels is None or (j == 0 and not any(c.endswith("position") for c in channels)):
            rotation = [f"{a}rotation" for a in rotation_order]
            channels = (["Xposition", "Yposition", "Zposition"] if j == 0 else []) + rotation
        result.append(list(channels))
    return result


def write_bvh(motion: Motion, path: str | os.PathLike, units: str = "cm",
              precision: int = 6, rotation_order: str = "ZXY") -> None:
    """Write a motion as a BVH file (all-or-nothing).

    Parameters
    ----------
    motion : Motion
    path : str or PathLike
    units : {"cm", "m", "mm", "in"}
        Length unit written (centimetres are what most animation tools expect).
    precision : int
        Decimals of every number written.
    rotation_order : str
        Rotation channel order (e.g. ``"ZXY"``) for joints whose layout is not already
        known from a BVH the motion was read from.
    """
    if units not in UNIT_SCALES:
        raise MocapError(f"unknown BVH unit {units!r}: use one of {', '.join(UNIT_SCALES)}")
    order = rotation_order.upper()
    if sorted(order) != ["X", "Y", "Z"]:
        raise MocapError(f"rotation order must be a permutation of XYZ, got {rotation_order!r}")
    scale = 1.0 / UNIT_SCALES[units]
    sk = motion.skeleton
    channels = _joint_channels(motion, order)
    fmt = f"%.{precision}f"

    def number(x: float) -> str:
        text = fmt % x
        return "0." + "0" * precision if text.startswith("-") and float(text) == 0 else text

    lines = ["HIERARCHY"]

    def joint(j: int, depth: int) -> None:
        pad = "  " * depth
        kind = "ROOT" if sk.parents[j] < 0 else "JOINT"
        lines.append(f"{pad}{kind} {sk.names[j]}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET " + " ".join(number(v * scale) for v in sk.offsets[j]))
        lines.append(f"{pad}  CHANNELS {len(channels[j])} " + " ".join(channels[j]))
        kids = sk.children(j)
        for child in kids:
            joint(child, depth + 1)
        if not kids:
            end = sk.end_sites[j]
            end = np.zeros(3) if not np.isfinite(end).all() else end
            lines.append(f"{pad}  End Site")
            lines.append(f"{pad}  {{")
            lines.append(f"{pad}    OFFSET " + " ".join(number(v * scale) for v in end))
            lines.append(f"{pad}  }}")
        lines.append(f"{pad}}}")

    joint(0, 0)
    lines += ["MOTION", f"Frames: {motion.frames}", f"Frame Time: {1.0 / motion.rate:.8f}"]

    columns = []
    for j, joint_channels in enumerate(channels):
        axes = "".join(c[0] for c in joint_channels if c.endswith("rotation"))
        angles = {}
        if axes:
            euler = Rotation.from_matrix(motion.rotations[:, j]).as_euler(axes, degrees=True)
            euler = unwrap_columns(euler)
            angles = {axis: euler[:, k] for k, axis in enumerate(axes)}
        for channel in joint_channels:
            axis = channel[0]
            if channel.endswith("rotation"):
                columns.append(angles[axis])
            elif j == 0:
                columns.append(motion.root_translation[:, "XYZ".index(axis)] * scale)
            else:
                columns.append(np.zeros(motion.frames))
    table = np.stack(columns, axis=1) if columns else np.zeros((motion.frames, 0))
    table[np.abs(table) < 0.5 * 10.0 ** -precision] = 0.0     # no "-0.000000"
    buffer = io.StringIO()
    np.savetxt(buffer, table, fmt=fmt, delimiter=" ")
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n" + buffer.getvalue(), encoding="utf-8")
