"""The project's 15-segment body: segment names, parents, a default skeleton, and the joint
names of other tools (BVH, ASF) mapped onto it.

A joint name is split into words (namespaces such as ``mixamorig:`` dropped, then at
``_ . - :`` spaces, case changes and digits: ``LeftUpLeg`` → left up leg, ``UpperArm_L`` →
upper arm l, ``DEF-thigh.L`` → def thigh l). A side word (``Left``, ``L``, ``Right``, ``r``
…) anywhere, or glued to the front or back of a single word (ASF ``lfemur``), gives the
side; the words on the far side of it name the limb (``upleg``, ``thigh``, ``femur``,
``upperleg``, ``calf``, ``shin`` …). Words tools put in front of every joint
(``Character1_``, ``Bip01``, ``DEF-``, ``ORG-``) are ignored.

Rigs covered (tests/mocap): CMU/MotionBuilder/Mixamo BVH (Hips, LeftUpLeg, LeftLeg,
LeftArm, LeftForeArm), CMU and HDM05 ASF bones (lfemur, ltibia, lhumerus, lradius, lhand),
Unreal (pelvis, thigh_l, calf_l, upperarm_l, lowerarm_l), Blender Rigify (DEF-thigh.L,
DEF-shin.L, DEF-upper_arm.L, DEF-spine.006 as the head), Bandai Namco (UpperLeg_L,
LowerArm_R), 3ds Max Biped (Bip01 L Thigh), Unity (LeftUpperLeg), mocapbank (LeftHip,
LeftKnee, LeftShoulder, LeftElbow). Anything else: a joint map (:func:`read_joint_map`).

:func:`reduce_to_segments`, which moves a foreign skeleton's motion onto these segments,
lives in :mod:`mocap.body.retarget` (it builds a motion from world frames).
"""
from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from mocap.errors import MocapError
from mocap.tomlfile import parse_toml
from mocap.skeleton import Skeleton

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


#: The segments every body needs: pelvis and both legs (the rest may be lumped).
LOWER_BODY = ["pelvis", "l_thigh", "l_shank", "l_foot", "r_thigh", "r_shank", "r_foot"]


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
# Joint names of other tools onto our segments
# ----------------------------------------------------------------------------------------

#: Side words.
SIDE_WORDS = {"l": "l", "left": "l", "lt": "l", "r": "r", "right": "r", "rt": "r"}
#: Words some tools put in every joint name; they carry no meaning for the body.
NOISE_WORDS = {"def", "org", "mch", "bip", "jnt", "joint", "bone", "bn", "ctrl", "drv",
               "character", "mixamorig", "sk", "deform"}
#: For each limb segment, the names (after the side word, words joined) that mean it, best
#: first. ``shoulder`` is the upper arm only when nothing better exists (it is the clavicle
#: of Mixamo, Rigify and Bandai rigs); ``hip`` likewise for the thigh (CMU's LHipJoint).
LIMB_WORDS = {
    "upperarm": ("upperarm", "arm", "humerus", "uparm", "shoulder"),
    "forearm": ("forearm", "lowerarm", "lowarm", "radius", "elbow"),
    "hand": ("hand", "wrist"),
    "thigh": ("upleg", "thigh", "femur", "upperleg", "hip"),
    "shank": ("leg", "shin", "tibia", "lowerleg", "lowleg", "knee", "calf"),
    "foot": ("foot", "ankle"),
}
#: Names of the central segments, best first (the last word of the joint name).
CENTRAL_WORDS = {"pelvis": ("hips", "pelvis", "hip", "root"), "head": ("head",)}
#: The limb chains of one side, proximal first.
CHAINS = (("upperarm", "forearm", "hand"), ("thigh", "shank", "foot"))


def words(name: str) -> list[str]:
    """The lower-case words of a joint name, namespace and noise words dropped.

    >>> words("mixamorig:LeftUpLeg"), words("DEF-upper_arm.L.001"), words("lfemur")
    (['left', 'up', 'leg'], ['upper', 'arm', 'l', '001'], ['lfemur'])
    """
    name = re.split(r"[:|]", str(name))[-1]
    found: list[str] = []
    for part in re.split(r"[^A-Za-z0-9]+", name):
        found += re.findall(r"[A-Z]+(?=[A-Z][a-z])|[A-Z]?[a-z]+|[A-Z]+|\d+", part)
    result = [w.lower() for w in found]
    # "Bip01", "Character1": a noise word with its number.
    kept = []
    for k, w in enumerate(result):
        if w in NOISE_WORDS or (w.isdigit() and k > 0 and result[k - 1] in NOISE_WORDS
                                and k == 1):
            continue
        kept.append(w)
    return kept


