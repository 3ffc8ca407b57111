"""Springs between particles: topology, Voigt spring-damper forces, energy and Jacobians.

Sign convention (``docs/formats/scene-toml.md``): with d = x_j − x_i, e = |d| − l and
de/dt = (v_j − v_i)·d/|d|, the force on i is (k e + γ_s de/dt) d/|d| and the force on
j is its opposite, so the damper always resists the change of length. A spring with
rest length 0 is the lecture's ideal zero-length spring, force on i = k (x_j − x_i)
(plus damping along d).

The per-spring loops are compiled with numba: a scatter-add over springs is the
simulator's hot loop (numpy's ``bincount`` version is about ten times slower on a
64 × 64 cloth, see dynamics-notes.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np

from dynamics.sim.pairs import add_pair_force, concatenate_records, separation

#: Spring kinds (the ``kind`` codes); heat conducts along STRUCTURAL and USER springs.
USER, STRUCTURAL, SHEAR, BEND = 0, 1, 2, 3
KIND_NAMES = {USER: "user", STRUCTURAL: "structural", SHEAR: "shear", BEND: "bend"}

_EPS = 1e-12


@dataclass
class Springs:
    """Springs between particles (structure of arrays, one row per spring).

    Attributes
    ----------
    pairs : (M, 2) int
        Particle indices (i, j) of each spring.
    rest_length : (M,) float, metres (0 = zero-length spring)
    stiffness : (M,) float, N/m (the current value; heat may lower it)
    damping : (M,) float, N·s/m, Voigt damper along the spring
    kind : (M,) int8, one of USER, STRUCTURAL, SHEAR, BEND
    base_stiffness : (M,) float, N/m, k⁰ (stiffness at low temperature)
    broken : (M,) bool, springs that have melted (stiffness and damping are 0 for good)
    version : int
        Increased whenever stiffness or damping change, so solvers know when a
        cached matrix factorisation is stale.
    """

    pairs: np.ndarray
    rest_length: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    kind: np.ndarray = field(default=None)  # type: ignore[assignment]
    base_stiffness: np.ndarray = field(default=None)  # type: ignore[assignment]
    broken: np.ndarray = field(default=None)  # type: ignore[assignment]
    version: int = 0

    def __post_init__(self) -> None:
        self.pairs = np.ascontiguousarray(self.pairs, dtype=np.int64).reshape(-1, 2)
        m = len(self.pairs)
        self.rest_length = _as_float(self.rest_length, m)
        self.stiffness = _as_float(self.stiffness, m)
        self.damping = _as_float(self.damping, m)
        self.kind = np.broadcast_to(np.asarray(USER if self.kind is None else self.kind,
                                               dtype=np.int8), (m,)).copy()
        self.base_stiffness = (self.stiffness.copy() if self.base_stiffness is None
                               else _as_float(self.base_stiffness, m))
        self.broken = (np.zeros(m, bool) if self.broken is None
                       else np.broadcast_to(np.asarray(self.broken, bool), (m,)).copy())
        if m and (np.any(self.stiffness < 0) or np.any(self.damping < 0)
                  or np.any(self.rest_length < 0)):
            raise ValueError("spring stiffness, damping and rest length must be >= 0")

    @classmethod
    def empty(cls) -> "Springs":
        """No springs."""
        return cls(np.zeros((0, 2), np.int64), np.zeros(0), np.zeros(0), np.zeros(0))

    @classmethod
    def between(cls, positions: np.ndarray, pairs: np.ndarray, stiffness, damping=0.0,
                rest_length=None, kind=USER) -> "Springs":
        """Springs over ``pairs`` whose rest length defaults to the current distance.

        Parameters
        ----------
        positions : (N, 3) float, metres
        pairs : (M, 2) int
        stiffness, damping : float or (M,) float, N/m and N·s/m
        rest_length : float or (M,) float, metres, optional (default: current length)
        kind : int or (M,) int
        """
        pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
        if rest_length is None:
            rest_length = np.linalg.norm(positions[pairs[:, 1]] - positions[pairs[:, 0]], axis=1)
        return cls(pairs, rest_length, stiffness, damping, kind)

    def __len__(self) -> int:
        return len(self.pairs)

    def mark_changed(self) -> None:
        """Record that stiffness or damping changed (invalidates cached factorisations)."""
        self.version += 1

    def copy(self) -> "Springs":
        """A deep copy."""
        return Springs(self.pairs.copy(), self.rest_length.copy(), self.stiffness.copy(),
                       self.damping.copy(), self.kind.copy(), self.base_stiffness.copy(),
                       self.broken.copy(), self.version)

    def offset(self, by: int) -> "Springs":
        """A copy whose particle indices are shifted by ``by`` (for joining systems)."""
        out = self.copy()
        out.pairs += by
        return out


def concatenate(parts: list[Springs]) -> Springs:
    """Join spring sets (their ``pairs`` must already index the joined particles)."""
    return concatenate_records(Springs, parts) if parts else Springs.empty()


def _as_float(value, m: int) -> np.ndarray:
    return np.ascontiguousarray(np.broadcast_to(np.asarray(value, dtype=float), (m,)),
                                dtype=float).copy()


@numba.njit(cache=True, nogil=True)
def _accumulate_spring_forces(position, velocity, pairs, rest, stiffness, damping, out):
    for s in range(pairs.shape[0]):
        k = stiffness[s]
        g = damping[s]
        if k == 0.0 and g == 0.0:
            continue
        i = pairs[s, 0]
        j = pairs[s, 1]
        dx, dy, dz, length = separation(position, i, j)
        if length < _EPS:
            continue
        inv = 1.0 / length
        ux = dx * inv
        uy = dy * inv
        uz = dz * inv
        rate = ((velocity[j, 0] - velocity[i, 0]) * ux + (velocity[j, 1] - velocity[i, 1]) * uy
                + (velocity[j, 2] - velocity[i, 2]) * uz)
        scale = k * (length - rest[s]) + g * rate
        add_pair_force(out, i, j, scale * ux, scale * uy, scale * uz)


def accumulate_spring_forces(springs: Springs, position: np.ndarray, velocity: np.ndarray,
                             out: np.ndarray) -> None:
    """Add every spring's Voigt force to ``out`` in place.

    Parameters
    ----------
    springs : Springs
    position, velocity : (N, 3) float, metres and m/s (C-contiguous)
    out : (N, 3) float, newtons, accumulated into
    """
    if len(springs):
        _accumulate_spring_forces(position, velocity, springs.pairs, springs.rest_length,
                                  springs.stiffness, springs.damping, out)


def spring_forces(springs: Springs, position: np.ndarray, velocity: np.ndarray) -> np.ndarray:
    """(N, 3) total spring force on every particle, newtons."""
    out = np.zeros_like(position, dtype=float)
    accumulate_spring_forces(springs, np.ascontiguousarray(position, float),
                             np.ascontiguousarray(velocity, float), out)
    return out


def spring_energy(springs: Springs, position: np.ndarray) -> float:
    """Elastic energy Σ ½ k (|x_j − x_i| − l)², joules."""
    if not len(springs):
        return 0.0
    d = position[springs.pairs[:, 1]] - position[springs.pairs[:, 0]]
    e = np.linalg.norm(d, axis=1) - springs.rest_length
    return 0.5 * float(np.sum(springs.stiffness * e * e))


@numba.njit(cache=True, nogil=True)
def _spring_jacobian_blocks(position, pairs, rest, stiffness, damping, kx, kv):
    for s in range(pairs.shape[0]):
        i = pairs[s, 0]
        j = pairs[s, 1]
        d0, d1, d2, length = separation(position, i, j)
        k = stiffness[s]
        g = damping[s]
        if length < _EPS:
            # zero-length spring at zero length: isotropic stiffness k I, damping undefined -> 0
            for a in range(3):
                for b in range(3):
                    kx[s, a, b] = k if a == b else 0.0
                    kv[s, a, b] = 0.0
            continue
        u = (d0 / length, d1 / length, d2 / length)
        # transverse term k (1 - l/|d|) is dropped when compressed (Baraff & Witkin) so
        # the block stays positive semi-definite and the implicit matrix positive definite
        t = 1.0 - rest[s] / length
        if t < 0.0:
            t = 0.0
        for a in range(3):
            for b in range(3):
                uu = u[a] * u[b]
                eye = 1.0 if a == b else 0.0
                kx[s, a, b] = k * (uu + t * (eye - uu))
                kv[s, a, b] = g * uu


def spring_jacobian_blocks(springs: Springs, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-spring 3 × 3 blocks of the stiffness and damping Jacobians.

    For spring s between i and j, −∂f_i/∂x_i = ∂f_i/∂x_j = K_s and likewise
    −∂f_i/∂v_i = ∂f_i/∂v_j = G_s, so the global stiffness and damping matrices
    K = −∂f/∂x and G = −∂f/∂v are block graph Laplacians of these blocks.

    Returns
    -------
    kx : (M, 3, 3) float, N/m, K_s = k [û ûᵀ + max(0, 1 − l/|d|) (I − û ûᵀ)]
    kv : (M, 3, 3) float, N·s/m, G_s = γ_s û ûᵀ
    """
    m = len(springs)
    kx = np.empty((m, 3, 3))
    kv = np.empty((m, 3, 3))
    if m:
        _spring_jacobian_blocks(np.ascontiguousarray(position, float), springs.pairs,
                                springs.rest_length, springs.stiffness, springs.damping, kx, kv)
    return kx, kv
