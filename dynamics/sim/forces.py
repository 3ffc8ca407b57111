"""External and per-particle forces: gravity, viscous drag, wind, user callbacks.

Every force has ``accumulate(particles, position, velocity, time, out)``, adding its
force (newtons, shape (N, 3)) into ``out``. ``position`` and ``velocity`` are passed
separately from ``particles`` because multi-stage integrators (RK4) evaluate forces at
trial states. Forces that are linear in velocity (drag, wind) also expose
``velocity_coefficients(particles)`` (the γ of f = −γ v + …, shape (N,)), which the
implicit integrator treats implicitly.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np

from dynamics.sim.particles import Particles


class Force(Protocol):
    """Anything that adds a force on the particles."""

    def accumulate(self, particles: Particles, position: np.ndarray, velocity: np.ndarray,
                   time: float, out: np.ndarray) -> None:
        """Add this force, (N, 3) newtons, into ``out``."""


@dataclass
class Gravity:
    """Uniform gravity f = m g.

    Attributes
    ----------
    g : (3,) float, m/s² (default: 9.81 m/s² along −Y, the scene convention)
    """

    g: np.ndarray = (0.0, -9.81, 0.0)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        self.g = np.asarray(self.g, dtype=float).reshape(3)

    def accumulate(self, particles, position, velocity, time, out) -> None:
        out += particles.mass[:, None] * self.g

    def potential_energy(self, particles: Particles, position: np.ndarray) -> float:
        """−Σ m g·x, joules (zero at the origin)."""
        return -float(particles.mass @ (position @ self.g))


@dataclass
class Drag:
    """Viscous drag on every particle, f = −γ v (the lecture's damping force).

    Attributes
    ----------
    gamma : float or (N,) float, N·s/m
    """

    gamma: float | np.ndarray = 0.0

    def accumulate(self, particles, position, velocity, time, out) -> None:
        gamma = np.asarray(self.gamma, dtype=float)
        if gamma.ndim == 0:
            if gamma != 0.0:
                out -= float(gamma) * velocity
        else:
            out -= gamma[:, None] * velocity

    def velocity_coefficients(self, particles: Particles) -> np.ndarray:
        """(N,) γ per particle, N·s/m."""
        return np.broadcast_to(np.asarray(self.gamma, dtype=float), (len(particles),))


@dataclass
class Wind:
    """Air drag towards a wind velocity, f = c (w(t) − v) on every particle.

    Attributes
    ----------
    velocity : (3,) float, m/s, the wind's velocity w
    coefficient : float, N·s/m, drag coefficient c per particle
    gust_amplitude : float, fraction of ``velocity`` added as a sinusoidal gust
    gust_frequency : float, Hz
    """

    velocity: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]
    coefficient: float = 0.01
    gust_amplitude: float = 0.0
    gust_frequency: float = 0.5

    def __post_init__(self) -> None:
        self.velocity = np.asarray(self.velocity, dtype=float).reshape(3)

    def wind_at(self, time: float) -> np.ndarray:
        """(3,) wind velocity at ``time`` seconds, m/s."""
        gust = 1.0 + self.gust_amplitude * np.sin(2.0 * np.pi * self.gust_frequency * time)
        return self.velocity * gust

    def accumulate(self, particles, position, velocity, time, out) -> None:
        out += self.coefficient * (self.wind_at(time) - velocity)

    def velocity_coefficients(self, particles: Particles) -> np.ndarray:
        """(N,) c per particle, N·s/m (the part of the force proportional to −v)."""
        return np.full(len(particles), float(self.coefficient))


@dataclass
class ForceCallback:
    """A user-supplied force: ``function(time, position, velocity) -> (N, 3)`` newtons.

    Examples
    --------
    >>> push = ForceCallback(lambda t, x, v: np.where(x[:, :1] > 0, [1.0, 0, 0], 0.0))
    """

    function: Callable[[float, np.ndarray, np.ndarray], np.ndarray]

    def accumulate(self, particles, position, velocity, time, out) -> None:
        out += np.asarray(self.function(time, position, velocity), dtype=float)
