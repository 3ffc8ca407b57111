"""Acclaim ASF (skeleton) and AMC (motion) reader, the format of the CMU and HDM05 databases.

ASF gives each bone a direction and length in the rest pose (world axes), a local axis
frame ``C`` (Euler angles in the order stated after them, e.g. ``axis 0 0 20 XYZ``) and its
degrees of freedom (``dof rx ry rz``). An AMC frame gives the dof values; a bone's world
rotation is ``G = G_parent · C · M · C⁻¹`` with ``M`` the dof rotations applied in the order
listed (``rx ry rz`` → ``Rz Ry Rx``), the root's ``G = C_root · M_root · C_root⁻¹``. A bone
starts where its parent ends, so the rest pose needs no other information.

Units: ``:units length L`` means lengths were multiplied by L from inches (CMU: 0.45), so a
value v is v / L inches; ``angle deg|rad``. Y is up, as in :class:`~mocap.skeleton.Motion`.
The AMC format stores no frame rate: CMU and HDM05 capture at 120 Hz, the default.
"""
from __future__ import annotations

import os
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mocap.errors import MocapError, MocapWarning, reading
from mocap.io.bvh import MAX_DEPTH, MAX_JOINT_FRAMES, MAX_JOINTS, UNIT_SCALES, detect_units
from mocap.skeleton import Motion, Skeleton


#: Largest magnitude of an AMC value (degrees, radians or file lengths): beyond it a value is
#: corrupt, and a rotation of 1e300 degrees has no meaningful remainder.
AMC_MAX_VALUE = 1e6


@dataclass
class AsfBone:
    """One bone of an ASF skeleton (lengths in file units, angles as in the file)."""

    name: str
    direction: np.ndarray
    length: float
    axis: np.ndarray
    axis_order: str
    dof: list[str] = field(default_factory=list)


@dataclass
class AsfSkeleton:
    """A parsed ASF file."""

    name: str
    length_multiplier: float
    angle_unit: str
    root_order: list[str]
    root_axis_order: str
    root_position: np.ndarray
    root_orientation: np.ndarray
    bones: dict[str, AsfBone]
    parent: dict[str, str]          # bone → parent bone ("root" for the root's children)
    order: list[str]                # bones, parents before children


def _numbers(words: list[str], count: int, what: str, path: str) -> np.ndarray:
    try:
        values = np.array([float(w) for w in words[:count]])
    except ValueError:
        raise MocapError(f"ASF {what}: expected {count} numbers, found {' '.join(words)!r}",
                         path) from None
    if values.size != count:
        raise MocapError(f"ASF {what}: expected {count} numbers, found {values.size}", path)
    if not np.isfinite(values).all():
        raise MocapError(f"ASF {what}: values must be finite numbers, found "
                         f"{' '.join(words[:count])!r}", path)
    return values


def _check_bone(bone: dict, path: str) -> None:
    """A bone's length must be >= 0 and, when it is not 0, its direction a non-zero vector
    (the rest pose places the bone's end at ``direction / |direction| * length``)."""
    if bone["length"] < 0:
        raise MocapError(f"ASF bone {bone['name']!r}: length must be >= 0, found "
                         f"{bone['length']:g}", path)
    if bone["length"] > 0 and not np.linalg.norm(bone["direction"]) > 0:
        raise MocapError(f"ASF bone {bone['name']!r}: direction 0 0 0 points nowhere", path)


