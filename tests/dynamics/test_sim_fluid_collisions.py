"""Fluid pair force (KD-tree vs brute force, momentum) and colliders (known responses)."""
from __future__ import annotations

import numpy as np
import pytest

from dynamics.sim.builders import particle_block
from dynamics.sim.collisions import Box, Capsule, Plane, Sphere
from dynamics.sim.fluid import FluidForce, equilibrium_beta, fluid_forces_bruteforce
from dynamics.sim.forces import Gravity
from dynamics.sim.integrators import advance
from dynamics.sim.particles import Particles
from dynamics.sim.springs import Springs
from dynamics.sim.system import System

G = np.array([0.0, -9.81, 0.0])


def jittered_block(seed=1):
    body = particle_block([0, 0, 0], [0.16, 0.16, 0.16], 0.02, 0.5, jitter=0.6, seed=seed)
    body.particles.mass[:] *= np.random.default_rng(seed).uniform(0.5, 1.5, len(body.particles))
    return body.particles


def test_equilibrium_beta_zeroes_the_pair_force():
    beta = equilibrium_beta(3.0, 0.01, 0.02)
    x = np.array([[0.0, 0, 0], [0.02, 0, 0]])
    force = fluid_forces_bruteforce(x, np.ones(2), 3.0, beta, 0.01, 0.05)
    np.testing.assert_allclose(force, 0.0, atol=1e-12)


def test_kdtree_forces_equal_brute_force_forces_also_after_moving():
    particles = jittered_block()
    alpha, zeta, cutoff = 5.0, 0.01, 0.045
    beta = equilibrium_beta(alpha, zeta, 0.02)
    force = FluidForce(alpha, beta, zeta, cutoff, skin=0.01)
    rng = np.random.default_rng(7)
    position = particles.position.copy()
    for scale in (0.0004, 0.0004, 0.01, 0.0):  # small moves reuse the list, big ones rebuild it
        out = np.zeros_like(position)
        force.accumulate(particles, position, particles.velocity, 0.0, out)
        reference = fluid_forces_bruteforce(position, particles.mass, alpha, beta, zeta, cutoff)
        np.testing.assert_allclose(out, reference, rtol=1e-9, atol=1e-12 * np.abs(reference).max())
        position = position + rng.normal(0, scale, position.shape)
    assert force.rebuilds == 2


def test_members_and_molten_only_pairs():
    particles = jittered_block()
    n = len(particles)
    members = np.arange(0, n, 2)
    force = FluidForce(5.0, equilibrium_beta(5.0, 0.01, 0.02), 0.01, 0.045, members=members)
    out = np.zeros((n, 3))
    force.accumulate(particles, particles.position, particles.velocity, 0.0, out)
    reference = np.zeros((n, 3))
    reference[members] = fluid_forces_bruteforce(particles.position[members],
                                                 particles.mass[members], 5.0, force.beta,
                                                 0.01, 0.045)
    np.testing.assert_allclose(out, reference, rtol=1e-9, atol=1e-15)
    # molten-only: with nobody at the melting temperature there is no force at all
    molten = FluidForce(5.0, force.beta, 0.01, 0.045, melt_temperature=400.0)
    out[:] = 0
    molten.accumulate(particles, particles.position, particles.velocity, 0.0, out)
    assert not out.any()


def test_pair_forces_conserve_momentum():
    particles = jittered_block(seed=3)
    n = len(particles)
    rng = np.random.default_rng(0)
    particles.velocity[:] = rng.normal(0, 0.05, (n, 3))
    pairs = np.stack([np.arange(n - 1), np.arange(1, n)], axis=1)
    system = System()
    system.add(particles, Springs.between(particles.position, pairs, 50.0, 0.1,
                                          rest_length=0.015))
    system.add_force(FluidForce(5.0, equilibrium_beta(5.0, 0.01, 0.02), 0.01, 0.045,
                                viscosity=0.01))
    momentum = system.particles.momentum()
    for _ in range(200):
        advance(system, 1e-4, "symplectic-euler")
    np.testing.assert_allclose(system.particles.momentum(), momentum, atol=1e-13)
    forces = system.compute_forces()
    np.testing.assert_allclose(forces.sum(axis=0), 0.0, atol=1e-12)


def falling(position, velocity, collider, gravity=True) -> System:
    system = System()
    system.add(Particles([position], [velocity], 1.0, False))
    if gravity:
        system.add_force(Gravity(G))
    system.add_collider(collider)
    return system


