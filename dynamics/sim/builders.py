"""Builders of mass-spring bodies: rope, cloth grid, 3-D lattice block, particle block.

Each builder returns a :class:`Body` (particles + springs indexed locally from 0, and the
grid shape) to add to a :class:`dynamics.sim.system.System` with ``system.add(body)``,
which returns the global indices of the body's particles.

Examples
--------
>>> cape = cloth_grid(origin=[-0.25, 1.5, 0.0], size=[0.5, 0.8], resolution=[12, 16],
...                   mass=0.4, u_axis=[1, 0, 0], v_axis=[0, -1, 0], pin=["top"])
>>> cape.particles.count, cape.shape
(192, (16, 12))
>>> cape.named("top-left"), cape.named("top-right")
(array([0]), array([11]))
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dynamics.sim.particles import Particles
from dynamics.sim.springs import BEND, SHEAR, STRUCTURAL, Springs

#: Stiffness (N/m) per spring kind when a builder is given one number.
_KINDS = ("structural", "shear", "bend")


@dataclass
class Body:
    """Particles and springs made by a builder (spring indices are local, from 0).

    Attributes
    ----------
    particles : Particles
    springs : Springs
    shape : tuple of int, the grid's shape in index order (rows, columns) for a cloth,
        (nx, ny, nz) for a lattice, (n,) for a rope; particle index = np.ravel_multi_index
    kind : str, "rope" | "cloth" | "lattice" | "block"
    """

    particles: Particles
    springs: Springs
    shape: tuple
    kind: str

    def index(self, *grid_index) -> int:
        """Local particle index of a grid position (row, column) / (i, j, k) / (i,)."""
        return int(np.ravel_multi_index(grid_index, self.shape))

    def named(self, *names) -> np.ndarray:
        """Local indices of named particles.

        Cloth: "top-left", "top-right", "bottom-left", "bottom-right" (corners), "top",
        "bottom", "left", "right" (whole edges; row 0 is the top, column 0 the left).
        Rope: "start", "end". Any body: "all", or an explicit [row, column] / [i] pair.
        """
        out = []
        grid = np.arange(int(np.prod(self.shape))).reshape(self.shape)
        for name in names:
            if isinstance(name, (list, tuple, np.ndarray)):
                out.append(np.atleast_1d(grid[tuple(int(v) for v in name)]))
                continue
            if name == "all":
                out.append(grid.ravel())
            elif self.kind == "rope" and name in ("start", "end"):
                out.append(np.array([0 if name == "start" else grid.size - 1]))
            elif self.kind == "cloth" and name in _CLOTH_NAMES:
                out.append(np.atleast_1d(grid[_CLOTH_NAMES[name]]).ravel())
            else:
                raise ValueError(f"unknown particle name {name!r} for a {self.kind}")
        return np.unique(np.concatenate(out)) if out else np.zeros(0, np.int64)


_CLOTH_NAMES = {
    "top-left": (0, 0), "top-right": (0, -1), "bottom-left": (-1, 0), "bottom-right": (-1, -1),
    "top": (0, slice(None)), "bottom": (-1, slice(None)),
    "left": (slice(None), 0), "right": (slice(None), -1),
}


def _per_kind(value, name: str) -> dict[str, float]:
    """Expand a number or a {structural, shear, bend} table into the three kinds."""
    if isinstance(value, dict):
        unknown = set(value) - set(_KINDS)
        if unknown:
            raise ValueError(f"{name}: unknown spring kind(s) {sorted(unknown)}; use "
                             + ", ".join(_KINDS))
        return {kind: float(value.get(kind, 0.0)) for kind in _KINDS}
    return {kind: float(value) for kind in _KINDS}


def grid_pairs(shape: tuple, offset: tuple) -> np.ndarray:
    """(P, 2) index pairs of every grid node and its neighbour at ``offset`` (vectorised).

    Parameters
    ----------
    shape : grid shape, e.g. (rows, columns) or (nx, ny, nz)
    offset : integer offset per axis, e.g. (0, 1) or (1, -1, 0)
    """
    grid = np.arange(int(np.prod(shape))).reshape(shape)
    source = tuple(slice(max(0, -o), n - max(0, o)) for n, o in zip(shape, offset))
    target = tuple(slice(max(0, o), n - max(0, -o)) for n, o in zip(shape, offset))
    a, b = grid[source].ravel(), grid[target].ravel()
    return np.stack([a, b], axis=1)


_OFFSETS_2D = {
    STRUCTURAL: [(0, 1), (1, 0)],
    SHEAR: [(1, 1), (1, -1)],
    BEND: [(0, 2), (2, 0)],
}
_OFFSETS_3D = {
    STRUCTURAL: [(1, 0, 0), (0, 1, 0), (0, 0, 1)],
    SHEAR: [(1, 1, 0), (1, -1, 0), (1, 0, 1), (1, 0, -1), (0, 1, 1), (0, 1, -1),
            (1, 1, 1), (1, 1, -1), (1, -1, 1), (1, -1, -1)],
    BEND: [(2, 0, 0), (0, 2, 0), (0, 0, 2)],
}


def _grid_springs(positions: np.ndarray, shape: tuple, offsets: dict, stiffness: dict,
                  damping: dict) -> Springs:
    pairs, kinds, k, g = [], [], [], []
    for kind, name in ((STRUCTURAL, "structural"), (SHEAR, "shear"), (BEND, "bend")):
        if stiffness[name] == 0.0 and damping[name] == 0.0:
            continue
        for offset in offsets[kind]:
            pp = grid_pairs(shape, offset)
            pairs.append(pp)
            kinds.append(np.full(len(pp), kind, np.int8))
            k.append(np.full(len(pp), stiffness[name]))
            g.append(np.full(len(pp), damping[name]))
    if not pairs:
        return Springs.empty()
    pairs = np.concatenate(pairs)
    rest = np.linalg.norm(positions[pairs[:, 1]] - positions[pairs[:, 0]], axis=1)
    return Springs(pairs, rest, np.concatenate(k), np.concatenate(g), np.concatenate(kinds))


def rope(start, end, particles: int, mass: float, stiffness: float = 500.0,
         damping: float = 0.5, bend_stiffness: float = 0.0, pin=("start",)) -> Body:
    """A chain of ``particles`` point masses from ``start`` to ``end``.

    Parameters
    ----------
    start, end : (3,) float, metres
    particles : int >= 2
    mass : float, kg, the whole rope (split evenly)
    stiffness, damping : float, N/m and N·s/m of each link (structural spring)
    bend_stiffness : float, N/m of the springs skipping one particle (0: none)
    pin : names ("start", "end") or local indices to pin
    """
    if particles < 2:
        raise ValueError("a rope needs at least 2 particles")
    t = np.linspace(0.0, 1.0, particles)[:, None]
    start, end = np.asarray(start, float), np.asarray(end, float)
    position = start + t * (end - start)
    body_particles = Particles(position, 0.0, mass / particles, False)
    k = {"structural": stiffness, "shear": 0.0, "bend": bend_stiffness}
    g = {"structural": damping, "shear": 0.0, "bend": damping if bend_stiffness else 0.0}
    springs = _grid_springs(position, (particles,), {STRUCTURAL: [(1,)], SHEAR: [], BEND: [(2,)]},
                            k, g)
    body = Body(body_particles, springs, (particles,), "rope")
    _pin(body, pin)
    return body


def cloth_grid(origin, size, resolution, mass: float, stiffness=500.0, damping=0.0,
               pin=(), u_axis=(1.0, 0.0, 0.0), v_axis=(0.0, 0.0, 1.0)) -> Body:
    """A rectangular cloth of particles with structural, shear and bend springs.

    Particle (row r, column c) sits at origin + c·Δu·u_axis + r·Δv·v_axis; row 0 is the
    "top" edge and column 0 the "left" edge (the names ``pin`` understands).
    Structural springs join 4-neighbours, shear springs the diagonals of each square,
    bend springs every second particle along rows and columns.

    Parameters
    ----------
    origin : (3,) float, metres, the top-left particle
    size : (2,) float, metres, extent along u (columns) and v (rows)
    resolution : (2,) int >= 2, particles along u (columns) and v (rows)
    mass : float, kg, the whole cloth (split evenly)
    stiffness, damping : float or {"structural", "shear", "bend"} table, N/m and N·s/m
    pin : names or [row, column] pairs to pin (see :meth:`Body.named`)
    u_axis, v_axis : (3,) float, the directions of the columns and rows (normalised)
        Default: a horizontal cloth in the X–Z plane (Y up), which swings down when pinned.
    """
    columns, rows = (int(r) for r in resolution)
    if columns < 2 or rows < 2:
        raise ValueError("cloth resolution must be at least 2 × 2")
    u = np.asarray(u_axis, float)
    v = np.asarray(v_axis, float)
    u, v = u / np.linalg.norm(u), v / np.linalg.norm(v)
    su, sv = (float(s) for s in size)
    r, c = np.meshgrid(np.arange(rows), np.arange(columns), indexing="ij")
    position = (np.asarray(origin, float)
                + (c.ravel() * su / (columns - 1))[:, None] * u
                + (r.ravel() * sv / (rows - 1))[:, None] * v)
    body_particles = Particles(position, 0.0, mass / position.shape[0], False)
    springs = _grid_springs(position, (rows, columns), _OFFSETS_2D,
                            _per_kind(stiffness, "stiffness"), _per_kind(damping, "damping"))
    body = Body(body_particles, springs, (rows, columns), "cloth")
    _pin(body, pin)
    return body


def lattice_block(origin, size, resolution, mass: float, stiffness=2000.0, damping=1.0,
                  pin=()) -> Body:
    """A 3-D block of particles joined by springs: a deformable solid.

    Structural springs join axis neighbours, shear springs the face and body diagonals
    of every cell, bend springs every second particle along each axis.

    Parameters
    ----------
    origin : (3,) float, metres, the corner with the smallest coordinates
    size : (3,) float, metres
    resolution : (3,) int >= 2, particles per axis
    mass : float, kg, the whole block
    stiffness, damping : float or {"structural", "shear", "bend"} table
    pin : local indices, [i, j, k] triples or "all"
    """
    shape = tuple(int(r) for r in resolution)
    if len(shape) != 3 or min(shape) < 2:
        raise ValueError("lattice resolution must be three integers >= 2")
    axes = [np.linspace(0.0, float(s), n) for s, n in zip(size, shape)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    position = np.asarray(origin, float) + grid
    body_particles = Particles(position, 0.0, mass / position.shape[0], False)
    springs = _grid_springs(position, shape, _OFFSETS_3D,
                            _per_kind(stiffness, "stiffness"), _per_kind(damping, "damping"))
    body = Body(body_particles, springs, shape, "lattice")
    _pin(body, pin)
    return body


def particle_block(origin, size, spacing: float, mass: float, jitter: float = 0.0,
                   seed: int = 0, velocity=(0.0, 0.0, 0.0)) -> Body:
    """Free particles on a cubic grid filling a box (a fluid's initial shape), no springs.

    Parameters
    ----------
    origin : (3,) float, metres, the box's smallest corner
    size : (3,) float, metres
    spacing : float, metres, grid step
    mass : float, kg, the whole block
    jitter : float, fraction of ``spacing`` of uniform random displacement
    seed : int, for the jitter
    velocity : (3,) float, m/s, initial velocity of every particle
    """
    counts = [max(1, int(np.floor(float(s) / spacing + 1e-9)) + 1) for s in size]
    axes = [np.arange(n) * spacing for n in counts]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    position = np.asarray(origin, float) + grid
    if jitter:
        rng = np.random.default_rng(seed)
        position = position + rng.uniform(-0.5, 0.5, position.shape) * jitter * spacing
    body_particles = Particles(position, np.asarray(velocity, float), mass / len(position), False)
    return Body(body_particles, Springs.empty(), tuple(counts), "block")


def _pin(body: Body, pin) -> None:
    if isinstance(pin, str):
        pin = [pin]
    names = list(pin)
    if not names:
        return
    explicit = [n for n in names if isinstance(n, (int, np.integer))]
    named = [n for n in names if not isinstance(n, (int, np.integer))]
    index = np.concatenate([np.asarray(explicit, dtype=np.int64),
                            body.named(*named) if named else np.zeros(0, np.int64)])
    body.particles.pinned[index] = True
