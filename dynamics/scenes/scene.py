"""Scene files (TOML, DESIGN 3.6) -> a simulation -> a result saved as ``.npz``.

Particle indices follow the order of creation: first every ``[[particle]]`` (in file
order), then the generators in this order: ``[[rope]]``, ``[[cloth]]``, ``[[lattice]]``,
``[[fluid]]`` (each in file order). ``[[spring]]`` ``between`` indices use this order.

Every key is checked: an unknown key, a wrong type or an impossible value is a
:class:`mocap.errors.MocapError` naming the file, the table and the key. The shipped
example scenes (``dynamics/scenes/examples/*.toml``) document every
table; :func:`example_scene_path` finds them by name.
"""
from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mocap.atomic import atomic_path
from mocap.errors import MocapError

from dynamics.sim import builders
from dynamics.sim.collisions import Box, Capsule, Plane, Sphere
from dynamics.sim.fluid import FluidForce, equilibrium_beta
from dynamics.sim.forces import Drag, Gravity, Wind
from dynamics.sim.integrators import IMPLICIT_SOLVERS, INTEGRATORS, advance
from dynamics.sim.particles import Particles
from dynamics.sim.rigid import RigidBody, newton_euler_step
from dynamics.sim.springs import STRUCTURAL, USER, Springs
from dynamics.sim.springs import concatenate as concatenate_springs
from dynamics.sim.system import System
from dynamics.sim.thermal import HeatModel, HeatSource

#: Folder of the example scenes shipped with the package.
SCENES_DIR = Path(__file__).resolve().parent / "examples"

_TOP_LEVEL = {"simulation", "gravity", "damping", "particle", "spring", "cloth", "rope",
              "lattice", "fluid", "heat", "plane", "sphere", "capsule", "box", "wind", "rigid",
              "title", "description"}


