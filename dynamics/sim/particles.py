"""Point masses: the state every force, integrator and collider works on."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from dynamics.sim.pairs import concatenate_records

#: Colour given to particles when none is asked for (RGB in [0, 1]).
DEFAULT_COLOUR = (0.2, 0.4, 0.8)


@dataclass
class Particles:
    """A set of point masses, one row per particle (structure of arrays).

    Attributes
    ----------
    position : (N, 3) float, metres
    velocity : (N, 3) float, metres per second
    mass : (N,) float, kilograms (> 0)
    pinned : (N,) bool
        Pinned particles are kinematic: no force moves them. Every integrator
        advances them by ``position += dt * velocity`` and never changes their
        velocity, so a caller drives them by setting position and velocity before
        each step (see :meth:`dynamics.sim.system.System.drive_pinned`).
    colour : (N, 3) float, RGB in [0, 1]
    temperature : (N,) float, kelvin
    age : (N,) float, seconds since the particle was created (advanced by the step loop).
    """

    position: np.ndarray
    velocity: np.ndarray
    mass: np.ndarray
    pinned: np.ndarray
    colour: np.ndarray = field(default=None)  # type: ignore[assignment]
    temperature: np.ndarray = field(default=None)  # type: ignore[assignment]
    age: np.ndarray = field(default=None)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        self.position = np.ascontiguousarray(self.position, dtype=float).reshape(-1, 3)
        n = len(self.position)
        self.velocity = np.ascontiguousarray(
            np.broadcast_to(np.asarray(self.velocity, dtype=float), (n, 3)), dtype=float).copy()
        self.mass = np.ascontiguousarray(
            np.broadcast_to(np.asarray(self.mass, dtype=float), (n,)), dtype=float).copy()
        self.pinned = np.broadcast_to(np.asarray(self.pinned, dtype=bool), (n,)).copy()
        colour = DEFAULT_COLOUR if self.colour is None else self.colour
        self.colour = np.broadcast_to(np.asarray(colour, dtype=float), (n, 3)).copy()
        temperature = 293.15 if self.temperature is None else self.temperature
        self.temperature = np.broadcast_to(np.asarray(temperature, dtype=float), (n,)).copy()
        age = 0.0 if self.age is None else self.age
        self.age = np.broadcast_to(np.asarray(age, dtype=float), (n,)).copy()
        if n and not np.all(self.mass > 0):
            raise ValueError("every particle mass must be positive")

    @classmethod
    def empty(cls) -> "Particles":
        """No particles."""
        return cls(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, bool))

    def __len__(self) -> int:
        return len(self.position)

    @property
    def count(self) -> int:
        """Number of particles."""
        return len(self.position)

    @property
    def free(self) -> np.ndarray:
        """(N,) bool: particles that forces move (the complement of ``pinned``)."""
        return ~self.pinned

    @property
    def inverse_mass(self) -> np.ndarray:
        """(N,) float, 1/kg, zero for pinned particles (they do not accelerate)."""
        return np.where(self.pinned, 0.0, 1.0 / self.mass)

    def kinetic_energy(self) -> float:
        """Total kinetic energy Σ ½ m |v|², joules (pinned particles included)."""
        return 0.5 * float(np.einsum("i,ij,ij->", self.mass, self.velocity, self.velocity))

    def momentum(self) -> np.ndarray:
        """(3,) total linear momentum Σ m v, kg·m/s."""
        return self.mass @ self.velocity

    def copy(self) -> "Particles":
        """A deep copy."""
        return Particles(self.position.copy(), self.velocity.copy(), self.mass.copy(),
                         self.pinned.copy(), self.colour.copy(), self.temperature.copy(),
                         self.age.copy())


def concatenate(parts: list[Particles]) -> Particles:
    """Join particle sets end to end (indices of part k are offset by the sizes before it)."""
    return concatenate_records(Particles, parts) if parts else Particles.empty()
