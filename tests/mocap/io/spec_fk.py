"""Reference readers written from the file specifications, independent of mocap.io.

Used by the tests as the known answer: a BVH parser and forward kinematics after the
Biovision specification (as Blender's importer and bvhio read it), and an Acclaim ASF/AMC
parser and forward kinematics after the Acclaim specification (as the CMU viewer does).
Plain Python and numpy; rotation matrices built here, not by scipy.
"""
from __future__ import annotations

import re

import numpy as np


def axis_rotation(axis: str, degrees: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotations by ``degrees`` (n,) about the X, Y or Z axis."""
    a = np.radians(np.asarray(degrees, float))
    c, s = np.cos(a), np.sin(a)
    one, zero = np.ones_like(a), np.zeros_like(a)
    rows = {"X": [[one, zero, zero], [zero, c, -s], [zero, s, c]],
            "Y": [[c, zero, s], [zero, one, zero], [-s, zero, c]],
            "Z": [[c, -s, zero], [s, c, zero], [zero, zero, one]]}[axis.upper()]
    return np.moveaxis(np.array(rows), (0, 1), (-2, -1))


# ----------------------------------------------------------------------------------------
# BVH
# ----------------------------------------------------------------------------------------
def parse_bvh(text: str) -> dict:
    """Joints (name, parent, offset, channels, end site) and the motion table of a BVH."""
    head, motion = re.split(r"\bMOTION\b", text, maxsplit=1)
    tokens = head.split()
    joints: list[dict] = []
    stack: list[int] = []
    i = 1                                          # after HIERARCHY
    while i < len(tokens):
        word = tokens[i]
        if word in ("ROOT", "JOINT"):
            joints.append({"name": tokens[i + 1], "parent": stack[-1] if stack else -1,
                           "end": None})
            stack.append(len(joints) - 1)
            i += 3                                 # name, "{"
        elif word == "OFFSET":
            joints[stack[-1]]["offset"] = np.array([float(v) for v in tokens[i + 1:i + 4]])
            i += 4
        elif word == "CHANNELS":
            n = int(tokens[i + 1])
            joints[stack[-1]]["channels"] = tokens[i + 2:i + 2 + n]
            i += 2 + n
        elif word == "End":
            joints[stack[-1]]["end"] = np.array([float(v) for v in tokens[i + 4:i + 7]])
            i += 8                                 # End Site { OFFSET x y z }
        elif word == "}":
            stack.pop()
            i += 1
        else:
            raise ValueError(word)
    lines = motion.strip().splitlines()
    frames = int(lines[0].split(":")[1])
    frame_time = float(lines[1].split(":")[1])
    table = np.array([[float(v) for v in line.split()] for line in lines[2:2 + frames]])
    for joint in joints:
        joint.setdefault("channels", [])
    return {"joints": joints, "table": table, "frame_time": frame_time}


def bvh_world_positions(bvh: dict, frames) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Joint names, world positions (len(frames), joints, 3) and end sites in file units.

    Each joint's local translation is its OFFSET with every position channel replacing its
    axis; its rotation is the product of its rotation channels in the order listed
    (``Zrotation Xrotation Yrotation`` → Rz Rx Ry).
    """
    table = bvh["table"][frames]
    n = table.shape[0]
    column = 0
    world_r, world_p, ends = [], [], []
    for joint in bvh["joints"]:
        local_t = np.tile(joint["offset"], (n, 1))
        local_r = np.tile(np.eye(3), (n, 1, 1))
        for channel in joint["channels"]:
            values = table[:, column]
            column += 1
            if channel.endswith("position"):
                local_t[:, "XYZ".index(channel[0])] = values
            else:
                local_r = local_r @ axis_rotation(channel[0], values)
        p = joint["parent"]
        if p < 0:
            world_r.append(local_r)
            world_p.append(local_t)
        else:
            world_r.append(world_r[p] @ local_r)
            world_p.append(world_p[p] + np.einsum("fij,fj->fi", world_r[p], local_t))
        if joint["end"] is not None:
            ends.append(world_p[-1] + world_r[-1] @ joint["end"])
    names = [j["name"] for j in bvh["joints"]]
    return names, np.stack(world_p, axis=1), np.stack(ends, axis=1)


# ----------------------------------------------------------------------------------------
# Acclaim ASF/AMC
# ----------------------------------------------------------------------------------------
def parse_asf(text: str) -> dict:
    """Bones (direction, length, axis, axis order, dof), hierarchy, root and units."""
    sections = re.split(r"^\s*:", text, flags=re.MULTILINE)
    asf = {"bones": {}, "children": {}, "length": 1.0, "root": {}}
    for section in sections:
        lines = [ln.split("#")[0].split() for ln in section.splitlines()]
        lines = [ln for ln in lines if ln]
        if not lines:
            continue
        title = lines[0][0]
        if title == "units":
            for ln in lines[1:]:
                if ln[0] == "length":
                    asf["length"] = float(ln[1])
        elif title == "root":
            for ln in lines[1:]:
                asf["root"][ln[0]] = ln[1:]
        elif title == "bonedata":
            bone: dict = {}
            for ln in lines[1:]:
                if ln[0] == "begin":
                    bone = {"dof": []}
                elif ln[0] == "end":
                    asf["bones"][bone["name"]] = bone
                elif ln[0] == "name":
                    bone["name"] = ln[1]
                elif ln[0] == "direction":
                    bone["direction"] = np.array([float(v) for v in ln[1:4]])
                elif ln[0] == "length":
                    bone["length"] = float(ln[1])
                elif ln[0] == "axis":
                    bone["axis"] = np.array([float(v) for v in ln[1:4]])
                    bone["order"] = ln[4]
                elif ln[0] == "dof":
                    bone["dof"] = ln[1:]
        elif title == "hierarchy":
            for ln in lines[1:]:
                if ln[0] not in ("begin", "end"):
                    asf["children"].setdefault(ln[0], []).extend(ln[1:])
    return asf


def parse_amc(text: str) -> list[dict]:
    """One dict per frame: bone → list of values."""
    frames: list[dict] = []
    for line in text.splitlines():
        words = line.split()
        if not words or words[0].startswith((":", "#")):
            continue
        if len(words) == 1 and words[0].isdigit():
            frames.append({})
        else:
            frames[-1][words[0]] = [float(v) for v in words[1:]]
    return frames


def _axis_matrix(angles: np.ndarray, order: str) -> np.ndarray:
    """C of an ASF ``axis a b c ORDER``: rotations applied in ORDER about fixed axes."""
    matrix = np.eye(3)
    for axis, angle in zip(order.upper(), angles):
        matrix = axis_rotation(axis, np.array([angle]))[0] @ matrix
    return matrix


def acclaim_positions(asf: dict, frames: list[dict]) -> dict[str, np.ndarray]:
    """World position of every bone's start and end, (frames, 3) each, in file units.

    W_root = C_root M_root; W_bone = W_parent C_parent⁻¹ C_bone M_bone, with M the dof
    rotations applied in the order listed; a bone ends at its start plus
    W_bone C_bone⁻¹ (direction × length) and starts where its parent ends.
    """
    root = asf["root"]
    order = [c.upper() for c in root.get("order", "TX TY TZ RX RY RZ".split())]
    c_root = _axis_matrix(np.array([float(v) for v in root.get("orientation", [0, 0, 0])]),
                          root.get("axis", ["XYZ"])[0])
    out: dict[str, np.ndarray] = {}
    n = len(frames)
    position = np.zeros((n, 3))
    m_root = np.tile(np.eye(3), (n, 1, 1))
    for k, channel in enumerate(order):
        values = np.array([f["root"][k] for f in frames])
        if channel.startswith("T"):
            position[:, "XYZ".index(channel[1])] = values
        else:
            m_root = axis_rotation(channel[1], values) @ m_root
    out["root"] = position
    world = {"root": c_root @ m_root}
    axes = {"root": c_root}
    todo = [("root", b) for b in asf["children"].get("root", [])]
    while todo:
        parent, name = todo.pop()
        bone = asf["bones"][name]
        c = _axis_matrix(bone.get("axis", np.zeros(3)), bone.get("order", "XYZ"))
        m = np.tile(np.eye(3), (n, 1, 1))
        for k, dof in enumerate(bone["dof"]):
            if dof.lower().startswith("r"):
                values = np.array([f.get(name, [0.0] * len(bone["dof"]))[k] for f in frames])
                m = axis_rotation(dof[1], values) @ m
        w = world[parent] @ axes[parent].T @ c @ m
        world[name], axes[name] = w, c
        start = out[parent] if parent == "root" else out[parent + ".end"]
        out[name] = start
        out[name + ".end"] = start + np.einsum("fij,j->fi", w @ c.T,
                                               bone["direction"] * bone["length"])
        todo += [(name, b) for b in asf["children"].get(name, [])]
    return out
