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


def _turn(axis: int, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices (frames, 3, 3) about world axis ``axis`` (0 = X, 2 = Z)."""
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros(angle.shape + (3, 3))
    i, j = [k for k in range(3) if k != axis]
    out[..., axis, axis] = 1.0
    out[..., i, i] = c
    out[..., j, j] = c
    out[..., j, i] = s
    out[..., i, j] = -s
    return out


def _smooth(t: np.ndarray, start: float, stop: float) -> np.ndarray:
    """0 before ``start``, 1 after ``stop``, the quintic smooth step between (zero
    velocity and acceleration at both ends)."""
    s = np.clip((t - start) / (stop - start), 0.0, 1.0)
    return s ** 3 * (10 - 15 * s + 6 * s ** 2)


def walking_on_the_spot(body, centre_of_mass, lift_deg: float = 40.0):
    """A reduced 15-segment body standing still (rest pose, feet flat on y = 0) made to
    walk on the spot, slowly enough to be quasi-static: over 8 s it shifts its weight onto
    the left foot (its legs lean, both feet planted and flat, the pelvis drops so they
    stay on the floor) until its centre of mass stands over the left ankle, lifts the
    right foot straight up (thigh flexed by ``lift_deg``, the shank back so that the
    ankle keeps its place fore and aft, the foot level) and puts it down, shifts over the
    right foot, lifts the left, and comes back. Built in the body's own axes (left, up,
    forward), whichever way it faces.

    ``centre_of_mass(motion)`` gives the body's centre of mass per frame (frames, 3): the
    lean is chosen so that it stands over the stance ankle (interpolated), so that one foot
    carries the whole body with no residual. Returns the Motion.
    """
    from mocap.skeleton import Motion

    sk = body.skeleton
    rate, frames = body.rate, int(round(8.0 * body.rate))
    t = np.arange(frames) / rate
    world_r, world_p = body.forward_kinematics()
    legs = {side: [sk.index(f"{side}_{s}") for s in ("thigh", "shank", "foot")]
            for side in ("l", "r")}
    # The body's own axes, whichever way it faces: X to its left (hip to hip, level), Y up,
    # Z = X × Y; the construction below works in them (``frame`` turns them to the world).
    left_axis = world_p[0, legs["l"][0]] - world_p[0, legs["r"][0]]
    left_axis[1] = 0.0
    left_axis /= np.linalg.norm(left_axis)
    frame = np.stack([left_axis, [0.0, 1.0, 0.0], np.cross(left_axis, [0.0, 1.0, 0.0])],
                     axis=1)
    world_r, world_p = frame.T @ world_r[0], world_p[0] @ frame
    hips = {side: world_p[legs[side][0]] for side in legs}
    knees = {side: world_p[legs[side][1]] for side in legs}
    ankle = {side: world_p[legs[side][2]] for side in legs}
    # Legs straight down under the hips first (a rig at rest may stand astride: the CMU
    # skeleton's ankles are 0.77 m apart), the root raised so the ankles keep their height.
    raise_m = []
    for side, (thigh, shank, _) in legs.items():
        reach = ankle[side] - hips[side]
        under = _turn(2, np.array(np.arctan(reach[0] / reach[1])))
        world_r[thigh], world_r[shank] = under @ world_r[thigh], under @ world_r[shank]
        knees[side] = hips[side] + under @ (knees[side] - hips[side])
        raise_m.append(ankle[side][1] - (hips[side] + under @ reach)[1])
        ankle[side] = hips[side] + under @ reach
    lift = np.array([0.0, np.mean(raise_m), 0.0])
    hips, knees, ankle = ({s: p[s] + lift for s in legs} for p in (hips, knees, ankle))
    reach = {side: ankle[side] - hips[side] for side in legs}          # hip to ankle

    def pose(lean: np.ndarray, flex: dict) -> Motion:
        tilt = _turn(2, lean)                                          # (F, 3, 3)
        move = np.mean([reach[s] - tilt @ reach[s] for s in legs], axis=0)   # (F, 3)
        world = np.repeat(world_r[None], lean.size, axis=0)
        for side, (thigh, shank, foot) in legs.items():
            # The thigh flexed forward, the shank back so that the ankle rises straight up
            # (its fore-aft place kept): b_y sin φ + b_z cos φ = k about the left axis.
            a = tilt @ (knees[side] - hips[side])
            b = tilt @ (ankle[side] - knees[side])
            k = a[:, 2] + b[:, 2] - np.sin(flex[side]) * a[:, 1] \
                - np.cos(flex[side]) * a[:, 2]
            size, delta = np.hypot(b[:, 1], b[:, 2]), np.arctan2(b[:, 2], b[:, 1])
            first = np.arcsin(np.clip(k / size, -1, 1))
            options = np.angle(np.exp(1j * np.stack([first - delta, np.pi - first - delta])))
            back = options[np.argmin(np.abs(options), axis=0), np.arange(lean.size)]
            world[:, thigh] = _turn(0, flex[side]) @ tilt @ world_r[thigh]
            world[:, shank] = _turn(0, back) @ tilt @ world_r[shank]
        local = world.copy()
        local[:, 0] = frame @ world[:, 0]
        for j in range(1, sk.count):
            local[:, j] = np.swapaxes(world[:, sk.parents[j]], 1, 2) @ world[:, j]
        return Motion(sk, body.root_translation[:1] + (lift + move) @ frame.T, local, rate,
                      dict(body.metadata))

    # Lean (rad, about the forward axis) putting the centre of mass over the left ankle: on a
    # fine grid of leans, interpolated where its sideways offset from it changes sign.
    grid = np.linspace(-1.0, 1.0, 801)
    rest = np.zeros_like(grid)
    off = centre_of_mass(pose(grid, {"l": rest, "r": rest})) @ left_axis - ankle["l"][0]
    k = int(np.flatnonzero(np.diff(np.sign(off)))[0])
    left = grid[k] - off[k] * (grid[k + 1] - grid[k]) / (off[k + 1] - off[k])
    lean = left * (_smooth(t, 0.0, 1.5) - 2 * _smooth(t, 2.5, 5.0) + _smooth(t, 6.0, 7.5))
    bump = lambda a, b: np.sin(np.pi * np.clip((t - a) / (b - a), 0, 1)) ** 2  # noqa: E731
    flex = {"r": np.radians(lift_deg) * bump(1.5, 2.5), "l": np.radians(lift_deg) * bump(5.0, 6.0)}
    return pose(lean, flex)
