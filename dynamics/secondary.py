"""Secondary motion driven by a moving skeleton: a cape on the shoulders, a rope at the head.

Built on the core simulator (:mod:`dynamics.sim.system`, :mod:`dynamics.sim.builders`,
:mod:`dynamics.sim.collisions`): the cape's top row and the rope's first particle are pinned
and driven every step to points of the skeleton (``System.drive_pinned``); the body is a
set of moving capsules (trunk and limbs) and a sphere (head) the cloth cannot enter; the
floor is a plane. Between two motion frames the skeleton points are interpolated linearly
for the substeps.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocap.errors import MocapError
from mocap.progress import progress
from mocap.body.retarget import reduce_to_segments
from mocap.skeleton import Motion

from dynamics.sim.builders import cloth_grid
from dynamics.sim.builders import rope as rope_builder
from dynamics.sim.collisions import Capsule, Plane, Sphere
from dynamics.sim.forces import Drag, Gravity
from dynamics.sim.system import System

#: Capsule radius (m) of each limb segment for a 1.75 m body (scaled by height).
CAPSULE_RADII = {"upperarm": 0.05, "forearm": 0.04, "thigh": 0.075, "shank": 0.055}
TRUNK_RADIUS = 0.12
#: How far behind the shoulder joints the cape is pinned (m, 1.75 m body): outside the trunk.
CAPE_BACK = TRUNK_RADIUS + 0.025
HEAD_RADIUS = 0.1


@dataclass
class SecondaryMotion:
    """Cloth and rope trajectories, one row per motion frame.

    Attributes
    ----------
    times : ndarray, shape (frames,), seconds
    cape : ndarray, shape (frames, rows·columns, 3), metres, or None
    cape_shape : (rows, columns)
    cape_springs : ndarray, shape (springs, 2), int (indices into ``cape`` particles)
    rope : ndarray, shape (frames, particles, 3), metres, or None
    rope_springs : ndarray, shape (springs, 2)
    steps : int
        Simulator steps taken (settling included).
    """

    times: np.ndarray
    cape: np.ndarray | None
    cape_shape: tuple[int, int]
    cape_springs: np.ndarray
    rope: np.ndarray | None
    rope_springs: np.ndarray
    steps: int


def _body_colliders(names: list[str], positions: np.ndarray, scale: float):
    """Capsules (trunk, arms, legs) and a head sphere at one frame's joint positions."""
    index = {n: i for i, n in enumerate(names)}
    colliders = {}
    trunk_top = positions[index["head"]]
    colliders["trunk"] = Capsule(a=positions[index["pelvis"]], b=trunk_top,
                                 radius=TRUNK_RADIUS * scale, margin=0.01, friction=0.3)
    for side in ("l", "r"):
        for limb, child in (("upperarm", "forearm"), ("forearm", "hand"),
                            ("thigh", "shank"), ("shank", "foot")):
            a, b = index[f"{side}_{limb}"], index[f"{side}_{child}"]
            colliders[f"{side}_{limb}"] = Capsule(a=positions[a], b=positions[b],
                                                  radius=CAPSULE_RADII[limb] * scale,
                                                  margin=0.005, friction=0.3)
    colliders["head"] = Sphere(centre=positions[index["head"]] + [0, 0.1 * scale, 0],
                               radius=HEAD_RADIUS * scale, margin=0.005, friction=0.3)
    return colliders


def _segment_ends(names: list[str]) -> dict[str, tuple[int, int]]:
    index = {n: i for i, n in enumerate(names)}
    ends = {"trunk": (index["pelvis"], index["head"])}
    for side in ("l", "r"):
        for limb, child in (("upperarm", "forearm"), ("forearm", "hand"),
                            ("thigh", "shank"), ("shank", "foot")):
            ends[f"{side}_{limb}"] = (index[f"{side}_{limb}"], index[f"{side}_{child}"])
    return ends


