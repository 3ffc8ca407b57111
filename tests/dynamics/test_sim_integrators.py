"""Known answers for the integrators: projectile, damped oscillator, energy behaviour,
implicit Euler on stiff cloth, factorisation reuse, pinned particles, instability."""
from __future__ import annotations

import numpy as np
import pytest

from dynamics.sim.builders import cloth_grid, rope
from dynamics.sim.forces import Drag, Gravity
from dynamics.sim.integrators import SimulationUnstable, advance, stability_limit
from dynamics.sim.particles import Particles
from dynamics.sim.springs import Springs, spring_forces
from dynamics.sim.system import System

G = np.array([0.0, -9.81, 0.0])


def projectile(v0=(3.0, 4.0, -1.0)) -> System:
    system = System()
    system.add(Particles([[0.0, 1.0, 0.0]], [v0], 2.0, False))
    system.add_force(Gravity(G))
    return system


@pytest.mark.parametrize("integrator, bias", [("rk4", 0.0), ("symplectic-euler", 0.5),
                                              ("explicit-euler", -0.5),
                                              ("implicit-euler", 0.5)])
def test_projectile_matches_closed_form(integrator, bias):
    # constant force: RK4 is exact; the Euler family has the exact discrete solution
    # x_n = x0 + v0 t + ½ g t² + bias · g Δt t (bias +½ when the new velocity moves x)
    dt, steps = 0.01, 150
    system = projectile()
    for _ in range(steps):
        advance(system, dt, integrator)
    t = dt * steps
    v0 = np.array([3.0, 4.0, -1.0])
    expected = np.array([0.0, 1.0, 0.0]) + v0 * t + 0.5 * G * t * t + bias * G * dt * t
    np.testing.assert_allclose(system.particles.position[0], expected, atol=1e-10)
    np.testing.assert_allclose(system.particles.velocity[0], v0 + G * t, atol=1e-10)
    assert system.time == pytest.approx(t)


def oscillator(k=400.0, gamma=0.8, mass=1.0, rest=0.5, stretch=0.1) -> System:
    """Particle 1 on a Voigt spring to the pinned particle 0, moving along x."""
    system = System()
    system.add(Particles([[0, 0, 0], [rest + stretch, 0, 0]], 0.0, [1.0, mass], [True, False]),
               Springs([[0, 1]], rest, k, gamma))
    return system


def test_spring_sign_convention_damping_resists_stretching():
    system = oscillator(k=100.0, gamma=2.0, rest=1.0, stretch=0.1)
    system.particles.velocity[1] = [0.5, 0.0, 0.0]          # moving away: stretching
    force = spring_forces(system.springs, system.particles.position, system.particles.velocity)
    # on j (particle 1): −(k e + γ ė) = −(100·0.1 + 2·0.5) along +x; on i the opposite
    np.testing.assert_allclose(force[1], [-11.0, 0, 0])
    np.testing.assert_allclose(force[0], [11.0, 0, 0])


def test_damped_spring_matches_analytic_oscillator():
    k, gamma, m, a0 = 400.0, 0.8, 1.0, 0.1
    w0 = np.sqrt(k / m)
    zeta = gamma / (2 * m * w0)
    wd = w0 * np.sqrt(1 - zeta ** 2)
    system = oscillator(k, gamma, m, 0.5, a0)
    dt, steps = 1e-3, 1500
    x = np.empty(steps)
    for n in range(steps):
        advance(system, dt, "rk4")
        x[n] = system.particles.position[1, 0] - 0.5
    t = dt * np.arange(1, steps + 1)
    exact = a0 * np.exp(-zeta * w0 * t) * (np.cos(wd * t) + zeta * w0 / wd * np.sin(wd * t))
    np.testing.assert_allclose(x, exact, atol=1e-8)


def test_symplectic_euler_period_and_decay():
    k, gamma, m, a0 = 400.0, 0.8, 1.0, 0.1
    w0 = np.sqrt(k / m)
    wd = w0 * np.sqrt(1 - (gamma / (2 * m * w0)) ** 2)
    system = oscillator(k, gamma, m, 0.5, a0)
    dt, steps = 2e-4, 12000
    x = np.empty(steps)
    for n in range(steps):
        advance(system, dt, "symplectic-euler")
        x[n] = system.particles.position[1, 0] - 0.5
    t = dt * np.arange(1, steps + 1)
    peaks = np.flatnonzero((x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:])) + 1
    period = np.diff(t[peaks]).mean()
    assert period == pytest.approx(2 * np.pi / wd, rel=2e-3)
    decay = x[peaks[1:]] / x[peaks[:-1]]                      # per period: exp(−γ/2m · T)
    np.testing.assert_allclose(decay, np.exp(-gamma / (2 * m) * 2 * np.pi / wd), rtol=5e-3)


