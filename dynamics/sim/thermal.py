"""Heat diffusion over a mass-spring mesh, thermoelastic stiffness and melting.

The lecture's discretised heat equation for a homogeneous isotropic material,

    μσ (θ⁺ − θ)/Δt − c Σ_axes (θ_{+} − 2θ + θ_{−}) / Δu² = q,

is applied on the mesh graph: node i exchanges heat with each node j it is joined to by
a conducting (structural or user) spring, with weight 1/l_ij² (l = rest length), which
is exactly the finite-difference stencil on a regular lattice:

    θ_i ← θ_i + Δt/(μσ) [ c Σ_j (θ_j − θ_i)/l_ij² + q_i ].

The update is explicit, so it is sub-stepped: each sub-step is below the stability limit
Δt ≤ μσ / (c max_i Σ_j 1/l_ij²), whatever the mechanical Δt.

Thermoelasticity (lecture): a spring's stiffness depends on the mean temperature θᵃ of its
ends: k⁰ for θᵃ ≤ θs, falling linearly to 0 at θm, and a spring whose θᵃ reaches θm
melts: it breaks for good (stiffness and damping 0), so a heated lattice slumps into
loose particles (add a :class:`dynamics.sim.fluid.FluidForce` with ``melt_temperature`` to
make those particles behave like a liquid).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from dynamics.sim.springs import STRUCTURAL, USER, Springs


def thermoelastic_stiffness(base_stiffness: np.ndarray, temperature: np.ndarray,
                            soften: float, melt: float) -> np.ndarray:
    """k(θ): k⁰ below θs, k⁰ − ν (θ − θs) between, 0 at or above θm; ν = k⁰/(θm − θs).

    Parameters
    ----------
    base_stiffness : (M,) float, N/m, k⁰
    temperature : (M,) float, kelvin, θᵃ (mean of each spring's two ends)
    soften, melt : float, kelvin, θs < θm
    """
    fraction = np.clip((melt - temperature) / (melt - soften), 0.0, 1.0)
    return base_stiffness * fraction


@dataclass
class HeatSource:
    """Heat put into particles inside an axis-aligned region (tested every sub-step).

    Exactly one of ``temperature`` (the region holds particles at this temperature, like
    a hot plate; kelvin) and ``power`` (heat generation q per unit volume, W/m³) is set.

    Attributes
    ----------
    minimum, maximum : (3,) float, metres, opposite corners of the region
    temperature : float or None, kelvin
    power : float or None, W/m³
    """

    minimum: np.ndarray
    maximum: np.ndarray
    temperature: float | None = None
    power: float | None = None

    def __post_init__(self) -> None:
        self.minimum = np.asarray(self.minimum, float).reshape(3)
        self.maximum = np.asarray(self.maximum, float).reshape(3)
        if (self.temperature is None) == (self.power is None):
            raise ValueError("a heat source needs exactly one of temperature and power")

    def inside(self, position: np.ndarray) -> np.ndarray:
        """(N,) bool, particles inside the region."""
        return np.all((position >= self.minimum) & (position <= self.maximum), axis=1)


@dataclass
class HeatModel:
    """Heat conduction over conducting springs, heat sources, melting.

    Attributes
    ----------
    conductivity : float, W/(m·K), c
    capacity : float, J/(m³·K), μσ (density × specific heat)
    soften : float, kelvin, θs (springs start to soften above it)
    melt : float, kelvin, θm (springs break at it)
    sources : list of HeatSource
    fixed : (N,) bool or None, particles held at their current temperature (boundary)
    ambient : float, kelvin, and cooling : float, 1/s: Newton cooling towards ambient
        (θ += Δt · cooling · (ambient − θ)); cooling 0 (default) = insulated
    thermoelastic : bool, whether temperature changes spring stiffness (and melts)
    """

    conductivity: float
    capacity: float
    soften: float = np.inf
    melt: float = np.inf
    sources: list = field(default_factory=list)
    fixed: np.ndarray | None = None
    ambient: float = 293.15
    cooling: float = 0.0
    thermoelastic: bool = True
    edges: np.ndarray | None = field(default=None, repr=False)
    edge_weight: np.ndarray | None = field(default=None, repr=False)
    edge_spring: np.ndarray | None = field(default=None, repr=False)
    melted_at: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if not (self.conductivity >= 0 and self.capacity > 0):
            raise ValueError("heat: conductivity must be >= 0 and capacity > 0")
        if self.thermoelastic and np.isfinite(self.melt) and not self.melt > self.soften:
            raise ValueError("heat: the melting temperature must exceed the softening one")

    def conduction_graph(self, springs: Springs,
                         position: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(E, 2) conducting edges and (E,) weights 1/l².

        Edges are the structural and user springs. A melted (broken) spring conducts only
        while its ends stay in contact (closer than 1.5 rest lengths, when ``position``
        is given), so molten particles that flowed away exchange no heat through it.
        """
        if self.edges is None or self.edge_spring is None:
            conducting = np.isin(springs.kind, (STRUCTURAL, USER)) & (springs.rest_length > 0)
            self.edge_spring = np.flatnonzero(conducting)
            self.edges = springs.pairs[conducting]
            self.edge_weight = 1.0 / springs.rest_length[conducting] ** 2
        broken = springs.broken[self.edge_spring]
        if position is None or not broken.any():
            return self.edges, self.edge_weight
        e = self.edges[broken]
        apart2 = np.einsum("ij,ij->i", position[e[:, 1]] - position[e[:, 0]],
                           position[e[:, 1]] - position[e[:, 0]])
        weight = self.edge_weight.copy()
        weight[np.flatnonzero(broken)[apart2 * self.edge_weight[broken] > 2.25]] = 0.0
        return self.edges, weight

    def stable_dt(self, n_particles: int, springs: Springs) -> float:
        """Largest stable explicit diffusion step, seconds."""
        edges, weight = self.conduction_graph(springs)
        if not len(edges) or self.conductivity == 0:
            return np.inf
        total = np.bincount(edges.ravel(), np.repeat(weight, 2), minlength=n_particles)
        return float(self.capacity / (self.conductivity * total.max() + self.capacity * self.cooling))

    def diffuse(self, temperature: np.ndarray, position: np.ndarray, springs: Springs,
                dt: float) -> np.ndarray:
        """Advance temperatures by ``dt`` seconds (sub-stepped for stability); returns θ.

        Parameters
        ----------
        temperature : (N,) float, kelvin (updated in place and returned)
        position : (N, 3) float, metres (for the heat sources' regions)
        springs : Springs (the conduction graph is taken from it once)
        """
        n = len(temperature)
        edges, weight = self.conduction_graph(springs, position)
        limit = 0.9 * self.stable_dt(n, springs)
        substeps = max(1, int(np.ceil(dt / limit))) if np.isfinite(limit) else 1
        h = dt / substeps
        held = self.fixed.copy() if self.fixed is not None else np.zeros(n, bool)
        held_value = temperature.copy()
        power = np.zeros(n)
        for source in self.sources:
            inside = source.inside(position)
            if source.temperature is not None:
                held |= inside
                held_value[inside] = source.temperature
            else:
                power[inside] += source.power
        i, j = (edges[:, 0], edges[:, 1]) if len(edges) else (None, None)
        for _ in range(substeps):  # sub-steps depend on each other: a loop is required
            rate = power.copy()
            if i is not None and self.conductivity:
                flux = self.conductivity * weight * (temperature[j] - temperature[i])
                rate += np.bincount(i, flux, minlength=n) - np.bincount(j, flux, minlength=n)
            temperature += h / self.capacity * rate
            if self.cooling:
                temperature += h * self.cooling * (self.ambient - temperature)
            temperature[held] = held_value[held]
        return temperature

    def update_springs(self, springs: Springs, temperature: np.ndarray, time: float) -> int:
        """Set k(θ) on every spring and break melted ones; returns how many broke now."""
        if not self.thermoelastic or not len(springs):
            return 0
        if self.melted_at is None or len(self.melted_at) != len(springs):
            self.melted_at = np.full(len(springs), np.inf)
        mean = 0.5 * (temperature[springs.pairs[:, 0]] + temperature[springs.pairs[:, 1]])
        stiffness = thermoelastic_stiffness(springs.base_stiffness, mean, self.soften, self.melt)
        newly = (mean >= self.melt) & ~springs.broken
        springs.broken |= newly
        self.melted_at[newly] = time
        stiffness[springs.broken] = 0.0
        damping = springs.damping.copy()
        damping[springs.broken] = 0.0
        if not (np.array_equal(stiffness, springs.stiffness)
                and np.array_equal(damping, springs.damping)):
            springs.stiffness[...] = stiffness
            springs.damping[...] = damping
            springs.mark_changed()
        return int(newly.sum())

    def step(self, system, dt: float) -> None:
        """Diffuse heat over ``dt`` and update the springs (called by ``advance``)."""
        p = system.particles
        self.diffuse(p.temperature, p.position, system.springs, dt)
        self.update_springs(system.springs, p.temperature, system.time + dt)
