"""Known-answer rigs for the dynamics check: BVH text built here, read by the real reader.

:func:`cmu_like_bvh` writes a CMU-named humanoid (centimetres, Y up) whose ankle and toe
joints touch the floor (y = 0) with the centre of mass over the feet, the rig of game
and tool exports whose joints sit on the sole; ``ankle_height_cm`` and ``toe_height_cm``
raise them (a rig with its joints inside the foot, as captured skeletons have). The root
path is given per frame, so still, raised, free-falling, sliding and jumping trials are
all the same rig moved by a known root path.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

GRAVITY = 9.81


def _joint(name: str, offset, children: str, indent: int) -> str:
    pad = "  " * indent
    return (f"{pad}JOINT {name}\n{pad}{{\n{pad}  OFFSET {offset[0]:g} {offset[1]:g} "
            f"{offset[2]:g}\n{pad}  CHANNELS 3 Zrotation Xrotation Yrotation\n"
            f"{children}{pad}}}\n")


def _end(offset, indent: int) -> str:
    pad = "  " * indent
    return (f"{pad}End Site\n{pad}{{\n{pad}  OFFSET {offset[0]:g} {offset[1]:g} "
            f"{offset[2]:g}\n{pad}}}\n")


def _chain(links: list[tuple[str, tuple]], end: tuple, indent: int) -> str:
    """Nested joints ``links`` (name, offset) ending in an End Site ``end``."""
    text = _end(end, indent + len(links))
    for depth, (name, offset) in reversed(list(enumerate(links))):
        text = _joint(name, offset, text, indent + depth)
    return text


def cmu_like_hierarchy(ankle_height_cm: float = 0.0, toe_height_cm: float = 0.0) -> str:
    """HIERARCHY of a CMU-named rig, centimetres; the hips 95 cm above the floor.

    The ankles (LeftFoot/RightFoot) stand ``ankle_height_cm`` above y = 0, the toe joints
    (LeftToeBase/RightToeBase, 14 cm ahead along +Z) and their end sites (5 cm further)
    ``toe_height_cm``. The arms hang down beside the trunk, so the centre of mass lies
    over the feet (between ankle and toe, x = 0).
    """
    hip_drop = 95.0 - 5.0 - 44.0 - ankle_height_cm        # hip joint to knee to ankle
    text = ""
    for side, x in (("Left", 9.0), ("Right", -9.0)):
        prefix = "L" if side == "Left" else "R"
        text += _chain([(f"{prefix}HipJoint", (0, 0, 0)), (f"{side}UpLeg", (x, -5, 0)),
                        (f"{side}Leg", (0, -44, 0)), (f"{side}Foot", (0, -hip_drop, 0)),
                        (f"{side}ToeBase", (0, toe_height_cm - ankle_height_cm, 14))],
                       (0, 0, 5), 1)
    spine = [("LowerBack", (0, 3, 0)), ("Spine", (0, 12, 0)), ("Spine1", (0, 12, 0))]
    upper = _chain([("Neck", (0, 20, 0)), ("Neck1", (0, 5, 0)), ("Head", (0, 5, 0))],
                   (0, 18, 0), 4)
    for side, x in (("Left", 1.0), ("Right", -1.0)):
        upper += _chain([(f"{side}Shoulder", (3 * x, 17, 0)), (f"{side}Arm", (14 * x, 0, 0)),
                         (f"{side}ForeArm", (0, -29, 0)), (f"{side}Hand", (0, -26, 0))],
                        (0, -9, 0), 4)
    for depth, (name, offset) in reversed(list(enumerate(spine))):
        upper = _joint(name, offset, upper, 1 + depth)
    return ("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition "
            "Zposition Zrotation Xrotation Yrotation\n" + text + upper + "}\n")


def cmu_like_bvh(path: Path, root_cm: np.ndarray, rate: float = 60.0,
                 ankle_height_cm: float = 0.0, toe_height_cm: float = 0.0) -> Path:
    """Write the rig moved along ``root_cm`` (frames, 3), centimetres, all joints at rest."""
    hierarchy = cmu_like_hierarchy(ankle_height_cm, toe_height_cm)
    channels = 6 + 3 * hierarchy.count("JOINT")
    rows = np.zeros((len(root_cm), channels))
    rows[:, :3] = root_cm
    lines = [hierarchy, f"MOTION\nFrames: {len(root_cm)}\nFrame Time: {1.0 / rate:.8f}\n"]
    lines += [" ".join(f"{v:.6f}" for v in row) + "\n" for row in rows]
    Path(path).write_text("".join(lines))
    return Path(path)


def root_path(kind: str, seconds: float = 2.0, rate: float = 60.0) -> np.ndarray:
    """Root path (frames, 3), cm, of a known-answer trial of the rig at rest height 95 cm.

    ``still``; ``raised`` (30 cm up); ``free fall`` (from rest, 1.5 m up: no contact within 0.5 s);
    ``sliding`` (1 m/s along +Z); ``jump`` (0.5 s stand, 0.3 s flight at g, stand).
    """
    frames = int(round(seconds * rate))
    t = np.arange(frames) / rate
    root = np.zeros((frames, 3))
    root[:, 1] = 95.0
    if kind == "raised":
        root[:, 1] += 30.0
    elif kind == "free fall":
        root[:, 1] += 150.0 - 100.0 * 0.5 * GRAVITY * t ** 2
    elif kind == "sliding":
        root[:, 2] = 100.0 * t
    elif kind == "jump":
        flight = 0.3
        start = 0.5
        s = np.clip(t - start, 0.0, flight)
        root[:, 1] += 100.0 * (0.5 * GRAVITY * flight * s - 0.5 * GRAVITY * s ** 2)
    elif kind != "still":
        raise ValueError(kind)
    return root