def read_asf(path: str | os.PathLike) -> AsfSkeleton:
    """Parse an ASF skeleton file.

    Raises
    ------
    MocapError
        Unreadable file, missing sections, a bone without direction or length, a hierarchy
        naming unknown bones or forming a cycle.
    """
    path = os.fspath(path)
    with reading(path, "ASF file"):
        lines = Path(path).read_text(encoding="utf-8-sig", errors="replace").splitlines()
    section = None
    name = "asf"
    length, angle = 1.0, "deg"
    root = {"order": ["TX", "TY", "TZ", "RX", "RY", "RZ"], "axis": "XYZ",
            "position": np.zeros(3), "orientation": np.zeros(3)}
    bones: dict[str, AsfBone] = {}
    current: dict | None = None
    parent: dict[str, str] = {}
    children_of: dict[str, list[str]] = {}
    for number, raw in enumerate(lines, 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        words = line.split()
        head = words[0].lower()
        if head.startswith(":"):
            section = head[1:]
            if section == "name" and len(words) > 1:
                name = " ".join(words[1:])
            continue
        if section == "units" and len(words) >= 2:
            if head == "length":
                length = float(_numbers(words[1:], 1, "length unit", path)[0])
                if not length > 0:
                    raise MocapError(f"ASF :units length must be > 0 (file lengths are inches "
                                     f"times it), found {words[1]!r}", path)
            elif head == "angle":
                angle = words[1].lower()
        elif section == "root":
            if head == "order":
                root["order"] = _names(words[1:], ROOT_CHANNELS, "root order", number, path)
            elif head == "axis":
                root["axis"] = _axis_order(words[1:2], number, path)
            elif head == "position":
                root["position"] = _numbers(words[1:], 3, "root position", path)
            elif head == "orientation":
                root["orientation"] = _numbers(words[1:], 3, "root orientation", path)
        elif section == "bonedata":
            if head == "begin":
                current = {"dof": []}
            elif head == "end":
                if current is None or "name" not in current:
                    raise MocapError("ASF bone without a name", path)
                for key in ("direction", "length"):
                    if key not in current:
                        raise MocapError(f"ASF bone {current['name']!r} has no {key}", path)
                _check_bone(current, path)
                bones[current["name"]] = AsfBone(
                    current["name"], current["direction"], current["length"],
                    current.get("axis", np.zeros(3)), current.get("axis_order", "XYZ"),
                    current["dof"])
                current = None
            elif current is not None:
                if head == "name":
                    current["name"] = words[1]
                elif head == "direction":
                    current["direction"] = _numbers(words[1:], 3, "bone direction", path)
                elif head == "length":
                    current["length"] = float(_numbers(words[1:], 1, "bone length", path)[0])
                elif head == "axis":
                    current["axis"] = _numbers(words[1:], 3, "bone axis", path)
                    current["axis_order"] = _axis_order(words[4:5], number, path)
                elif head == "dof":
                    current["dof"] = [w.lower() for w in
                                      _names(words[1:], BONE_DOFS, "dof", number, path)]
        elif section == "hierarchy":
            if head in ("begin", "end"):
                continue
            children_of.setdefault(words[0], []).extend(words[1:])
            for child in words[1:]:
                parent[child] = words[0]
    if not bones:
        raise MocapError("not an ASF file: no :bonedata bones", path)
    unknown = [b for b in parent if b not in bones] + \
        [p for p in children_of if p != "root" and p not in bones]
    if unknown:
        raise MocapError(f"ASF hierarchy names unknown bones: {', '.join(sorted(set(unknown)))}",
                         path)
    if len(bones) >= MAX_JOINTS:
        raise MocapError(f"ASF skeleton has {len(bones)} bones, more than {MAX_JOINTS - 1} "
                         f"(the limit of a skeleton, as for BVH)", path)
    order: list[str] = []
    seen: set[str] = set()
    stack = [(child, 1) for child in reversed(children_of.get("root", []))]
    while stack:
        bone, depth = stack.pop()
        if bone in seen:
            raise MocapError(f"ASF hierarchy has a cycle through {bone!r}", path)
        if depth > MAX_DEPTH:
            raise MocapError(f"ASF hierarchy nests bones deeper than {MAX_DEPTH} (the limit, "
                             f"as for BVH) at {bone!r}", path)
        seen.add(bone)
        order.append(bone)
        stack.extend((child, depth + 1) for child in reversed(children_of.get(bone, [])))
    if angle not in ("deg", "rad"):
        raise MocapError(f"ASF angle unit must be deg or rad, found {angle!r}", path)
    return AsfSkeleton(name, length, angle, root["order"], root["axis"], root["position"],
                       root["orientation"], bones, parent, order)


#: Channels of the root's ``order`` line and of a bone's ``dof`` line (upper case here;
#: ``l`` is a bone's change of length, which Acclaim allows).
ROOT_CHANNELS = ("TX", "TY", "TZ", "RX", "RY", "RZ")
BONE_DOFS = ("RX", "RY", "RZ", "TX", "TY", "TZ", "L")


def _names(words: list[str], known: tuple[str, ...], what: str, line: int, path) -> list[str]:
    """``words`` in upper case, each one of ``known`` and none twice (else MocapError
    naming the line)."""
    names = [w.upper() for w in words]
    unknown = [w for w, n in zip(words, names) if n not in known]
    if unknown:
        raise MocapError(f"ASF line {line}: unknown {what} {unknown[0]!r} (known: "
                         f"{' '.join(k.lower() if what == 'dof' else k for k in known)})", path)
    twice = next((w for i, w in enumerate(names) if w in names[:i]), None)
    if twice is not None:
        raise MocapError(f"ASF line {line}: {what} {twice!r} given twice", path)
    return names


def _axis_order(words: list[str], line: int, path) -> str:
    """An ``axis`` line's rotation order (default XYZ), checked to be a permutation of XYZ."""
    order = words[0].upper() if words else "XYZ"
    if sorted(order) != ["X", "Y", "Z"]:
        raise MocapError(f"ASF line {line}: axis order {words[0]!r} is not an order of "
                         f"X, Y and Z (such as XYZ)", path)
    return order


#: A line holding only a frame number (ASCII digits: ``str.isdigit`` below takes others too,
#: which can only make the count low, never the limit wrong by more).
_FRAME_NUMBER = re.compile(r"^[ \t]*[0-9]+[ \t]*\r?$", re.MULTILINE)


def read_amc(path: str | os.PathLike, asf: AsfSkeleton) -> tuple[dict[str, np.ndarray], str]:
    """Parse an AMC motion file against its skeleton.

    Returns
    -------
    values : dict
        Bone (and ``"root"``) → (frames, dof count) array in file units; bones a frame does
        not list are 0 in that frame.
    angle_unit : {"deg", "rad"}
        From ``:DEGREES``/``:RADIANS`` in the AMC header, else the ASF's.
    """
    path = os.fspath(path)
    with reading(path, "AMC file"):
        text = Path(path).read_text(encoding="utf-8-sig", errors="replace")
    sizes = {name: len(bone.dof) for name, bone in asf.bones.items()}
    sizes["root"] = len(asf.root_order)
    # the frames the file numbers, against the limit before any is parsed
    count = text.count("\n") + 1           # at most one frame a line: counted only if needed
    if count * len(sizes) > MAX_JOINT_FRAMES:
        count = sum(1 for _ in _FRAME_NUMBER.finditer(text))
    if count * len(sizes) > MAX_JOINT_FRAMES:
        raise MocapError(f"AMC motion of {count} frames × {len(sizes)} joints is beyond the "
                         f"limit of {MAX_JOINT_FRAMES:,} joint-frames (as for BVH); cut it "
                         f"into parts", path)
    lines = text.splitlines()
    angle = asf.angle_unit
    frames: list[dict[str, list[float]]] = []
    expected, jumped = 0, False
    # Text parsing: one pass over the lines (AMC is line-oriented and bones may be absent).
    for number, raw in enumerate(lines, 1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith(":"):
            if line.upper().startswith(":RADIANS"):
                angle = "rad"
            elif line.upper().startswith(":DEGREES"):
                angle = "deg"
            continue
        words = line.split()
        if len(words) == 1 and words[0].isdigit():
            numbered = int(words[0])
            if frames and numbered != expected and not jumped:
                jumped = True
                warnings.warn(f"{path}: AMC frame numbers do not count up by one (line "
                              f"{number}: frame {numbered} after {expected - 1}); the frames "
                              "are taken in file order", MocapWarning, stacklevel=2)
            expected = numbered + 1
            frames.append({})
            continue
        if not frames:
            raise MocapError(f"AMC line {number}: data before the first frame number", path)
        bone = words[0]
        if bone not in sizes:
            raise MocapError(f"AMC line {number}: bone {bone!r} is not in the ASF skeleton",
                             path)
        try:
            values = [float(w) for w in words[1:]]
        except ValueError:
            raise MocapError(f"AMC line {number}: non-numeric value in {line!r}", path) from None
        if not all(abs(v) <= AMC_MAX_VALUE for v in values):
            raise MocapError(f"AMC line {number}: bone {bone!r} has a value that is not a "
                             f"finite number within ±{AMC_MAX_VALUE:g} (NaN, infinity or "
                             "absurd)", path)
        if len(values) != sizes[bone]:
            raise MocapError(f"AMC line {number}: bone {bone!r} has {len(values)} values, the "
                             f"ASF gives it {sizes[bone]} degrees of freedom", path)
        if bone in frames[-1]:
            raise MocapError(f"AMC line {number}: bone {bone!r} a second time in frame "
                             f"{expected - 1} (a frame number missing?)", path)
        frames[-1][bone] = values
    if not frames:
        raise MocapError("AMC file has no frames", path)
    listed = {bone: sum(bone in frame for frame in frames) for bone in sizes}
    partial = sorted(bone for bone, count in listed.items() if 0 < count < len(frames))
    if partial:
        missing = len(frames) - listed[partial[0]]
        warnings.warn(f"{path}: {len(partial)} bone(s) missing from some frames, taken as 0 "
                      f"there ({partial[0]}: {missing} of {len(frames)} frames)",
                      MocapWarning, stacklevel=2)
    result = {}
    for bone, size in sizes.items():
        table = np.zeros((len(frames), size))
        for f, frame in enumerate(frames):
            if bone in frame:
                table[f] = frame[bone]
        result[bone] = table
    return result, angle


def _euler(order: str, angles: np.ndarray) -> np.ndarray:
    """Rotation matrices of extrinsic rotations in ``order`` (first letter applied first)."""
    if not order:
        return np.broadcast_to(np.eye(3), angles.shape[:-1] + (3, 3)).copy()
    from scipy.spatial.transform import Rotation   # deferred: 0.4 s to import
    return Rotation.from_euler(order.lower(), angles, degrees=True).as_matrix()


def read_asf_amc(asf_path: str | os.PathLike, amc_path: str | os.PathLike,
                 rate: float = 120.0, units: str | None = None) -> Motion:
    """Read an ASF skeleton and an AMC motion into a :class:`~mocap.skeleton.Motion`.

    Parameters
    ----------
    asf_path, amc_path : str or PathLike
    rate : float
        Frames per second (AMC files do not store it; CMU and HDM05 use 120 Hz).
    units : {"in", "cm", "mm", "m"}, optional
        Unit of the file's lengths after dividing by the ASF length multiplier. Default:
        inches (the Acclaim/CMU convention); if the figure is then not 0.5–3 m tall, the
        unit is detected from its size (``metadata["units_detected"]``).

    Returns
    -------
    Motion
        Joints: ``root`` then every bone (ASF names), metres, Y up.
    """
    asf = read_asf(asf_path)
    values, angle_unit = read_amc(amc_path, asf)
    to_deg = 1.0 if angle_unit == "deg" else 180.0 / np.pi
    names = ["root"] + asf.order
    index = {n: i for i, n in enumerate(names)}
    parents = [-1] + [index[asf.parent[b]] for b in asf.order]
    frames = values["root"].shape[0]

    # Rest pose: a bone starts at its parent's end.
    offsets = np.zeros((len(names), 3))
    ends = np.full((len(names), 3), np.nan)
    vectors = {b: asf.bones[b].direction * asf.bones[b].length for b in asf.order}
    for b in asf.order:             # one pass (a search for each bone's children was
        up = asf.parent[b]          # quadratic: minutes for a chain of 10 000 bones)
        if up != "root":
            offsets[index[b]] = vectors[up]
    leaves = set(asf.order) - {asf.parent[b] for b in asf.order}
    for b in leaves:
        ends[index[b]] = vectors[b]
    raw = Skeleton(names, parents, offsets, ends)

    # Units.
    multiplier = asf.length_multiplier or 1.0
    detected = units is None
    extent = float(np.ptp(_rest_points(raw), axis=0).max())
    if units is None:
        scale = UNIT_SCALES["in"] / multiplier
        units = "in"
        if not 0.5 <= extent * scale <= 3.0:
            try:
                units = detect_units(extent / multiplier)
            except ValueError as error:
                raise MocapError(f"{error}; give the unit", asf_path) from None
            scale = UNIT_SCALES[units] / multiplier
    elif units in UNIT_SCALES:
        scale = UNIT_SCALES[units] / multiplier
    else:
        raise MocapError(f"unknown length unit {units!r}: use one of {', '.join(UNIT_SCALES)}")

    # Root: translation and rotation channels in the stated order.
    root_values = values["root"]
    translation = np.zeros((frames, 3))
    rot_axes, rot_columns = "", []
    for k, channel in enumerate(asf.root_order):
        if channel.startswith("T"):
            translation[:, "XYZ".index(channel[1])] = root_values[:, k]
        elif channel.startswith("R"):
            rot_axes += channel[1]
            rot_columns.append(root_values[:, k] * to_deg)
    axis_to_deg = 1.0 if asf.angle_unit == "deg" else 180.0 / np.pi
    c_root = _euler(asf.root_axis_order, asf.root_orientation * axis_to_deg)
    m_root = _euler(rot_axes, np.stack(rot_columns, axis=1)) if rot_axes else \
        np.broadcast_to(np.eye(3), (frames, 3, 3))
    world = np.empty((frames, len(names), 3, 3))
    world[:, 0] = c_root @ m_root @ c_root.T
    # Bones: G = G_parent C M Cᵀ; the relative rotation is G_parentᵀ G = C M Cᵀ.
    relative = np.empty_like(world)
    relative[:, 0] = world[:, 0]
    for b in asf.order:
        bone = asf.bones[b]
        c = _euler(bone.axis_order, bone.axis * axis_to_deg)
        axes = "".join(d[1].upper() for d in bone.dof if d.startswith("r"))
        columns = [values[b][:, k] * to_deg for k, d in enumerate(bone.dof) if d.startswith("r")]
        m = _euler(axes, np.stack(columns, axis=1)) if axes else \
            np.broadcast_to(np.eye(3), (frames, 3, 3))
        relative[:, index[b]] = c @ m @ c.T
    skeleton = Skeleton(names, parents, offsets * scale, ends * scale)
    metadata = {"source": os.fspath(amc_path), "skeleton_source": os.fspath(asf_path),
                "format": "asf/amc", "units": units, "units_detected": detected,
                "height_file_units": extent / multiplier,
                "length_multiplier": multiplier, "angle_unit": angle_unit}
    return Motion(skeleton, translation * scale, relative, rate, metadata)


def _rest_points(skeleton: Skeleton) -> np.ndarray:
    return Motion.still(skeleton, 1, 1.0).all_points()[0]
