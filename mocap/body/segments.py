"""The project's 15-segment body: segment names, parents, a default skeleton, and the joint
names of other tools (BVH, ASF) mapped onto it.

:func:`reduce_to_segments`, which moves a foreign skeleton's motion onto these segments,
lives in :mod:`mocap.body.retarget` (it builds a motion from world frames).
"""
from __future__ import annotations

import re

import numpy as np

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