def test_plane_restitution_reverses_normal_velocity():
    system = falling([0.0, 0.001, 0.0], [0.3, -2.0, 0.0], Plane(restitution=0.5), gravity=False)
    advance(system, 0.01, "symplectic-euler")
    np.testing.assert_allclose(system.particles.position[0, 1], 0.0, atol=1e-15)
    np.testing.assert_allclose(system.particles.velocity[0], [0.3, 1.0, 0.0])


def test_coulomb_friction_stopping_distance():
    mu, speed, dt = 0.4, 2.0, 1e-4
    system = falling([0.0, 0.0, 0.0], [speed, 0.0, 0.0], Plane(friction=mu))
    for _ in range(int(1.0 / dt)):
        advance(system, dt, "symplectic-euler")
    assert system.particles.velocity[0, 0] == pytest.approx(0.0, abs=1e-12)
    assert system.particles.position[0, 0] == pytest.approx(speed ** 2 / (2 * mu * 9.81), rel=0.01)


def test_sphere_pushes_particles_to_its_surface():
    sphere = Sphere([0, 0, 0], 0.5, margin=0.01)
    system = falling([0.1, 0.2, 0.0], [0, 0, 0], sphere, gravity=False)
    advance(system, 1e-3, "symplectic-euler")
    assert np.linalg.norm(system.particles.position[0]) == pytest.approx(0.51)


def test_moving_capsule_carries_a_resting_particle():
    capsule = Capsule([-1, 0, 0], [1, 0, 0], 0.1)
    system = falling([0.3, 0.1, 0.0], [0, 0, 0], capsule, gravity=False)
    dt = 1e-3
    for _ in range(10):
        capsule.move_to(capsule.a + [0, 0.002, 0], capsule.b + [0, 0.002, 0], dt=dt)
        advance(system, dt, "symplectic-euler")
    np.testing.assert_allclose(capsule.velocity_a, [0, 2.0, 0])
    np.testing.assert_allclose(system.particles.position[0, 1], 0.12, atol=1e-12)
    np.testing.assert_allclose(system.particles.velocity[0], [0, 2.0, 0], atol=1e-12)


def test_box_keeps_particles_inside():
    rng = np.random.default_rng(2)
    system = System()
    system.add(Particles(rng.uniform(-0.1, 0.1, (200, 3)), rng.normal(0, 3, (200, 3)), 1.0, False))
    system.add_force(Gravity(G))
    system.add_collider(Box([-0.1, -0.1, -0.1], [0.1, 0.1, 0.1], open_top=False, restitution=0.8))
    for _ in range(500):
        advance(system, 1e-3, "symplectic-euler")
    p = system.particles.position
    assert np.all(p >= -0.1 - 1e-12) and np.all(p <= 0.1 + 1e-12)


@pytest.mark.parametrize("integrator, dt", [("implicit-euler", 1 / 120),
                                            ("symplectic-euler", 1 / 2400)])
def test_cape_on_a_moving_torso_stays_outside_it(integrator, dt):
    # the humanoid use: a cloth pinned along its top edge to moving points, draped over a
    # moving capsule; no free particle may end inside the capsule
    from dynamics.sim.builders import cloth_grid
    system = System()
    cape = cloth_grid([-0.2, 1.5, -0.16], [0.4, 0.7], [8, 12], 0.4,
                      {"structural": 400.0, "shear": 50.0, "bend": 5.0}, {"structural": 0.05},
                      pin=["top"], u_axis=[1, 0, 0], v_axis=[0, -1, 0])
    index = system.add(cape)
    top = index[cape.named("top")]
    system.add_force(Gravity(G))
    torso = Capsule([0, 0.9, 0], [0, 1.45, 0], 0.15, margin=0.01, friction=0.3)
    system.add_collider(torso)
    anchors = system.particles.position[top].copy()
    seconds = 1.0
    for step in range(1, int(round(seconds / dt)) + 1):
        shift = np.array([0.0, 0.0, 0.3 * np.sin(np.pi * step * dt)])   # walk forward and back
        system.drive_pinned(top, anchors + shift, dt)
        torso.move_to([0, 0.9, 0] + shift, [0, 1.45, 0] + shift, dt=dt)
        advance(system, dt, integrator)
    free = np.setdiff1d(index, top)
    distance = torso.signed_distance(system.particles.position[free])
    assert distance.min() > -1e-9
    np.testing.assert_allclose(system.particles.position[top], anchors + shift, atol=1e-12)
    assert np.all(np.isfinite(system.particles.position))
