"""Heat diffusion against the analytic series, thermoelastic melting, rigid-body dynamics."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from dynamics.sim.builders import lattice_block, rope
from dynamics.sim.forces import Gravity
from dynamics.sim.integrators import advance
from dynamics.sim.rigid import (RigidBody, box_inertia, box_mesh, inertia_from_points, mesh_inertia,
                            newton_euler_step)
from dynamics.sim.system import System
from dynamics.sim.thermal import HeatModel, HeatSource, thermoelastic_stiffness


def test_heat_diffusion_on_a_rod_matches_the_fourier_series():
    # rod of length L, ends held at 300 K, interior starts at 400 K:
    # θ − 300 = Σ_{n odd} 400/(nπ) sin(nπx/L) exp(−κ (nπ/L)² t)
    length, nodes, kappa, t_end = 1.0, 41, 0.01, 5.0
    body = rope([0, 0, 0], [length, 0, 0], nodes, 1.0)
    temperature = np.full(nodes, 400.0)
    temperature[[0, -1]] = 300.0
    fixed = np.zeros(nodes, bool)
    fixed[[0, -1]] = True
    heat = HeatModel(conductivity=kappa, capacity=1.0, fixed=fixed, thermoelastic=False)
    dt = 0.05                                    # above the diffusion limit: sub-stepped
    assert heat.stable_dt(nodes, body.springs) < dt
    for _ in range(int(round(t_end / dt))):
        heat.diffuse(temperature, body.particles.position, body.springs, dt)
    x = body.particles.position[:, 0]
    n = np.arange(1, 400, 2)[:, None]
    series = 300 + (400 / (n * np.pi) * np.sin(n * np.pi * x / length)
                    * np.exp(-kappa * (n * np.pi / length) ** 2 * t_end)).sum(axis=0)
    np.testing.assert_allclose(temperature, series, atol=0.1)       # 0.1 % of the 100 K step


def test_thermoelastic_stiffness_is_the_lectures_piecewise_law():
    k0 = np.full(5, 1000.0)
    theta = np.array([250.0, 300.0, 325.0, 350.0, 400.0])
    np.testing.assert_allclose(thermoelastic_stiffness(k0, theta, 300.0, 350.0),
                               [1000.0, 1000.0, 500.0, 0.0, 0.0])


def test_heated_block_melts_and_slumps():
    system = System()
    system.add(lattice_block([0, 0, 0], [0.1, 0.1, 0.1], [4, 4, 4], 0.5, 800.0, 0.5))
    system.add_force(Gravity([0, -9.81, 0]))
    from dynamics.sim.collisions import Plane
    system.add_collider(Plane())
    system.heat = HeatModel(conductivity=0.01, capacity=1.0, soften=330.0, melt=360.0,
                            sources=[HeatSource([-1, -1, -1], [1, 0.005, 1], temperature=600.0)])
    top = system.particles.position[:, 1].max()
    springs = system.springs
    for step in range(4000):
        advance(system, 2e-4, "symplectic-euler")
        if step == 200:
            # part-way: the bottom is hot and soft, the top still cold and at full stiffness
            hot = system.particles.temperature > 330
            assert hot.any() and not hot.all()
            cold = ~hot[springs.pairs].any(axis=1)
            np.testing.assert_array_equal(springs.stiffness[cold], springs.base_stiffness[cold])
    assert springs.broken.mean() > 0.9
    assert np.all(springs.stiffness[springs.broken] == 0)
    assert system.particles.position[:, 1].max() < 0.5 * top
    assert np.isfinite(system.heat.melted_at[springs.broken]).all()


def test_box_inertia_from_mesh_corners_and_dense_points():
    mass, size = 3.0, np.array([0.4, 0.2, 0.1])
    expected = box_inertia(mass, size)
    np.testing.assert_allclose(np.diag(expected), mass / 12 * np.array([0.05, 0.17, 0.2]))
    vertices, faces = box_mesh(size)
    m, centre, inertia = mesh_inertia(vertices + [1.0, 2.0, 3.0], faces,
                                      density=mass / size.prod())
    assert m == pytest.approx(mass)
    np.testing.assert_allclose(centre, [1, 2, 3], atol=1e-12)
    np.testing.assert_allclose(inertia, expected, atol=1e-12)
    # eight equal point masses at the corners: I_xx = m (b² + c²)/4
    _, corners = inertia_from_points(np.full(8, mass / 8), vertices)
    np.testing.assert_allclose(np.diag(corners), mass / 4 * np.array([0.05, 0.17, 0.2]))
    # a fine grid of cell-centred points converges to the solid box (error ∝ 1/n²)
    n = 40
    axes = [(np.arange(n) + 0.5) / n * s - s / 2 for s in size]
    points = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    _, dense = inertia_from_points(np.full(len(points), mass / len(points)), points)
    np.testing.assert_allclose(dense, expected, rtol=1e-3, atol=1e-12)
    # rotated box: R I Rᵀ
    r = Rotation.from_euler("ZXY", [30, 20, 10], degrees=True).as_matrix()
    _, _, rotated = mesh_inertia(vertices @ r.T, faces, density=mass / size.prod())
    np.testing.assert_allclose(rotated, r @ expected @ r.T, atol=1e-12)


def test_torque_free_body_conserves_angular_momentum_and_energy():
    body = RigidBody.box(2.0, [0.3, 0.12, 0.04])
    body.set_angular_velocity([0.3, 8.0, 0.2])                # near the unstable middle axis
    momentum, energy = body.angular_momentum.copy(), body.kinetic_energy()
    axes = []
    for _ in range(4000):
        newton_euler_step(body, 1e-3)
        axes.append(body.rotation[:, 1])
    np.testing.assert_allclose(body.angular_momentum, momentum, rtol=0, atol=1e-15)
    assert body.kinetic_energy() == pytest.approx(energy, rel=1e-3)
    assert min(a[1] for a in axes) < -0.9                      # it flipped (tennis racket)


def test_symmetric_top_precesses_at_the_closed_form_rate():
    # I1 = I2: the symmetry axis precesses about L at the rate |L| / I1
    inertia = np.diag([2.0, 2.0, 1.0])
    q0 = Rotation.from_euler("x", 30, degrees=True)
    body = RigidBody(1.0, inertia, orientation=q0.as_quat())
    body.angular_momentum = np.array([0.0, 0.0, 3.0])
    dt, steps = 1e-3, 1000
    for _ in range(steps):
        newton_euler_step(body, dt)
    rate = 3.0 / 2.0
    expected = Rotation.from_rotvec([0, 0, rate * dt * steps]).apply(q0.apply([0, 0, 1]))
    np.testing.assert_allclose(body.rotation[:, 2], expected, atol=1e-5)


def test_off_centre_force_gives_torque_and_linear_push():
    body = RigidBody.box(2.0, [1.0, 1.0, 1.0], position=[0, 0, 0])
    body.apply_force([0, 0, 10.0], point=[0.5, 0.0, 0.0])
    newton_euler_step(body, 0.01)
    np.testing.assert_allclose(body.velocity, [0, 0, 0.05])
    np.testing.assert_allclose(body.angular_momentum, [0, -0.05, 0])   # (r × F) Δt
    np.testing.assert_allclose(body.force, 0)
    body.apply_force([0, 0, 10.0])                             # at the centre: no torque
    newton_euler_step(body, 0.01)
    np.testing.assert_allclose(body.angular_momentum, [0, -0.05, 0])


def test_an_absurd_push_stops_the_run_with_one_line_not_a_quaternion_error(tmp_path):
    """Found by the hostile re-run: a push of 1e300 N gave scipy's "zero norm quaternions"
    traceback. The particles' rule (non-finite or faster than the speed limit) now applies
    to rigid bodies too, before the orientation update."""
    from mocap.cli import main
    from mocap.errors import MocapError
    from dynamics.sim.integrators import SimulationUnstable

    body = RigidBody.box(1.0, [0.3, 0.1, 0.05])
    body.apply_force(np.array([0.0, 0.0, 1e300]), body.position + np.array([0.15, 0.0, 0.0]))
    with pytest.raises(SimulationUnstable, match="rigid body went unstable"):
        newton_euler_step(body, 1e-3, speed_limit=1e3)
    assert issubclass(SimulationUnstable, MocapError)
    # a fast but finite spin above the limit stops too; below it the step runs
    slow = RigidBody.box(1.0, [0.3, 0.1, 0.05], angular_momentum=[0.0, 0.01, 0.0])
    newton_euler_step(slow, 1e-3, speed_limit=1e3)
    fast = RigidBody.box(1.0, [0.3, 0.1, 0.05], angular_momentum=[0.0, 1e3, 0.0])
    with pytest.raises(SimulationUnstable, match="limit 1000 m/s"):
        newton_euler_step(fast, 1e-3, speed_limit=1e3)
    scene = tmp_path / "push.toml"
    scene.write_text('[simulation]\ndt = 0.001\nsteps = 3\n[[rigid]]\nshape = "box"\n'
                     'size = [0.3, 0.12, 0.04]\nmass = 1.0\n[[rigid.push]]\n'
                     'force = [0.0, 0.0, 1e300]\npoint = [0.15, 0.0, 0.0]\n'
                     'start = 0.0\nduration = 0.02\n')
    out = tmp_path / "s.npz"
    assert main(["simulate", str(scene), "--no-progress", "-o", str(out)]) == 2
    assert not out.exists()