def test_energy_bounded_for_symplectic_and_growing_for_explicit_euler():
    dt = 0.01                                                  # ω Δt = 0.2
    energies = {}
    for integrator in ("symplectic-euler", "explicit-euler"):
        system = oscillator(k=400.0, gamma=0.0, rest=0.5, stretch=0.1)
        system.speed_limit = np.inf                           # let explicit Euler grow
        e0 = system.energy()["total"]
        trace = []
        for _ in range(2000):
            advance(system, dt, integrator)
            trace.append(system.energy()["total"] / e0)
        energies[integrator] = np.array(trace)
    symplectic = energies["symplectic-euler"]
    assert np.all(np.abs(symplectic - 1) < 0.12)               # bounded oscillation ~ ω Δt / 2
    assert symplectic[-500:].max() < symplectic[:500].max() * (1 + 1e-4)   # no drift
    explicit = energies["explicit-euler"]
    # each step multiplies the energy by (1 + ω²Δt²) = 1.04
    assert explicit[99] == pytest.approx(1.04 ** 100, rel=0.02)
    assert explicit[-1] > 1e10


def stiff_cloth() -> System:
    system = System()
    system.add(cloth_grid([0, 1, 0], [0.5, 0.5], [10, 10], 0.2,
                          {"structural": 5000.0, "shear": 1000.0, "bend": 100.0}, 0.0,
                          pin=["top-left", "top-right"]))
    system.add_force(Gravity(G))
    return system


def test_implicit_euler_stable_where_explicit_diverges():
    limit = stability_limit(stiff_cloth())
    dt = 20 * limit
    explicit = stiff_cloth()
    with pytest.raises(SimulationUnstable, match=r"unstable at step \d+.*implicit-euler"):
        for _ in range(300):
            advance(explicit, dt, "symplectic-euler")
    assert np.all(np.isfinite(explicit.particles.position))   # the bad step was undone
    for solver in ("projective", "direct"):
        system = stiff_cloth()
        start = system.energy()["total"]
        for _ in range(300):
            advance(system, dt, "implicit-euler", solver=solver)
        p = system.particles.position
        assert np.all(np.isfinite(p))
        assert system.energy()["total"] <= start + 1e-9     # backward Euler only dissipates
        # the cloth hangs below its pins and keeps its size (no blow-up, no collapse)
        reach = np.linalg.norm(p - p[0], axis=1).max()
        assert 0.6 < reach < 0.85                             # diagonal 0.707 m
        assert p[:, 1].min() < 0.6


def test_direct_and_cg_solve_the_same_system():
    results = []
    for solver in ("direct", "cg"):
        system = stiff_cloth()
        system.add_force(Drag(0.01))
        system.springs.damping[:] = 0.5
        for _ in range(5):
            advance(system, 0.005, "implicit-euler", solver=solver, tolerance=1e-12)
        results.append(system.particles.position.copy())
    np.testing.assert_allclose(results[0], results[1], atol=1e-9)


def zero_length_chain() -> System:
    system = System()
    body = rope([0, 0, 0], [1, 0, 0], 6, 0.6, stiffness=50.0, damping=0.0, pin=["start"])
    body.springs.rest_length[:] = 0.0                         # ideal zero-length springs
    system.add(body)
    system.add_force(Gravity(G))
    return system


def test_linear_system_projective_equals_direct_and_factorisations_are_reused():
    # zero-length springs are linear: the projective global step is then exact and the
    # direct solver's matrix is constant, so its factorisation must be reused
    projective, direct = zero_length_chain(), zero_length_chain()
    advance(projective, 0.02, "implicit-euler", solver="projective", iterations=1)
    advance(direct, 0.02, "implicit-euler", solver="direct")
    factor_p = projective.cache["projective"][1][0]
    factor_d = direct.cache["implicit_direct"][1]
    for _ in range(20):
        advance(projective, 0.02, "implicit-euler", solver="projective", iterations=1)
        advance(direct, 0.02, "implicit-euler", solver="direct")
    np.testing.assert_allclose(projective.particles.position, direct.particles.position,
                               atol=1e-10)
    assert projective.cache["projective"][1][0] is factor_p
    assert direct.cache["implicit_direct"][1] is factor_d