def _limb(key: str) -> tuple[str, int] | None:
    for limb, names in LIMB_WORDS.items():
        if key in names:
            return limb, names.index(key)
    return None


def limb_match(name: str) -> tuple[str, int] | None:
    """``(segment, rank)`` for a limb joint name (``("l_thigh", 0)`` for LeftUpLeg), or None.

    Rank 0 is the best name for the segment (see :data:`LIMB_WORDS`).
    """
    parts = words(name)
    for i, word in enumerate(parts):
        side = SIDE_WORDS.get(word)
        if side is None:
            continue
        after, before = parts[i + 1:], parts[:i]
        found = _limb("".join(after)) if after else _limb("".join(before))
        if found:
            return f"{side}_{found[0]}", found[1]
    if len(parts) >= 1:
        key = "".join(parts)
        for word, side in sorted(SIDE_WORDS.items(), key=lambda item: -len(item[0])):
            for rest in ((key[len(word):],) if key.startswith(word) else ()) + \
                        ((key[:-len(word)],) if key.endswith(word) else ()):
                found = _limb(rest)
                if found:
                    return f"{side}_{found[0]}", found[1]
    return None


def central_match(name: str) -> tuple[str, int] | None:
    """``(segment, rank)`` for a pelvis or head joint name (Hips, pelvis, root, Head)."""
    parts = words(name)
    if not parts or any(p in SIDE_WORDS for p in parts):
        return None
    for segment, names in CENTRAL_WORDS.items():
        if parts[-1] in names and not any(p.isalpha() for p in parts[:-1]):
            return segment, names.index(parts[-1])
    return None


def canonical_segment(name: str) -> str | None:
    """The body segment one joint name of another tool stands for, or None.

    Ambiguous names ("LeftShoulder" is the clavicle when "LeftArm" exists) are settled by
    :func:`map_segments`, which also looks at the hierarchy.
    """
    key = "".join(words(name))
    if key in {s.replace("_", "") for s in BODY_SEGMENTS}:
        return next(s for s in BODY_SEGMENTS if s.replace("_", "") == key)
    found = central_match(name) or limb_match(name)
    return found[0] if found else None


def _ancestors(parents: list[int], index: int) -> list[int]:
    chain = []
    while index >= 0:
        chain.append(index)
        index = parents[index]
    return chain


def _common_ancestor(parents: list[int], a: int, b: int) -> int:
    chain = set(_ancestors(parents, a))
    while b not in chain:
        b = parents[b]
    return b


def map_segments(names: list[str], parents: list[int],
                 joint_map: dict[str, str] | None = None) -> dict[str, int]:
    """Which joint of a foreign skeleton stands for each of the body segments.

    Limbs: per side, the best-named upper arm (thigh), then the best-named forearm (shank)
    below it, then the hand (foot) below that. Pelvis: where the two thighs branch (their
    lowest common ancestor), or the nearest joint above it named like a pelvis (Hips,
    pelvis). Thorax: where the two upper arms branch. Head: the best joint named Head, else
    the end of the chain above the thorax that holds no arm (Rigify's spine.006).

    Parameters
    ----------
    names, parents : the skeleton's joint names and parent indices (-1 for the root).
    joint_map : dict, optional
        Body segment → joint name, taken as given (see :func:`read_joint_map`).

    Returns
    -------
    dict
        Body segment name → joint index; only the segments found.
    """
    given = {}
    for segment, joint in (joint_map or {}).items():
        if joint not in names:
            raise MocapError(f"the joint map gives {segment} = {joint!r}, but the skeleton has "
                             f"no such joint (joints: {', '.join(names)})")
        given[segment] = names.index(joint)
    exact = {s.replace("_", ""): s for s in BODY_SEGMENTS}
    limbs: dict[str, list[tuple[int, int]]] = {}
    central: dict[str, list[tuple[int, int]]] = {}
    for index, name in enumerate(names):
        key = "".join(words(name))
        if key in exact:
            target = limbs if exact[key][:2] in ("l_", "r_") else central
            target.setdefault(exact[key], []).append((-1, index))
            continue
        found = central_match(name)
        if found:
            central.setdefault(found[0], []).append((found[1], index))
            continue
        found = limb_match(name)
        if found:
            limbs.setdefault(found[0], []).append((found[1], index))
    result = dict(given)
    for side in ("l", "r"):
        for chain in CHAINS:
            above = None
            for limb in chain:
                segment = f"{side}_{limb}"
                if segment not in result:
                    options = sorted(limbs.get(segment, []))
                    below = [o for o in options if above is not None
                             and above in _ancestors(parents, o[1])[1:]]
                    pick = (below or options or [None])[0]
                    if pick is not None:
                        result[segment] = pick[1]
                above = result.get(segment, above)
    if "pelvis" not in result:
        if "l_thigh" in result and "r_thigh" in result:
            fork = _common_ancestor(parents, result["l_thigh"], result["r_thigh"])
            named = {i for _, i in central.get("pelvis", []) if words(names[i])[-1] != "root"}
            result["pelvis"] = next((i for i in _ancestors(parents, fork) if i in named), fork)
        else:
            options = sorted(central.get("pelvis", []))
            result["pelvis"] = options[0][1] if options else 0
    if "thorax" not in result and "l_upperarm" in result and "r_upperarm" in result:
        result["thorax"] = _common_ancestor(parents, result["l_upperarm"],
                                            result["r_upperarm"])
    if "head" not in result:
        options = sorted(central.get("head", []))
        if "thorax" in result:
            inside = [o for o in options if result["thorax"] in _ancestors(parents, o[1])]
            options = inside or options
        if options:
            result["head"] = options[0][1]
        elif "thorax" in result:
            head = _chain_end(parents, result["thorax"],
                              [result[s] for s in ("l_upperarm", "r_upperarm") if s in result])
            if head is not None:
                result["head"] = head
    return result


