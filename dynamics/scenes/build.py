"""A scene document (``docs/formats/scene-toml.md``) -> a :class:`Scene`: the particle system, rigid bodies and
the run settings.

Particle indices follow the order of creation: first every ``[[particle]]`` (in file
order), then the generators in this order: ``[[rope]]``, ``[[cloth]]``, ``[[lattice]]``,
``[[fluid]]`` (each in file order). ``[[spring]]`` ``between`` indices use this order.
The tables are read through :class:`dynamics.scenes.schema.Table` (every key checked).
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mocap.budget import read_budget
from mocap.errors import MocapError

from dynamics.scenes.schema import (TOP_LEVEL_TABLES, Table, read_scene_document, table_of,
                                    tables_of)
from dynamics.sim import builders
from dynamics.sim.collisions import Box, Capsule, Plane, Sphere
from dynamics.sim.fluid import FluidForce, equilibrium_beta
from dynamics.sim.forces import Drag, Gravity, Wind
from dynamics.sim.integrators import IMPLICIT_SOLVERS, INTEGRATORS
from dynamics.sim.particles import Particles
from dynamics.sim.rigid import RigidBody, box_inertia
from dynamics.sim.springs import STRUCTURAL, USER, Springs
from dynamics.sim.springs import concatenate as concatenate_springs
from dynamics.sim.system import System
from dynamics.sim.thermal import HeatModel, HeatSource


@dataclass
class Push:
    """A force on a rigid body at a body-fixed point during [start, start + duration)."""

    body: int
    force: np.ndarray          # (3,) N, world
    point: np.ndarray          # (3,) m, body frame, relative to the centre of mass
    start: float
    duration: float


@dataclass
class Scene:
    """A loaded scene: the particle system, rigid bodies and the run settings."""

    system: System
    dt: float
    steps: int
    integrator: str
    save_every: int = 1
    solver: str = "projective"
    iterations: int = 10
    gravity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rigid_bodies: list = field(default_factory=list)
    pushes: list = field(default_factory=list)
    title: str = ""
    path: str | None = None

    @property
    def integrator_options(self) -> dict:
        """Keyword options for :func:`dynamics.sim.integrators.advance`."""
        if self.integrator == "implicit-euler":
            return {"solver": self.solver, "iterations": self.iterations}
        return {}


def load_scene(path: str | os.PathLike) -> Scene:
    """Read and validate a TOML scene file (``docs/formats/scene-toml.md``) and build its :class:`Scene`."""
    path = Path(path)
    return build_scene(read_scene_document(path), path)


def build_scene(document: dict, path=None) -> Scene:
    """Build a :class:`Scene` from a parsed TOML document (a dict)."""
    unknown = sorted(set(document) - TOP_LEVEL_TABLES)
    if unknown:
        raise MocapError(f"unknown table(s) {', '.join(map(repr, unknown))}; known: "
                         + ", ".join(sorted(TOP_LEVEL_TABLES)), path)
    simulation = table_of(document, "simulation", path) or Table({}, "[simulation]", path)
    dt = simulation.number("dt", 0.001, above=0.0)
    steps = simulation.integer("steps", 1000, minimum=1)
    integrator = simulation.choice("integrator", INTEGRATORS, "symplectic-euler")
    save_every = simulation.integer("save_every", max(1, steps // 200), minimum=1)
    solver = simulation.choice("solver", IMPLICIT_SOLVERS, "projective")
    iterations = simulation.integer("iterations", 10, minimum=1)
    speed_limit = simulation.number("speed_limit", 1000.0, above=0.0)
    simulation.finish()

    system = System(speed_limit=speed_limit)
    gravity_table = table_of(document, "gravity", path)
    gravity = np.zeros(3)
    if gravity_table is not None:
        gravity = gravity_table.vector("g", [0.0, -9.81, 0.0])
        gravity_table.finish()
        system.add_force(Gravity(gravity))
    damping_table = table_of(document, "damping", path)
    if damping_table is not None:
        gamma = damping_table.number("gamma", 0.0, minimum=0.0)
        damping_table.finish()
        if gamma:
            system.add_force(Drag(gamma))

    _add_particles(system, tables_of(document, "particle", path))
    fluid_forces, molten = _add_bodies(system, document, path, steps // save_every + 1)
    _add_springs(system, tables_of(document, "spring", path))
    for force in fluid_forces:
        system.add_force(force)
    _add_heat(system, table_of(document, "heat", path))
    for table, spacing, index in molten:
        if system.heat is None or not np.isfinite(system.heat.melt):
            raise MocapError(f"{table.where} needs [heat] with a 'melt' temperature", path)
        system.add_force(_fluid_force(table, spacing, index, system.heat.melt,
                                      count=len(index)))
    _add_colliders(system, document, path)
    wind = table_of(document, "wind", path)
    if wind is not None:
        system.add_force(Wind(wind.vector("velocity"), wind.number("coefficient", 0.01, minimum=0),
                              wind.number("gust_amplitude", 0.0, minimum=0),
                              wind.number("gust_frequency", 0.5, minimum=0)))
        wind.finish()
    bodies, pushes = _rigid_bodies(tables_of(document, "rigid", path))
    if len(system.particles) == 0 and not bodies:
        raise MocapError("the scene has nothing to simulate: add particles, a body or [[rigid]]",
                         path)
    title = document.get("title", "")
    if not isinstance(title, str) or not isinstance(document.get("description", ""), str):
        raise MocapError("'title' and 'description' must be strings", path)
    return Scene(system, dt, steps, integrator, save_every, solver, iterations, gravity,
                 bodies, pushes, title, None if path is None else os.fspath(path))


def _colour(table: Table, default) -> np.ndarray:
    return table.vector("colour", default, minimum=0.0).clip(0.0, 1.0)


def _add_particles(system: System, tables: list[Table]) -> None:
    if not tables:
        return
    rows = []
    for t in tables:
        rows.append((t.vector("position"), t.vector("velocity", [0, 0, 0]),
                     t.number("mass", 1.0, above=0.0), t.boolean("pinned", False),
                     _colour(t, [0.8, 0.3, 0.2]), t.number("temperature", 293.15, above=0.0)))
        t.finish()
    position, velocity, mass, pinned, colour, temperature = (np.array(c) for c in zip(*rows))
    system.add(Particles(position, velocity, mass, pinned, colour, temperature))


def _pin_list(table: Table):
    pins = table.raw("pin", [])
    if isinstance(pins, str):
        pins = [pins]
    if not isinstance(pins, list):
        raise table.error("pin", f"must be a list of names or [row, column] pairs, not {pins!r}")
    return pins


def _finish_body(system: System, body: builders.Body, table: Table, colour) -> np.ndarray:
    body.particles.colour[:] = _colour(table, colour)
    body.particles.temperature[:] = table.number("temperature", 293.15, above=0.0)
    body.particles.velocity[:] = table.vector("velocity", [0, 0, 0])
    table.finish()
    return system.add(body)


#: Most particles one scene may create (memory and time guard for typos in resolutions).
MAX_PARTICLES = 2_000_000


#: Bytes a particle takes while its scene is built and run, besides its saved frames: its
#: state, its share of the springs (a cloth makes 6 per particle, a lattice up to 13) and
#: work arrays (a 300 × 300 cloth peaks at 1.3 kB per particle while it is built).
PARTICLE_BYTES = 2000


def _check_count(t: Table, count: float, system: System, key: str, frames: int) -> None:
    """Refuse a body of ``count`` particles beyond :data:`MAX_PARTICLES`, or one that with
    the particles before it and ``frames`` saved frames (24 bytes a particle each) would
    take more than the reading budget (:func:`mocap.budget.read_budget`), before
    anything of it is allocated."""
    total = count + len(system.particles)
    if not total <= MAX_PARTICLES:      # also NaN and inf
        shown = f"{count:.0f}" if math.isfinite(count) else "infinitely many"
        raise t.error(key, f"would make {shown} particles; a scene may have at most "
                           f"{MAX_PARTICLES}")
    need = total * (PARTICLE_BYTES + 24 * frames)
    if need > read_budget():
        raise t.error(key, f"would make {count:.0f} particles, which with {frames} saved "
                           f"frames would take about {need / 1e6:.0f} MB, more than the "
                           f"budget of {read_budget() / 1e6:.0f} MB (MOCAP_READ_BUDGET_MB); "
                           f"use fewer particles, or raise [simulation] save_every")


def _positive_sizes(t: Table, key: str, length: int = 3) -> np.ndarray:
    size = t.vector(key, length=length)
    if not np.all(size > 0):
        raise t.error(key, f"must be positive on every axis, not {size.tolist()}")
    return size


def _add_bodies(system: System, document: dict, path, frames: int) -> tuple[list, list]:
    """Ropes, cloths, lattices and fluid blocks, in that order (``frames``: the frames a
    run will save, for the memory budget).

    Returns the fluid forces of [[fluid]] blocks and the pending molten-fluid settings
    of lattices (table, spacing, particle indices), built once [heat] is known.
    """
    fluid_forces, molten = [], []
    for t in tables_of(document, "rope", path):
        count = t.integer("particles", 20, minimum=2)
        _check_count(t, count, system, "particles", frames)
        try:
            body = builders.rope(t.vector("start"), t.vector("end"), count,
                                 t.number("mass", 0.2, above=0.0),
                                 t.number("stiffness", 500.0, minimum=0.0),
                                 t.number("damping", 0.5, minimum=0.0),
                                 t.number("bend_stiffness", 0.0, minimum=0.0), _pin_list(t))
        except MocapError:                       # a value the table refused: said already
            raise
        except (ValueError, IndexError) as error:
            raise MocapError(f"{t.where}: {error}", path) from None
        _finish_body(system, body, t, [0.6, 0.4, 0.2])
    for t in tables_of(document, "cloth", path):
        resolution = t.vector("resolution", [16, 16], length=2, integer=True, minimum=2)
        _check_count(t, math.prod(int(r) for r in resolution), system, "resolution", frames)
        try:
            body = builders.cloth_grid(
                t.vector("origin"), _positive_sizes(t, "size", 2), resolution,
                t.number("mass", 0.5, above=0.0), t.per_kind("stiffness", 500.0),
                t.per_kind("damping", 0.0), _pin_list(t),
                t.vector("u_axis", [1, 0, 0]), t.vector("v_axis", [0, 0, 1]))
        except MocapError:                       # a value the table refused: said already
            raise
        except (ValueError, IndexError) as error:
            raise MocapError(f"{t.where}: {error}", path) from None
        _finish_body(system, body, t, [0.2, 0.4, 0.8])
    for t in tables_of(document, "lattice", path):
        resolution = t.vector("resolution", [5, 5, 5], integer=True, minimum=2)
        _check_count(t, math.prod(int(r) for r in resolution), system, "resolution", frames)
        size = _positive_sizes(t, "size")
        try:
            body = builders.lattice_block(
                t.vector("origin"), size, resolution, t.number("mass", 1.0, above=0.0),
                t.per_kind("stiffness", 2000.0), t.per_kind("damping", 1.0), _pin_list(t))
        except MocapError:                       # a value the table refused: said already
            raise
        except (ValueError, IndexError) as error:
            raise MocapError(f"{t.where}: {error}", path) from None
        fluid = t.raw("molten_fluid")
        index = _finish_body(system, body, t, [0.7, 0.7, 0.75])
        if fluid is not None:
            spacing = float(np.min(size / (resolution - 1)))
            molten.append((Table(fluid, f"{t.where} molten_fluid", path), spacing, index))
    for t in tables_of(document, "fluid", path):
        spacing = t.number("spacing", above=0.0)
        size = t.vector("size", minimum=0.0)
        # in floats: a huge size over a small spacing is inf or beyond int64, and must
        # reach the particle limit's message, not an OverflowError
        with np.errstate(over="ignore"):
            count = float(np.prod(np.floor(size / spacing + 1e-9) + 1))
        _check_count(t, count, system, "spacing", frames)
        if count < 2:
            # a block under one spacing on every axis is one particle: no fluid at all
            raise t.error("size", f"{size.tolist()} is under one spacing ({spacing:g} m) on "
                                  f"every axis, which makes one particle, not a fluid")
        body = builders.particle_block(t.vector("origin"), size, spacing,
                                       t.number("mass", 1.0, above=0.0),
                                       t.number("jitter", 0.0, minimum=0.0),
                                       t.integer("seed", 0))
        # the pair-force keys live in the same table; _finish_body checks for unknown keys
        force = _fluid_force(t, spacing, None, None, finish=False, count=count)
        force.members = _finish_body(system, body, t, [0.1, 0.5, 0.9])
        fluid_forces.append(force)
    return fluid_forces, molten


#: Bytes a neighbour pair of a fluid takes while its forces are computed (the pair's
#: indices, its offset, distance and force terms).
PAIR_BYTES = 96


def _fluid_force(t: Table, spacing: float, members, melt, finish: bool = True,
                 count: float = 0) -> FluidForce:
    """The pair force of a fluid of ``count`` particles at ``spacing``; a cutoff that would
    give its neighbour list more pairs than the reading budget holds is refused (a cutoff
    of metres over a spacing of centimetres pairs every particle with every other)."""
    alpha = t.number("alpha", above=0.0)
    zeta = t.number("zeta", 0.5 * spacing, minimum=0.0)
    a = t.number("a", 2.0, above=0.0)
    b = t.number("b", 4.0, above=0.0)
    beta = t.number("beta", equilibrium_beta(alpha, zeta, spacing, a, b), above=0.0)
    cutoff = t.number("cutoff", 1.25 * spacing, above=0.0)
    # neighbours within the cutoff and its Verlet skin (a quarter more), at rest spacing
    with np.errstate(over="ignore"):
        neighbours = min(float(count), 4.19 * (1.25 * cutoff / spacing) ** 3 + 1.0)
    need = 0.5 * count * neighbours * PAIR_BYTES
    if need > read_budget():
        raise t.error("cutoff", f"{cutoff:g} m over a spacing of {spacing:g} m gives each of "
                                f"{count:.0f} particles about {neighbours:.0f} neighbours: "
                                f"about {need / 1e6:.0f} MB of pairs, more than the budget "
                                f"of {read_budget() / 1e6:.0f} MB (MOCAP_READ_BUDGET_MB)")
    viscosity = t.number("viscosity", 0.0, minimum=0.0)
    if finish:
        t.finish()
    return FluidForce(alpha, beta, zeta, cutoff, a, b, viscosity, members,
                      None if melt is None or not np.isfinite(melt) else melt)


def _add_springs(system: System, tables: list[Table]) -> None:
    if not tables:
        return
    n = len(system.particles)
    pairs, rest, k, g = [], [], [], []
    for t in tables:
        between = t.vector("between", length=2, integer=True, minimum=0)
        if between.max() >= n:
            raise t.error("between", f"refers to particle {between.max()} but the scene has "
                                     f"{n} particles (indices start at 0)")
        if between[0] == between[1]:
            raise t.error("between", "joins a particle to itself")
        pairs.append(between)
        k.append(t.number("stiffness", minimum=0.0))
        g.append(t.number("damping", 0.0, minimum=0.0))
        p = system.particles.position
        rest.append(t.number("rest_length", float(np.linalg.norm(p[between[1]] - p[between[0]])),
                             minimum=0.0))
        t.finish()
    springs = Springs(np.array(pairs), np.array(rest), np.array(k), np.array(g), USER)
    system.springs = concatenate_springs([system.springs, springs])
    system.cache.clear()


def _add_heat(system: System, t: Table | None) -> None:
    if t is None:
        return
    sources = []
    raw_sources = t.raw("source", [])
    if isinstance(raw_sources, dict) or not isinstance(raw_sources, list):
        raise t.error("source", "must be an array of tables: write [[heat.source]]")
    for n, item in enumerate(raw_sources):
        st = Table(item, f"[[heat.source]] #{n + 1}", t.path)
        temperature = st.number("temperature", above=0.0) if st.has("temperature") else None
        power = st.number("power") if st.has("power") else None
        if (temperature is None) == (power is None):
            raise MocapError(f"{st.where}: give exactly one of 'temperature' and 'power'", t.path)
        sources.append(HeatSource(st.vector("minimum"), st.vector("maximum"), temperature, power))
        st.finish()
    melt = t.number("melt", above=0.0) if t.has("melt") else np.inf
    if np.isfinite(melt) and not t.has("soften"):
        raise t.error("soften", "is required with 'melt' (stiffness falls from soften to melt)")
    soften = t.number("soften", above=0.0) if t.has("soften") else np.inf
    if np.isfinite(melt) and not melt > soften:
        raise t.error("melt", f"({melt}) must be above 'soften' ({soften})")
    heat = HeatModel(t.number("conductivity", minimum=0.0), t.number("capacity", above=0.0),
                     soften, melt, sources, None, t.number("ambient", 293.15, above=0.0),
                     t.number("cooling", 0.0, minimum=0.0), t.boolean("thermoelastic", True))
    if t.has("initial"):
        system.particles.temperature[:] = t.number("initial", above=0.0)
    t.finish()
    if not np.any(np.isin(system.springs.kind, (STRUCTURAL, USER))):
        raise MocapError("[heat]: heat conducts along structural springs, but the scene has "
                         "none (add a [[lattice]], [[cloth]], [[rope]] or [[spring]])", t.path)
    system.heat = heat


def _add_colliders(system: System, document: dict, path) -> None:
    for t in tables_of(document, "plane", path):
        normal = t.vector("normal", [0, 1, 0])
        if not np.linalg.norm(normal) > 0:
            raise t.error("normal", "must be non-zero")
        system.add_collider(Plane(t.vector("point", [0, 0, 0]), normal, *_contact(t)))
        t.finish()
    for t in tables_of(document, "sphere", path):
        system.add_collider(Sphere(t.vector("centre"), t.number("radius", above=0.0),
                                   t.vector("velocity", [0, 0, 0]), *_contact(t)))
        t.finish()
    for t in tables_of(document, "capsule", path):
        system.add_collider(Capsule(t.vector("a"), t.vector("b"), t.number("radius", above=0.0),
                                    t.vector("velocity_a", [0, 0, 0]),
                                    t.vector("velocity_b", [0, 0, 0]), *_contact(t)))
        t.finish()
    for t in tables_of(document, "box", path):
        lo, hi = t.vector("minimum"), t.vector("maximum")
        if not np.all(hi > lo):
            raise t.error("maximum", "must exceed 'minimum' on every axis")
        e, mu, margin = _contact(t)
        system.add_collider(Box(lo, hi, t.boolean("open_top", True), 1, e, mu, margin))
        t.finish()


def _contact(t: Table) -> tuple[float, float, float]:
    restitution = t.number("restitution", 0.0, minimum=0.0)
    if restitution > 1.0:
        raise t.error("restitution", "must be between 0 and 1")
    return restitution, t.number("friction", 0.0, minimum=0.0), t.number("margin", 0.0, minimum=0.0)


def _rigid_bodies(tables: list[Table]) -> tuple[list, list]:
    bodies, pushes = [], []
    for n, t in enumerate(tables):
        t.choice("shape", ("box",), "box")
        mass = t.number("mass", above=0.0)
        size = t.vector("size", minimum=0.0)
        if not np.all(size > 0):
            raise t.error("size", "must be positive on every axis")
        orientation = t.vector("orientation", [0, 0, 0, 1], length=4)
        if not np.linalg.norm(orientation) > 0:
            raise t.error("orientation", "must be a non-zero quaternion (x, y, z, w)")
        _check_inertia(t, mass, size)
        body = RigidBody.box(mass, size, position=t.vector("position", [0, 0, 0]),
                             orientation=orientation, velocity=t.vector("velocity", [0, 0, 0]))
        body.set_angular_velocity(t.vector("angular_velocity", [0, 0, 0]))
        raw = t.raw("push", [])
        if not isinstance(raw, list):
            raise t.error("push", "must be an array of tables: write [[rigid.push]]")
        for m, item in enumerate(raw):
            pt = Table(item, f"{t.where} [[rigid.push]] #{m + 1}", t.path)
            pushes.append(Push(n, pt.vector("force"), pt.vector("point", [0, 0, 0]),
                               pt.number("start", 0.0, minimum=0.0),
                               pt.number("duration", above=0.0)))
            pt.finish()
        t.finish()
        bodies.append(body)
    return bodies, pushes


#: Smallest ratio of a rigid body's least to its largest principal inertia: below it the
#: inertia cannot be inverted in floating point to any useful accuracy.
MIN_INERTIA_RATIO = 1e-12


def _check_inertia(t: Table, mass: float, size: np.ndarray) -> None:
    """Refuse a box whose inertia is singular in floating point (a size so small that its
    squares underflow, a denormal mass): the Newton-Euler step inverts it, which raised
    ``LinAlgError: Singular matrix``, or made the spin infinite at the first push."""
    with np.errstate(all="ignore"):
        moments = np.diag(box_inertia(mass, size))
        inverse = 1.0 / moments
    if not (np.isfinite(moments).all() and np.isfinite(inverse).all() and moments.min() > 0
            and moments.min() >= MIN_INERTIA_RATIO * moments.max()):
        raise t.error("size", f"{size.tolist()} with mass {mass:g} kg gives principal "
                              f"inertias {', '.join(f'{m:.3g}' for m in moments)} kg·m², "
                              f"which cannot be inverted (a singular body: make it larger or "
                              f"less thin)")