@pytest.mark.parametrize("integrator", ["symplectic-euler", "explicit-euler", "rk4",
                                        "implicit-euler"])
def test_driven_pinned_particles_reach_their_targets(integrator):
    system = System()
    body = cloth_grid([0, 1, 0], [0.3, 0.3], [5, 5], 0.1, 200.0, 0.1, pin=["top"])
    index = system.add(body)
    top = index[body.named("top")]
    system.add_force(Gravity(G))
    dt = 1e-3
    for step in range(1, 51):
        targets = system.particles.position[top].copy()
        targets[:, 0] += 0.002 * np.sin(step)                # a shaking shoulder line
        system.drive_pinned(top, targets, dt)
        advance(system, dt, integrator)
        np.testing.assert_allclose(system.particles.position[top], targets, atol=1e-12)
    free = np.setdiff1d(index, top)
    assert system.particles.position[free, 1].min() < 0.99     # the rest fell under gravity


def test_set_pinned_refuses_free_particles():
    system = System()
    system.add(Particles([[0, 0, 0], [1, 0, 0]], 0.0, 1.0, [True, False]))
    system.set_pinned([0], [[0, 1, 0]], [[0, 0, 1]])
    np.testing.assert_allclose(system.particles.position[0], [0, 1, 0])
    with pytest.raises(ValueError):
        system.set_pinned([1], [[0, 0, 0]])


def test_unstable_run_stops_with_step_and_remedy():
    system = oscillator(k=1e6, gamma=0.0, rest=0.5, stretch=0.1)
    with pytest.raises(SimulationUnstable) as caught:
        for _ in range(1000):
            advance(system, 0.01, "symplectic-euler")
    message = str(caught.value)
    assert "step" in message and "reduce dt" in message and "implicit-euler" in message
    assert np.all(np.isfinite(system.particles.position))


def test_driving_pins_keeps_the_implicit_factorisation():
    system = System()
    body = cloth_grid([0, 1, 0], [0.3, 0.3], [6, 6], 0.1, 300.0, 0.1, pin=["top"])
    index = system.add(body)
    top = index[body.named("top")]
    system.add_force(Gravity(G))
    dt = 1 / 60
    advance(system, dt, "implicit-euler")
    factor = system.cache["projective"][1][0]
    for step in range(30):
        system.drive_pinned(top, system.particles.position[top] + [0.01, 0.0, 0.0], dt)
        advance(system, dt, "implicit-euler")
    assert system.cache["projective"][1][0] is factor
    system.pin(index[-1])                                   # a new pinned set: refactorised
    advance(system, dt, "implicit-euler")
    assert system.cache["projective"][1][0] is not factor


def test_wind_drag_reaches_the_wind_speed_and_callbacks_add_forces():
    from dynamics.sim.forces import ForceCallback, Wind
    system = System()
    system.add(Particles([[0, 0, 0]], 0.0, 0.5, False))
    system.add_force(Wind([2.0, 0.0, 0.0], coefficient=1.0))
    for _ in range(2000):                                   # time constant m / c = 0.5 s
        advance(system, 2e-3, "rk4")
    np.testing.assert_allclose(system.particles.velocity[0], [2 * (1 - np.exp(-8)), 0, 0],
                               rtol=1e-6)
    assert system.particles.age[0] == pytest.approx(4.0)
    pushed = System()
    pushed.add(Particles([[0, 0, 0]], 0.0, 2.0, False))
    pushed.add_force(ForceCallback(lambda t, x, v: np.tile([0.0, 0.0, 4.0], (len(x), 1))))
    for _ in range(100):
        advance(pushed, 0.01, "rk4")
    np.testing.assert_allclose(pushed.particles.position[0], [0, 0, 0.5 * 2.0 * 1.0 ** 2])


def test_particles_validate_masses():
    with pytest.raises(ValueError, match="positive"):
        Particles([[0, 0, 0]], 0.0, 0.0, False)
