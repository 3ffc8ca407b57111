"""Running a :class:`~dynamics.scenes.build.Scene` and its outputs: the saved frames
(:class:`SimulationResult`), written and read as ``.npz``.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from mocap.atomic import atomic_path
from mocap.budget import read_npz
from mocap.errors import MocapError
from mocap.progress import progress

from dynamics.scenes.build import Scene
from dynamics.sim.collisions import Box, Plane, Sphere
from dynamics.sim.integrators import SimulationUnstable, advance
from dynamics.sim.rigid import newton_euler_step

#: Largest in-memory result (saved frames) a run may build, bytes.
MAX_OUTPUT_BYTES = 4_000_000_000
#: Most heat-conduction sub-steps per time step (explicit diffusion is stable only below
#: ``stable_dt``; beyond this the run would take hours).
MAX_HEAT_SUBSTEPS = 10_000


@dataclass
class SimulationResult:
    """Saved frames of a run (S saved frames, N particles, M springs, B rigid bodies).

    Attributes
    ----------
    times : (S,) float, seconds
    positions : (S, N, 3) float, metres
    springs : (M, 2) int
    spring_kind : (M,) int8 (dynamics.sim.springs kinds)
    spring_broken_at : (M,) float, seconds (inf: never melted)
    colour : (N, 3) float
    mass : (N,) float, kg
    pinned : (N,) bool
    energy : (S, 4) float, joules: kinetic, spring, gravity, total (particles only)
    temperature : (S, N) float, kelvin, or None without [heat]
    rigid_positions : (S, B, 3), rigid_orientations : (S, B, 4) quaternions (x, y, z, w),
    rigid_vertices : (S, B, V, 3) world corners, rigid_angular_momentum : (S, B, 3)
    dt : float, integrator : str
    spheres : (K, 4) float, centre and radius of each sphere collider at the end (for drawing)
    boxes : (K, 6) float, minimum and maximum corners of each box collider
    planes : (K, 6) float, point and unit normal of each plane collider
    """

    times: np.ndarray
    positions: np.ndarray
    springs: np.ndarray
    spring_kind: np.ndarray
    spring_broken_at: np.ndarray
    colour: np.ndarray
    mass: np.ndarray
    pinned: np.ndarray
    energy: np.ndarray
    temperature: np.ndarray | None
    rigid_positions: np.ndarray
    rigid_orientations: np.ndarray
    rigid_vertices: np.ndarray
    rigid_angular_momentum: np.ndarray
    dt: float
    integrator: str
    spheres: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    boxes: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    planes: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))

    def arrays(self) -> dict[str, np.ndarray]:
        """Every field as an array (what ``save`` writes)."""
        out = {name: np.asarray(getattr(self, name)) for name in self.__dataclass_fields__
               if getattr(self, name) is not None}
        return out

    def save(self, path: str | os.PathLike) -> None:
        """Write a compressed ``.npz`` atomically (nothing is left on failure)."""
        arrays = self.arrays()
        if any(np.isnan(v).any() for v in arrays.values() if v.dtype.kind == "f"):
            raise MocapError("refusing to write NaNs (the simulation went unstable)", path)
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as handle:
                np.savez_compressed(handle, **arrays)


def run_scene(scene: Scene, show_progress: bool | None = None) -> SimulationResult:
    """Run ``scene`` to the end and return the saved frames.

    Raises
    ------
    MocapError (SimulationUnstable)
        When the run goes unstable: names the step and the remedy, with the scene's path.
    """
    system = scene.system
    p = system.particles
    bodies = scene.rigid_bodies
    saved = scene.steps // scene.save_every + 1
    n, b = len(p), len(bodies)
    vertices = max((len(body.vertices) for body in bodies), default=0)
    size = saved * (n * (3 + (system.heat is not None)) + b * (10 + 3 * vertices)) * 8
    if size > MAX_OUTPUT_BYTES:
        raise MocapError(f"the saved frames would take {size / 1e9:.1f} GB ({saved} frames of "
                         f"{n} particles); raise [simulation] save_every or lower steps",
                         scene.path)
    if system.heat is not None:
        stable = 0.9 * system.heat.stable_dt(n, system.springs)
        substeps = scene.dt / stable if np.isfinite(stable) and stable > 0 else 1.0
        if not substeps <= MAX_HEAT_SUBSTEPS:
            raise MocapError(f"heat conduction would need {substeps:.3g} sub-steps per time "
                             f"step (at most {MAX_HEAT_SUBSTEPS}); lower [heat] conductivity "
                             "or [simulation] dt, or raise capacity", scene.path)
    times = np.empty(saved)
    positions = np.empty((saved, n, 3))
    energy = np.empty((saved, 4))
    temperature = np.empty((saved, n)) if system.heat is not None else None
    rigid = (np.empty((saved, b, 3)), np.empty((saved, b, 4)), np.zeros((saved, b, vertices, 3)),
             np.empty((saved, b, 3)))

    def record(slot: int) -> None:
        times[slot] = system.time
        positions[slot] = p.position
        e = system.energy()
        energy[slot] = (e["kinetic"], e["spring"], e["gravity"], e["total"])
        if temperature is not None:
            temperature[slot] = p.temperature
        for k, body in enumerate(bodies):
            rigid[0][slot, k] = body.position
            rigid[1][slot, k] = body.orientation
            rigid[2][slot, k, :len(body.vertices)] = body.world_vertices()
            rigid[3][slot, k] = body.angular_momentum

    record(0)
    options = scene.integrator_options
    for step in progress(range(1, scene.steps + 1), "simulating", total=scene.steps,
                         enabled=show_progress):
        # each step depends on the previous one: the loop over time is inherent
        if n:
            try:
                advance(system, scene.dt, scene.integrator, **options)
            except MocapError as error:
                raise type(error)(error.problem, scene.path) from None
        else:
            system.time += scene.dt
            system.step_count += 1
        for push in scene.pushes:
            body = bodies[push.body]
            if push.start <= system.time - scene.dt < push.start + push.duration:
                body.apply_force(push.force, body.position + body.rotation @ push.point)
        for k, body in enumerate(bodies):
            try:
                newton_euler_step(body, scene.dt, scene.gravity, system.speed_limit)
            except SimulationUnstable as error:
                raise SimulationUnstable(
                    f"rigid body {k + 1} at step {step} (t = {system.time:.4g} s): "
                    f"{error.problem}", scene.path) from None
        if step % scene.save_every == 0:
            record(step // scene.save_every)
    broken_at = (system.heat.melted_at if system.heat is not None
                 and system.heat.melted_at is not None else np.full(len(system.springs), np.inf))
    colliders = system.colliders
    spheres = [np.r_[c.centre, c.radius] for c in colliders if isinstance(c, Sphere)]
    boxes = [np.r_[c.minimum, c.maximum] for c in colliders if isinstance(c, Box)]
    planes = [np.r_[c.point, c.normal] for c in colliders if isinstance(c, Plane)]
    return SimulationResult(times, positions, system.springs.pairs.copy(),
                            system.springs.kind.copy(), broken_at.copy(), p.colour.copy(),
                            p.mass.copy(), p.pinned.copy(), energy, temperature, rigid[0], rigid[1],
                            rigid[2], rigid[3], scene.dt, scene.integrator,
                            np.reshape(spheres, (-1, 4)), np.reshape(boxes, (-1, 6)),
                            np.reshape(planes, (-1, 6)))


def load_result(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """Read a saved run (``.npz``) as a dict of arrays."""
    return read_npz(path, "cannot read simulation result")
