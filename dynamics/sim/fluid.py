"""Particle fluid: the lecture's pairwise attraction/repulsion force with a cut-off.

For particles i, j closer than the cut-off radius,

    g_ij = m_i m_j (x_i − x_j) (−α / (d_ij + ζ)^a + β / d_ij^b),   d_ij = |x_j − x_i|,

with a = 2 and b = 4 by default: long-range attraction, short-range repulsion
(Lennard-Jones-like), equal and opposite on j, so momentum is conserved. An optional
pair viscosity −μ w(d) ((v_i − v_j)·r̂) r̂ (w = 1 − d/cut-off) calms the liquid without
damping its bulk motion.

Neighbours come from a KD-tree (scipy.spatial.cKDTree) built with a Verlet "skin": the
pair list is built for radius cut-off + skin and reused until some particle has moved
more than skin/2, so the cost per step is O(N log N) for the rebuilds and O(pairs)
otherwise. The force loop is compiled with numba.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np
from scipy.spatial import cKDTree

from dynamics.sim.pairs import add_pair_force


def equilibrium_beta(alpha: float, zeta: float, spacing: float, a: float = 2.0,
                     b: float = 4.0) -> float:
    """β that makes the pair force vanish at distance ``spacing``: β = α s^b / (s + ζ)^a."""
    return alpha * spacing ** b / (spacing + zeta) ** a


@numba.njit(cache=True, nogil=True)
def _pair_forces(position, velocity, mass, pairs, hot, use_hot, alpha, beta, zeta, a, b,
                 cutoff, viscosity, out):
    cutoff2 = cutoff * cutoff
    standard = a == 2.0 and b == 4.0
    for p in range(pairs.shape[0]):
        i = pairs[p, 0]
        j = pairs[p, 1]
        if use_hot and not (hot[i] or hot[j]):
            continue
        d0 = position[i, 0] - position[j, 0]
        d1 = position[i, 1] - position[j, 1]
        d2 = position[i, 2] - position[j, 2]
        dist2 = d0 * d0 + d1 * d1 + d2 * d2
        if dist2 >= cutoff2 or dist2 < 1e-24:
            continue
        dist = np.sqrt(dist2)
        if standard:
            near = dist + zeta
            scale = mass[i] * mass[j] * (-alpha / (near * near) + beta / (dist2 * dist2))
        else:
            scale = mass[i] * mass[j] * (-alpha / (dist + zeta) ** a + beta / dist ** b)
        if viscosity != 0.0:
            rate = ((velocity[i, 0] - velocity[j, 0]) * d0 + (velocity[i, 1] - velocity[j, 1]) * d1
                    + (velocity[i, 2] - velocity[j, 2]) * d2) / dist2
            scale -= viscosity * (1.0 - dist / cutoff) * rate
        add_pair_force(out, i, j, scale * d0, scale * d1, scale * d2)


@dataclass
class FluidForce:
    """Pairwise fluid force among ``members`` (default: every particle).

    Attributes
    ----------
    alpha : float, attraction strength α (N·m^(a−1)/kg²)
    beta : float, repulsion strength β (N·m^(b−1)/kg²)
    zeta : float, metres, ζ: softens the attraction at short range
    cutoff : float, metres, pairs farther apart feel nothing
    a, b : float, exponents (2 and 4 in the lecture)
    viscosity : float, N·s/m, pair viscosity μ (0: none)
    members : (n,) int or None, the particles that take part
    melt_temperature : float or None, kelvin
        If set, a pair interacts only when at least one of its particles is at or above
        this temperature (molten matter from a melting lattice behaves like a liquid).
    skin : float, metres, Verlet skin of the neighbour list (default: cutoff / 4)
    """

    alpha: float
    beta: float
    zeta: float
    cutoff: float
    a: float = 2.0
    b: float = 4.0
    viscosity: float = 0.0
    members: np.ndarray | None = None
    melt_temperature: float | None = None
    skin: float | None = None
    _pairs: np.ndarray | None = field(default=None, init=False, repr=False)
    _reference: np.ndarray | None = field(default=None, init=False, repr=False)
    rebuilds: int = field(default=0, init=False)

    def __post_init__(self) -> None:
        if not self.cutoff > 0:
            raise ValueError("fluid cut-off radius must be positive")
        if self.skin is None:
            self.skin = 0.25 * self.cutoff
        if self.members is not None:
            self.members = np.asarray(self.members, dtype=np.int64)

    def neighbour_pairs(self, position: np.ndarray) -> np.ndarray:
        """(P, 2) candidate pairs (within cut-off + skin), rebuilt only when needed."""
        current = position if self.members is None else position[self.members]
        if (self._pairs is not None and self._reference is not None
                and self._reference.shape == current.shape):
            moved2 = np.einsum("ij,ij->i", current - self._reference, current - self._reference)
            if moved2.max(initial=0.0) < (0.5 * self.skin) ** 2:
                return self._pairs
        tree = cKDTree(current)
        pairs = tree.query_pairs(self.cutoff + self.skin, output_type="ndarray").astype(np.int64)
        if self.members is not None:
            pairs = self.members[pairs]
        # sorted pairs touch memory in order: faster scatter in the force loop
        pairs = pairs[np.argsort(pairs[:, 0], kind="stable")]
        self._pairs = np.ascontiguousarray(pairs)
        self._reference = current.copy()
        self.rebuilds += 1
        return self._pairs

    def accumulate(self, particles, position, velocity, time, out) -> None:
        pairs = self.neighbour_pairs(position)
        if not len(pairs):
            return
        use_hot = self.melt_temperature is not None
        hot = (particles.temperature >= self.melt_temperature) if use_hot else np.zeros(1, bool)
        if use_hot and not hot.any():
            return
        _pair_forces(position, velocity, particles.mass, pairs, hot, use_hot, float(self.alpha),
                     float(self.beta), float(self.zeta), float(self.a), float(self.b),
                     float(self.cutoff), float(self.viscosity), out)


def fluid_forces_bruteforce(position: np.ndarray, mass: np.ndarray, alpha: float, beta: float,
                            zeta: float, cutoff: float, a: float = 2.0,
                            b: float = 4.0) -> np.ndarray:
    """(N, 3) the same force summed over all N² pairs with numpy (reference; O(N²) memory).

    Parameters
    ----------
    position : (N, 3) float, metres
    mass : (N,) float, kg
    """
    diff = position[:, None, :] - position[None, :, :]            # x_i − x_j
    dist = np.linalg.norm(diff, axis=2)
    np.fill_diagonal(dist, np.inf)
    inside = dist < cutoff
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(inside, -alpha / (dist + zeta) ** a + beta / dist ** b, 0.0)
    scale *= mass[:, None] * mass[None, :]
    return np.einsum("ij,ijk->ik", scale, diff)