def _chain_end(parents: list[int], start: int, avoid: list[int]) -> int | None:
    """The end of the longest chain of joints below ``start`` holding none of ``avoid``."""
    children: dict[int, list[int]] = {}
    for i, p in enumerate(parents):
        children.setdefault(p, []).append(i)
    blocked = {a for joint in avoid for a in _ancestors(parents, joint)}
    best, depth_best = None, 0
    stack = [(c, 1) for c in children.get(start, []) if c not in blocked]
    while stack:
        joint, depth = stack.pop()
        if depth > depth_best:
            best, depth_best = joint, depth
        stack.extend((c, depth + 1) for c in children.get(joint, []) if c not in blocked)
    return best


def describe_mapping(names: list[str], found: dict[str, int], needed: list[str]) -> str:
    """One line: what was found, what is missing, and how to say it (a joint map)."""
    have = ", ".join(f"{s}={names[found[s]]}" for s in BODY_SEGMENTS if s in found)
    missing = [s for s in needed if s not in found]
    shown = ", ".join(names[:40]) + (f" … ({len(names)} joints)" if len(names) > 40 else "")
    return ("cannot map the skeleton onto the body model: missing " + ", ".join(missing)
            + f"; found {have or 'nothing'}; joints: {shown}; name them with joint_map= "
            "(a TOML file of lines such as l_thigh = \"MyLeftThigh\")")


def read_joint_map(path: str | os.PathLike) -> dict[str, str]:
    """A user's joint map: a TOML file of ``body segment = "joint name"`` lines.

    The keys may also sit in a ``[joints]`` table. Segments are those of the body model
    (pelvis, thorax, head, l_upperarm, l_forearm, l_hand, r_…, l_thigh, l_shank, l_foot,
    r_…); segments not given are found by name as usual.

    Raises
    ------
    MocapError
        Unreadable or invalid TOML, an unknown segment, a value that is not a joint name.
    """
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as error:
        raise MocapError(f"cannot read the joint map: {error.strerror or error}", path) from None
    except UnicodeDecodeError as error:
        raise MocapError(f"the joint map is not valid TOML: {error}", path) from None
    data = parse_toml(text, path, "joint map")
    table = data.get("joints", data)
    if not isinstance(table, dict) or not table:
        raise MocapError("the joint map holds no 'segment = \"joint\"' lines", path)
    result = {}
    for segment, joint in table.items():
        if segment not in BODY_SEGMENTS:
            raise MocapError(f"the joint map names {segment!r}, which is not a body segment "
                             f"(use {', '.join(BODY_SEGMENTS)})", path)
        if not isinstance(joint, str) or not joint:
            raise MocapError(f"the joint map's {segment} must be a joint name in quotes", path)
        result[segment] = joint
    if len(set(result.values())) != len(result):
        raise MocapError("the joint map gives one joint to two segments", path)
    return result


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