# -- validated access to TOML tables ------------------------------------------------------------
class _Table:
    """A TOML table whose keys are type-checked and must all be known."""

    def __init__(self, data, where: str, path):
        if not isinstance(data, dict):
            raise MocapError(f"{where} must be a table", path)
        self.data, self.where, self.path = data, where, path
        self.used: set[str] = set()

    def error(self, key: str, problem: str) -> MocapError:
        return MocapError(f"{self.where}: '{key}' {problem}", self.path)

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default=None):
        self.used.add(key)
        return self.data.get(key, default)

    def number(self, key: str, default=None, minimum=None, above=None) -> float:
        self.used.add(key)
        if key not in self.data:
            if default is None:
                raise self.error(key, "is required")
            return float(default)
        value = self.data[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise self.error(key, f"must be a finite number, not {value!r}")
        if minimum is not None and value < minimum:
            raise self.error(key, f"must be >= {minimum}, not {value!r}")
        if above is not None and not value > above:
            raise self.error(key, f"must be > {above}, not {value!r}")
        return float(value)

    def integer(self, key: str, default=None, minimum=None) -> int:
        self.used.add(key)
        if key not in self.data:
            if default is None:
                raise self.error(key, "is required")
            return int(default)
        value = self.data[key]
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, f"must be an integer, not {value!r}")
        if minimum is not None and value < minimum:
            raise self.error(key, f"must be >= {minimum}, not {value!r}")
        return int(value)

    def boolean(self, key: str, default: bool) -> bool:
        self.used.add(key)
        value = self.data.get(key, default)
        if not isinstance(value, bool):
            raise self.error(key, f"must be true or false, not {value!r}")
        return value

    def vector(self, key: str, default=None, length: int = 3, integer: bool = False,
               minimum=None) -> np.ndarray:
        self.used.add(key)
        if key not in self.data:
            if default is None:
                raise self.error(key, "is required")
            return np.asarray(default, dtype=int if integer else float)
        value = self.data[key]
        ok = (isinstance(value, list) and len(value) == length and all(
            isinstance(v, int) if integer else isinstance(v, (int, float)) for v in value)
            and not any(isinstance(v, bool) for v in value))
        if not ok or (not integer and not all(math.isfinite(v) for v in value)):
            kind = "integers" if integer else "numbers"
            raise self.error(key, f"must be a list of {length} {kind}, not {value!r}")
        if minimum is not None and any(v < minimum for v in value):
            raise self.error(key, f"must have every entry >= {minimum}, not {value!r}")
        return np.asarray(value, dtype=int if integer else float)

    def choice(self, key: str, choices, default=None) -> str:
        self.used.add(key)
        value = self.data.get(key, default)
        if value is None:
            raise self.error(key, "is required")
        if value not in choices:
            raise self.error(key, f"must be one of {', '.join(choices)}; not {value!r}")
        return value

    def per_kind(self, key: str, default) -> dict | float:
        """A number or a {structural, shear, bend} table of numbers >= 0."""
        self.used.add(key)
        value = self.data.get(key, default)
        if isinstance(value, dict):
            unknown = set(value) - {"structural", "shear", "bend"}
            if unknown:
                raise self.error(key, f"has unknown spring kind(s) {sorted(unknown)}; "
                                      "use structural, shear, bend")
            for kind, v in value.items():
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not v >= 0:
                    raise self.error(key, f"{kind} must be a number >= 0, not {v!r}")
            return {k: float(v) for k, v in value.items()}
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= 0:
            raise self.error(key, f"must be a number >= 0 or a table of structural/shear/bend, "
                                  f"not {value!r}")
        return float(value)

    def finish(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise MocapError(f"{self.where}: unknown key(s) {', '.join(map(repr, unknown))}",
                             self.path)


def _tables(document: dict, key: str, path) -> list[_Table]:
    value = document.get(key, [])
    if isinstance(value, dict):
        raise MocapError(f"'{key}' must be an array of tables: write [[{key}]]", path)
    return [_Table(item, f"[[{key}]] #{n + 1}", path) for n, item in enumerate(value)]


def _table(document: dict, key: str, path) -> _Table | None:
    if key not in document:
        return None
    if isinstance(document[key], list):
        raise MocapError(f"'{key}' must be a single table: write [{key}], not [[{key}]]", path)
    return _Table(document[key], f"[{key}]", path)


# -- the scene ----------------------------------------------------------------------------------
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


def example_scene_path(name: str) -> Path:
    """Path of a shipped example scene by name ("hanging-cloth" or "hanging-cloth.toml")."""
    stem = name[:-5] if name.endswith(".toml") else name
    path = SCENES_DIR / f"{stem}.toml"
    if not path.is_file():
        names = ", ".join(sorted(p.stem for p in SCENES_DIR.glob("*.toml")))
        raise MocapError(f"no such scene file or example scene (examples: {names})", name)
    return path


def load_scene(path: str | os.PathLike) -> Scene:
    """Read and validate a TOML scene file (DESIGN 3.6) and build its :class:`Scene`."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MocapError("scene file not found", path) from None
    except (OSError, UnicodeDecodeError) as error:
        raise MocapError(f"cannot read scene file: {error}", path) from None
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise MocapError(f"not valid TOML: {error}", path) from None
    return build_scene(document, path)


def build_scene(document: dict, path=None) -> Scene:
    """Build a :class:`Scene` from a parsed TOML document (a dict)."""
    unknown = sorted(set(document) - _TOP_LEVEL)
    if unknown:
        raise MocapError(f"unknown table(s) {', '.join(map(repr, unknown))}; known: "
                         + ", ".join(sorted(_TOP_LEVEL)), path)
    simulation = _table(document, "simulation", path) or _Table({}, "[simulation]", path)
    dt = simulation.number("dt", 0.001, above=0.0)
    steps = simulation.integer("steps", 1000, minimum=1)
    integrator = simulation.choice("integrator", INTEGRATORS, "symplectic-euler")
    save_every = simulation.integer("save_every", max(1, steps // 200), minimum=1)
    solver = simulation.choice("solver", IMPLICIT_SOLVERS, "projective")
    iterations = simulation.integer("iterations", 10, minimum=1)
    speed_limit = simulation.number("speed_limit", 1000.0, above=0.0)
    simulation.finish()

    system = System(speed_limit=speed_limit)
    gravity_table = _table(document, "gravity", path)
    gravity = np.zeros(3)
    if gravity_table is not None:
        gravity = gravity_table.vector("g", [0.0, -9.81, 0.0])
        gravity_table.finish()
        system.add_force(Gravity(gravity))
    damping_table = _table(document, "damping", path)
    if damping_table is not None:
        gamma = damping_table.number("gamma", 0.0, minimum=0.0)
        damping_table.finish()
        if gamma:
            system.add_force(Drag(gamma))

    _add_particles(system, _tables(document, "particle", path))
    fluid_forces, molten = _add_bodies(system, document, path)
    _add_springs(system, _tables(document, "spring", path))
    for force in fluid_forces:
        system.add_force(force)
    _add_heat(system, _table(document, "heat", path))
    for table, spacing, index in molten:
        if system.heat is None or not np.isfinite(system.heat.melt):
            raise MocapError(f"{table.where} needs [heat] with a 'melt' temperature", path)
        system.add_force(_fluid_force(table, spacing, index, system.heat.melt))
    _add_colliders(system, document, path)
    wind = _table(document, "wind", path)
    if wind is not None:
        system.add_force(Wind(wind.vector("velocity"), wind.number("coefficient", 0.01, minimum=0),
                              wind.number("gust_amplitude", 0.0, minimum=0),
                              wind.number("gust_frequency", 0.5, minimum=0)))
        wind.finish()
    bodies, pushes = _rigid_bodies(_tables(document, "rigid", path))
    if len(system.particles) == 0 and not bodies:
        raise MocapError("the scene has nothing to simulate: add particles, a body or [[rigid]]",
                         path)
    title = document.get("title", "")
    if not isinstance(title, str) or not isinstance(document.get("description", ""), str):
        raise MocapError("'title' and 'description' must be strings", path)
    return Scene(system, dt, steps, integrator, save_every, solver, iterations, gravity,
                 bodies, pushes, title, None if path is None else os.fspath(path))


def _colour(table: _Table, default) -> np.ndarray:
    return table.vector("colour", default, minimum=0.0).clip(0.0, 1.0)


def _add_particles(system: System, tables: list[_Table]) -> None:
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


def _pin_list(table: _Table):
    pins = table.raw("pin", [])
    if isinstance(pins, str):
        pins = [pins]
    if not isinstance(pins, list):
        raise table.error("pin", f"must be a list of names or [row, column] pairs, not {pins!r}")
    return pins


def _finish_body(system: System, body: builders.Body, table: _Table, colour) -> np.ndarray:
    body.particles.colour[:] = _colour(table, colour)
    body.particles.temperature[:] = table.number("temperature", 293.15, above=0.0)
    body.particles.velocity[:] = table.vector("velocity", [0, 0, 0])
    table.finish()
    return system.add(body)


#: Most particles one scene may create (memory and time guard for typos in resolutions).
MAX_PARTICLES = 2_000_000
#: Largest in-memory result (saved frames) a run may build, bytes.
MAX_OUTPUT_BYTES = 4_000_000_000


def _check_count(t: _Table, count: int, system: System, key: str) -> None:
    if count + len(system.particles) > MAX_PARTICLES:
        raise t.error(key, f"would make {count} particles; a scene may have at most "
                           f"{MAX_PARTICLES}")


def _positive_sizes(t: _Table, key: str, length: int = 3) -> np.ndarray:
    size = t.vector(key, length=length)
    if not np.all(size > 0):
        raise t.error(key, f"must be positive on every axis, not {size.tolist()}")
    return size


def _add_bodies(system: System, document: dict, path) -> tuple[list, list]:
    """Ropes, cloths, lattices and fluid blocks, in that order.

    Returns the fluid forces of [[fluid]] blocks and the pending molten-fluid settings
    of lattices (table, spacing, particle indices), built once [heat] is known.
    """
    fluid_forces, molten = [], []
    for t in _tables(document, "rope", path):
        count = t.integer("particles", 20, minimum=2)
        _check_count(t, count, system, "particles")
        try:
            body = builders.rope(t.vector("start"), t.vector("end"), count,
                                 t.number("mass", 0.2, above=0.0),
                                 t.number("stiffness", 500.0, minimum=0.0),
                                 t.number("damping", 0.5, minimum=0.0),
                                 t.number("bend_stiffness", 0.0, minimum=0.0), _pin_list(t))
        except (ValueError, IndexError) as error:
            raise MocapError(f"{t.where}: {error}", path) from None
        _finish_body(system, body, t, [0.6, 0.4, 0.2])
    for t in _tables(document, "cloth", path):
        resolution = t.vector("resolution", [16, 16], length=2, integer=True, minimum=2)
        _check_count(t, int(np.prod(resolution)), system, "resolution")
        try:
            body = builders.cloth_grid(
                t.vector("origin"), _positive_sizes(t, "size", 2), resolution,
                t.number("mass", 0.5, above=0.0), t.per_kind("stiffness", 500.0),
                t.per_kind("damping", 0.0), _pin_list(t),
                t.vector("u_axis", [1, 0, 0]), t.vector("v_axis", [0, 0, 1]))
        except (ValueError, IndexError) as error:
            raise MocapError(f"{t.where}: {error}", path) from None
        _finish_body(system, body, t, [0.2, 0.4, 0.8])
    for t in _tables(document, "lattice", path):
        resolution = t.vector("resolution", [5, 5, 5], integer=True, minimum=2)
        _check_count(t, int(np.prod(resolution)), system, "resolution")
        size = _positive_sizes(t, "size")
        try:
            body = builders.lattice_block(
                t.vector("origin"), size, resolution, t.number("mass", 1.0, above=0.0),
                t.per_kind("stiffness", 2000.0), t.per_kind("damping", 1.0), _pin_list(t))
        except (ValueError, IndexError) as error:
            raise MocapError(f"{t.where}: {error}", path) from None
        fluid = t.raw("molten_fluid")
        index = _finish_body(system, body, t, [0.7, 0.7, 0.75])
        if fluid is not None:
            spacing = float(np.min(size / (resolution - 1)))
            molten.append((_Table(fluid, f"{t.where} molten_fluid", path), spacing, index))
    for t in _tables(document, "fluid", path):
        spacing = t.number("spacing", above=0.0)
        size = t.vector("size", minimum=0.0)
        count = int(np.prod(np.floor(size / spacing + 1e-9) + 1))
        _check_count(t, count, system, "spacing")
        body = builders.particle_block(t.vector("origin"), size, spacing,
                                       t.number("mass", 1.0, above=0.0),
                                       t.number("jitter", 0.0, minimum=0.0),
                                       t.integer("seed", 0))
        # the pair-force keys live in the same table; _finish_body checks for unknown keys
        force = _fluid_force(t, spacing, None, None, finish=False)
        force.members = _finish_body(system, body, t, [0.1, 0.5, 0.9])
        fluid_forces.append(force)
    return fluid_forces, molten


def _fluid_force(t: _Table, spacing: float, members, melt, finish: bool = True) -> FluidForce:
    alpha = t.number("alpha", above=0.0)
    zeta = t.number("zeta", 0.5 * spacing, minimum=0.0)
    a = t.number("a", 2.0, above=0.0)
    b = t.number("b", 4.0, above=0.0)
    beta = t.number("beta", equilibrium_beta(alpha, zeta, spacing, a, b), above=0.0)
    cutoff = t.number("cutoff", 1.25 * spacing, above=0.0)
    viscosity = t.number("viscosity", 0.0, minimum=0.0)
    if finish:
        t.finish()
    return FluidForce(alpha, beta, zeta, cutoff, a, b, viscosity, members,
                      None if melt is None or not np.isfinite(melt) else melt)


def _add_springs(system: System, tables: list[_Table]) -> None:
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


def _add_heat(system: System, t: _Table | None) -> None:
    if t is None:
        return
    sources = []
    raw_sources = t.raw("source", [])
    if isinstance(raw_sources, dict) or not isinstance(raw_sources, list):
        raise t.error("source", "must be an array of tables: write [[heat.source]]")
    for n, item in enumerate(raw_sources):
        st = _Table(item, f"[[heat.source]] #{n + 1}", t.path)
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
    for t in _tables(document, "plane", path):
        normal = t.vector("normal", [0, 1, 0])
        if not np.linalg.norm(normal) > 0:
            raise t.error("normal", "must be non-zero")
        system.add_collider(Plane(t.vector("point", [0, 0, 0]), normal, *_contact(t)))
        t.finish()
    for t in _tables(document, "sphere", path):
        system.add_collider(Sphere(t.vector("centre"), t.number("radius", above=0.0),
                                   t.vector("velocity", [0, 0, 0]), *_contact(t)))
        t.finish()
    for t in _tables(document, "capsule", path):
        system.add_collider(Capsule(t.vector("a"), t.vector("b"), t.number("radius", above=0.0),
                                    t.vector("velocity_a", [0, 0, 0]),
                                    t.vector("velocity_b", [0, 0, 0]), *_contact(t)))
        t.finish()
    for t in _tables(document, "box", path):
        lo, hi = t.vector("minimum"), t.vector("maximum")
        if not np.all(hi > lo):
            raise t.error("maximum", "must exceed 'minimum' on every axis")
        e, mu, margin = _contact(t)
        system.add_collider(Box(lo, hi, t.boolean("open_top", True), 1, e, mu, margin))
        t.finish()


def _contact(t: _Table) -> tuple[float, float, float]:
    restitution = t.number("restitution", 0.0, minimum=0.0)
    if restitution > 1.0:
        raise t.error("restitution", "must be between 0 and 1")
    return restitution, t.number("friction", 0.0, minimum=0.0), t.number("margin", 0.0, minimum=0.0)


def _rigid_bodies(tables: list[_Table]) -> tuple[list, list]:
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
        body = RigidBody.box(mass, size, position=t.vector("position", [0, 0, 0]),
                             orientation=orientation, velocity=t.vector("velocity", [0, 0, 0]))
        body.set_angular_velocity(t.vector("angular_velocity", [0, 0, 0]))
        raw = t.raw("push", [])
        if not isinstance(raw, list):
            raise t.error("push", "must be an array of tables: write [[rigid.push]]")
        for m, item in enumerate(raw):
            pt = _Table(item, f"{t.where} [[rigid.push]] #{m + 1}", t.path)
            pushes.append(Push(n, pt.vector("force"), pt.vector("point", [0, 0, 0]),
                               pt.number("start", 0.0, minimum=0.0),
                               pt.number("duration", above=0.0)))
            pt.finish()
        t.finish()
        bodies.append(body)
    return bodies, pushes


# -- running -------------------------------------------------------------------------------------
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
    from mocap.progress import progress

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
        for body in bodies:
            newton_euler_step(body, scene.dt, scene.gravity)
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
    try:
        with np.load(path, allow_pickle=False) as data:
            return {key: data[key] for key in data.files}
    except (OSError, ValueError) as error:
        raise MocapError(f"cannot read simulation result: {error}", path) from None