def simulate_secondary(motion: Motion, cape: bool = True, rope: bool = False,
                       cape_resolution: tuple[int, int] = (9, 14), cape_length: float = 0.8,
                       cape_mass: float = 0.6, rope_particles: int = 10,
                       rope_length: float = 0.45, rope_mass: float = 0.1,
                       substeps: int = 4, settle: float = 0.5,
                       integrator: str = "implicit-euler") -> SecondaryMotion:
    """Simulate a cape pinned to the shoulders and/or a rope at the back of the head.

    Parameters
    ----------
    motion : Motion
        Any skeleton our body model can map (``reduce_to_segments``), metres, Y up.
    cape, rope : bool
        Which to simulate.
    cape_resolution : (columns, rows)
        Particles across the shoulders and down the back.
    cape_length : float, m
    cape_mass, rope_mass : float, kg (whole cloth / rope)
    rope_particles : int
    rope_length : float, m
    substeps : int
        Simulator steps per motion frame.
    settle : float, s
        Time simulated on the first pose before the motion starts, so the cape hangs.
    integrator : str
        A :data:`dynamics.sim.integrators.INTEGRATORS` name; implicit Euler is stable at frame
        rate (symplectic Euler needs many substeps for a stiff cloth).

    Returns
    -------
    SecondaryMotion
    """
    if not (cape or rope):
        raise MocapError("nothing to simulate: ask for the cape, the rope or both")
    try:
        body = reduce_to_segments(motion)      # the whole body: the cape needs shoulders
    except MocapError as error:
        raise MocapError("the cape and rope need a whole body (trunk, head and arms to "
                         f"hang from and fall against): {error.problem}",
                         error.path) from None
    world_r, world_p = body.forward_kinematics()
    names = body.skeleton.names
    index = {n: i for i, n in enumerate(names)}
    frames = body.frames
    height = float(np.ptp(body.all_points()[0, :, 1]))
    scale = height / 1.75 if height > 0.5 else 1.0
    dt = 1.0 / body.rate / substeps

    # Anchor points per frame: the shoulders moved up a little and back to just outside the
    # trunk capsule (so the cape starts on the back, not inside it); the back of the head.
    anterior = world_r[:, index["thorax"], :, 2]                          # (F, 3)
    up = world_r[:, index["thorax"], :, 1]
    back = CAPE_BACK * scale
    left = world_p[:, index["l_upperarm"]] - back * anterior + 0.03 * scale * up
    right = world_p[:, index["r_upperarm"]] - back * anterior + 0.03 * scale * up
    head_r = world_r[:, index["head"]]
    head_back = world_p[:, index["head"]] + np.einsum(
        "fij,j->fi", head_r, np.array([0.0, 0.12, -0.1]) * scale)

    system = System()
    system.add_force(Gravity([0.0, -9.81, 0.0]))
    system.add_force(Drag(0.02))
    system.add_collider(Plane(point=(0, 0, 0), normal=(0, 1, 0), friction=0.5, margin=0.005))
    colliders = _body_colliders(names, world_p[0], scale)
    for collider in colliders.values():
        system.add_collider(collider)
    ends = _segment_ends(names)

    columns, rows = cape_resolution
    cape_index = top = None
    cape_springs = np.zeros((0, 2), int)
    targets_cape = None
    if cape:
        width = float(np.linalg.norm(right[0] - left[0]))
        cloth = cloth_grid(origin=left[0], size=[width, cape_length * scale],
                           resolution=[columns, rows], mass=cape_mass,
                           stiffness={"structural": 600.0, "shear": 80.0, "bend": 8.0},
                           damping={"structural": 0.3, "shear": 0.05, "bend": 0.01},
                           u_axis=right[0] - left[0], v_axis=[0.0, -1.0, 0.0], pin=["top"])
        cape_index = system.add(cloth)
        top = cape_index[cloth.named("top")]
        cape_springs = cloth.springs.pairs.copy()
        weights = np.linspace(0.0, 1.0, columns)[None, :, None]
        targets_cape = (1 - weights) * left[:, None, :] + weights * right[:, None, :]
    rope_index = None
    rope_springs = np.zeros((0, 2), int)
    if rope:
        strand = rope_builder(head_back[0], head_back[0] - [0, rope_length * scale, 0],
                              rope_particles, rope_mass, stiffness=300.0, damping=0.2,
                              bend_stiffness=5.0, pin=("start",))
        rope_index = system.add(strand)
        rope_springs = strand.springs.pairs.copy()

    def drive(frame: int, fraction: float) -> None:
        """Pinned particles and colliders at a time between frame and frame + 1."""
        nxt = min(frame + 1, frames - 1)
        blend = lambda a: (1 - fraction) * a[frame] + fraction * a[nxt]   # noqa: E731
        if cape:
            system.drive_pinned(top, blend(targets_cape), dt)
        if rope:
            system.drive_pinned(rope_index[:1], blend(head_back)[None], dt)
        p = blend(world_p)
        for name, (a, b) in ends.items():
            colliders[name].move_to(p[a], p[b], dt=dt)
        colliders["head"].move_to(p[index["head"]] + np.array([0, 0.1, 0]) * scale, dt=dt)

    steps = 0
    for _ in range(int(round(settle / dt))):
        drive(0, 0.0)
        system.step(dt, integrator)
        steps += 1
    cape_out = np.empty((frames, len(cape_index), 3)) if cape else None
    rope_out = np.empty((frames, rope_particles, 3)) if rope else None
    # Time stepping is sequential: each step depends on the previous one.
    for frame in progress(range(frames), "simulating the cape and rope"):
        if cape:
            cape_out[frame] = system.particles.position[cape_index]
        if rope:
            rope_out[frame] = system.particles.position[rope_index]
        if frame == frames - 1:
            break
        for sub in range(substeps):
            drive(frame, (sub + 1) / substeps)
            system.step(dt, integrator)
            steps += 1
    return SecondaryMotion(body.times, cape_out, (rows, columns), cape_springs, rope_out,
                           rope_springs, steps)
