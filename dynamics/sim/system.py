"""The simulated system: particles, springs, forces, colliders, optional heat, and time.

A :class:`System` is what every integrator steps. It separates the constant description
(spring topology, forces, colliders) from the state that changes (particle positions,
velocities, temperatures, time) only as far as is useful: everything lives in plain
numpy arrays that callers may read and write between steps.

Driving pinned particles from outside (a cape on a skeleton)
------------------------------------------------------------
Pinned particles are kinematic: no force moves them and every integrator advances them
by ``x += dt v``. To make them follow a moving skeleton point, call, before each step,

>>> system.drive_pinned(indices, targets, dt)        # doctest: +SKIP
>>> system.step(dt, "implicit-euler")                # doctest: +SKIP

which sets their velocity to (target − x)/dt so they arrive exactly at ``targets`` at
the end of the step (springs attached to them see that velocity, and the implicit
solver keeps its factorisation because the pinned set did not change). Moving sphere
and capsule colliders are updated with their ``move_to`` methods in the same way.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from dynamics.sim import particles as _particles
from dynamics.sim import springs as _springs
from dynamics.sim.forces import Gravity
from dynamics.sim.integrators import advance
from dynamics.sim.particles import Particles
from dynamics.sim.springs import Springs, accumulate_spring_forces, spring_energy


@dataclass
class System:
    """Particles, springs, forces and colliders, stepped together.

    Attributes
    ----------
    particles : Particles
    springs : Springs (indices into ``particles``)
    forces : list of forces (``dynamics.sim.forces``, ``dynamics.sim.fluid.FluidForce`` …)
    colliders : list of colliders (``dynamics.sim.collisions``)
    heat : dynamics.sim.thermal.HeatModel or None
    time : float, seconds
    step_count : int
    speed_limit : float, m/s
        A particle faster than this (or any non-finite value) means the run went
        unstable: the step raises :class:`dynamics.sim.integrators.SimulationUnstable`.
    """

    particles: Particles = field(default_factory=Particles.empty)
    springs: Springs = field(default_factory=Springs.empty)
    forces: list = field(default_factory=list)
    colliders: list = field(default_factory=list)
    heat: object | None = None
    time: float = 0.0
    step_count: int = 0
    speed_limit: float = 1.0e3
    cache: dict = field(default_factory=dict, repr=False)

    # -- building -------------------------------------------------------------------------
    def add(self, particles, springs: Springs | None = None) -> np.ndarray:
        """Append particles (and springs indexed locally to them); returns their indices.

        Parameters
        ----------
        particles : Particles, the new ones, or a :class:`dynamics.sim.builders.Body`
            (its particles and springs)
        springs : Springs, optional, with ``pairs`` indexing ``particles`` (0-based)

        Returns
        -------
        (n,) int, the indices the new particles got in this system.
        """
        if hasattr(particles, "springs") and hasattr(particles, "particles"):
            particles, springs = particles.particles, particles.springs
        offset = len(self.particles)
        self.particles = _particles.concatenate([self.particles, particles])
        if springs is not None and len(springs):
            self.springs = _springs.concatenate([self.springs, springs.offset(offset)])
        self.cache.clear()
        return np.arange(offset, offset + len(particles))

    def add_force(self, force) -> None:
        """Add a force (anything with ``accumulate``)."""
        self.forces.append(force)
        self.cache.clear()

    def add_collider(self, collider) -> None:
        """Add a collider (anything with ``resolve``)."""
        self.colliders.append(collider)

    # -- driving pinned particles ---------------------------------------------------------
    def pin(self, indices, pinned: bool = True) -> None:
        """Pin (or release) particles; a solver refactorises on the next implicit step."""
        self.particles.pinned[np.asarray(indices)] = pinned
        self.cache.clear()

    def set_pinned(self, indices, positions, velocities=None) -> None:
        """Set positions (and velocities, m/s; default unchanged) of pinned particles.

        Parameters
        ----------
        indices : (n,) int, particles that must be pinned
        positions : (n, 3) float, metres
        velocities : (n, 3) float, m/s, optional
        """
        indices = np.asarray(indices)
        if not np.all(self.particles.pinned[indices]):
            raise ValueError("set_pinned: some of these particles are not pinned")
        self.particles.position[indices] = positions
        if velocities is not None:
            self.particles.velocity[indices] = velocities

    def drive_pinned(self, indices, targets, dt: float) -> None:
        """Give pinned particles the velocity that brings them to ``targets`` in one step.

        Parameters
        ----------
        indices : (n,) int, pinned particles
        targets : (n, 3) float, metres, where they must be at the end of the next step
        dt : float, seconds, the length of that step
        """
        indices = np.asarray(indices)
        if not np.all(self.particles.pinned[indices]):
            raise ValueError("drive_pinned: some of these particles are not pinned")
        targets = np.asarray(targets, dtype=float)
        self.particles.velocity[indices] = (targets - self.particles.position[indices]) / dt

    # -- physics --------------------------------------------------------------------------
    def compute_forces(self, position: np.ndarray | None = None,
                       velocity: np.ndarray | None = None, time: float | None = None,
                       out: np.ndarray | None = None) -> np.ndarray:
        """(N, 3) total force on every particle (springs + all forces), newtons.

        Defaults to the current state; pass trial ``position``/``velocity`` for
        multi-stage integrators.
        """
        position = self.particles.position if position is None else position
        velocity = self.particles.velocity if velocity is None else velocity
        time = self.time if time is None else time
        if out is None:
            out = np.zeros_like(position)
        else:
            out[...] = 0.0
        accumulate_spring_forces(self.springs, position, velocity, out)
        for force in self.forces:
            force.accumulate(self.particles, position, velocity, time, out)
        return out

    def energy(self) -> dict[str, float]:
        """Kinetic, spring (elastic) and gravitational potential energy, joules."""
        p = self.particles
        gravity = sum(f.potential_energy(p, p.position) for f in self.forces
                      if isinstance(f, Gravity))
        kinetic = p.kinetic_energy()
        elastic = spring_energy(self.springs, p.position)
        return {"kinetic": kinetic, "spring": elastic, "gravity": float(gravity),
                "total": kinetic + elastic + float(gravity)}

    def step(self, dt: float, integrator: str = "symplectic-euler", **options) -> None:
        """Advance by ``dt`` seconds (see :func:`dynamics.sim.integrators.advance`)."""
        advance(self, dt, integrator, **options)
