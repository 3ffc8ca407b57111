"""Simulator speed: cloth (symplectic and implicit Euler) and particle fluid, beside plain
references measured in the same run. Prints figures and ratios; asserts nothing.

    python benchmarks/simulator.py            # full run (about a minute)
    python benchmarks/simulator.py --quick    # smaller sizes only

Targets (issue 4): 64 × 64 cloth symplectic step < 1 ms; implicit step < 30 ms at a Δt at
least 20× the explicit stability limit; 10 000 fluid particles < 50 ms a step.
"""
from __future__ import annotations

import argparse
import math
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")      # small sparse systems: threads hurt

import numpy as np  # noqa: E402

from dynamics.sim.builders import cloth_grid, particle_block  # noqa: E402
from dynamics.sim.collisions import Box  # noqa: E402
from dynamics.sim.fluid import FluidForce, equilibrium_beta  # noqa: E402
from dynamics.sim.forces import Drag, Gravity  # noqa: E402
from dynamics.sim.integrators import advance, stability_limit  # noqa: E402
from dynamics.sim.system import System  # noqa: E402

STIFFNESS = {"structural": 500.0, "shear": 100.0, "bend": 20.0}


def cloth(n: int) -> System:
    system = System()
    system.add(cloth_grid([0, 1, 0], [1, 1], [n, n], 0.5, STIFFNESS, {"structural": 0.01},
                          pin=["top-left", "top-right"]))
    system.add_force(Gravity())
    system.add_force(Drag(0.0005))
    return system


def per_step(function, min_time: float = 0.5, max_steps: int = 2000) -> float:
    """Seconds per call of ``function`` (after one warm-up call)."""
    function()
    count, start = 0, time.perf_counter()
    while True:
        function()
        count += 1
        elapsed = time.perf_counter() - start
        if elapsed > min_time or count >= max_steps:
            return elapsed / count


def naive_spring_forces(position, velocity, pairs, rest, k, g):
    """The lecture's C loop in plain Python: one spring at a time."""
    force = [[0.0, 0.0, 0.0] for _ in range(len(position))]
    for s in range(len(pairs)):
        i, j = pairs[s]
        xi, xj, vi, vj = position[i], position[j], velocity[i], velocity[j]
        d = (xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2])
        length = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        u = (d[0] / length, d[1] / length, d[2] / length)
        rate = (vj[0] - vi[0]) * u[0] + (vj[1] - vi[1]) * u[1] + (vj[2] - vi[2]) * u[2]
        scale = k[s] * (length - rest[s]) + g[s] * rate
        for a in range(3):
            force[i][a] += scale * u[a]
            force[j][a] -= scale * u[a]
    return force


def naive_cloth_step(system: System, dt: float) -> None:
    """Symplectic Euler with the per-spring Python loop (gravity and drag included)."""
    p, s = system.particles, system.springs
    force = np.array(naive_spring_forces(p.position.tolist(), p.velocity.tolist(),
                                         s.pairs.tolist(), s.rest_length.tolist(),
                                         s.stiffness.tolist(), s.damping.tolist()))
    force += p.mass[:, None] * np.array([0, -9.81, 0]) - 0.0005 * p.velocity
    p.velocity += dt * force * p.inverse_mass[:, None]
    p.position += dt * p.velocity


def bincount_cloth_step(system: System, dt: float) -> None:
    """Symplectic Euler with vectorised numpy (bincount scatter): the plain-numpy figure."""
    p, s = system.particles, system.springs
    i, j = s.pairs[:, 0], s.pairs[:, 1]
    d = p.position[j] - p.position[i]
    length = np.linalg.norm(d, axis=1)
    u = d / length[:, None]
    rate = np.einsum("ij,ij->i", p.velocity[j] - p.velocity[i], u)
    f = (s.stiffness * (length - s.rest_length) + s.damping * rate)[:, None] * u
    n = len(p)
    force = np.stack([np.bincount(i, f[:, a], n) - np.bincount(j, f[:, a], n) for a in range(3)], 1)
    force += p.mass[:, None] * np.array([0, -9.81, 0]) - 0.0005 * p.velocity
    p.velocity += dt * force * p.inverse_mass[:, None]
    p.position += dt * p.velocity


def bench_cloth(sizes, implicit_dt: float) -> None:
    print("\n== cloth (structural 500, shear 100, bend 20 N/m; 0.5 kg; two corners pinned) ==")
    print(f"{'size':>7} {'springs':>8} {'limit s':>9} | {'symplectic':>11} {'numpy':>9} "
          f"{'naive py':>9} {'vs numpy':>8} {'vs naive':>8} | {'implicit':>9} {'dt/limit':>8} "
          f"{'direct':>8} {'cg':>8} | {'sim s/s expl':>12} {'impl':>6}")
    for n in sizes:
        system = cloth(n)
        limit = stability_limit(system)
        dt = 0.5 * limit
        symplectic = per_step(lambda: advance(system, dt, "symplectic-euler"))
        reference = cloth(n)
        numpy_step = per_step(lambda: bincount_cloth_step(reference, dt), 0.3, 200)
        if n <= 64:
            naive = per_step(lambda: naive_cloth_step(reference, dt), 0.3, 3)
        else:
            naive = float("nan")
        implicit_system = cloth(n)
        implicit = per_step(lambda: advance(implicit_system, implicit_dt, "implicit-euler",
                                            solver="projective", iterations=10), 1.0, 100)
        direct = cg = float("nan")
        if n <= 64:
            direct_system = cloth(n)
            direct = per_step(lambda: advance(direct_system, implicit_dt, "implicit-euler",
                                              solver="direct"), 0.5, 5)
        if n <= 32:
            cg_system = cloth(n)
            cg = per_step(lambda: advance(cg_system, implicit_dt, "implicit-euler", solver="cg",
                                          tolerance=1e-6), 0.5, 5)
        print(f"{n:>4}^2 {len(system.springs):>8} {limit:>9.2e} | {symplectic * 1e3:>8.3f} ms "
              f"{numpy_step * 1e3:>6.2f} ms {naive * 1e3:>6.1f} ms {numpy_step / symplectic:>7.1f}x "
              f"{naive / symplectic:>7.0f}x | {implicit * 1e3:>6.1f} ms {implicit_dt / limit:>7.0f}x "
              f"{direct * 1e3:>5.0f} ms {cg * 1e3:>5.0f} ms | {dt / symplectic:>12.2f} "
              f"{implicit_dt / implicit:>6.2f}")
    print("symplectic: dt = 0.5 x the estimated limit; implicit: projective solver (Liu et al."
          f" 2013, 10 iterations) at dt = {implicit_dt:.4f} s; direct = linearised backward Euler "
          "with SuperLU each step; cg = the same by Jacobi-PCG. 'sim s/s' = simulated seconds per"
          " wall-clock second.")


def swing_energy(n: int = 32, seconds: float = 0.6, implicit_dt: float = 1 / 60) -> None:
    print(f"\n== what implicit Euler costs in motion ({n}^2 cloth, kinetic energy after "
          f"{seconds} s of swing) ==")
    explicit = cloth(n)
    dt = 0.5 * stability_limit(explicit)
    for _ in range(int(round(seconds / dt))):
        advance(explicit, dt, "symplectic-euler")
    for label, system, step, options in [("symplectic", explicit, dt, {})] + [
            (f"implicit ({solver})", cloth(n), implicit_dt, {"solver": solver})
            for solver in ("projective", "direct")]:
        if system is not explicit:
            for _ in range(int(round(seconds / step))):
                advance(system, step, "implicit-euler", **options)
        print(f"  {label:<22} dt = {step:.2e} s  kinetic {system.energy()['kinetic']:.3f} J")


def bench_fluid(counts) -> None:
    print("\n== fluid (pair force a = 2, b = 4, cut-off 1.25 spacing, viscosity; gravity; box) ==")
    print(f"{'particles':>9} {'pairs':>8} | {'step':>9} {'force only':>10} | {'numpy N^2':>10} "
          f"{'naive py':>10} {'vs numpy':>8} {'vs naive':>8}")
    for count in counts:
        side = round(count ** (1 / 3))
        spacing = 0.02
        body = particle_block([0, 0.1, 0], [spacing * (side - 1)] * 3, spacing, count * 7.5e-4,
                              jitter=0.1)
        system = System()
        system.add(body)
        system.add_force(Gravity())
        alpha, zeta = 2000.0, 0.01
        force = FluidForce(alpha, equilibrium_beta(alpha, zeta, spacing), zeta, 1.25 * spacing,
                           viscosity=0.05)
        system.add_force(force)
        system.add_collider(Box([-1, 0, -1], [1, 2, 1]))
        for _ in range(200):                     # let it start moving: realistic rebuild rate
            advance(system, 2.5e-4, "symplectic-euler")
        step = per_step(lambda: advance(system, 2.5e-4, "symplectic-euler"), 1.0, 400)
        p = system.particles
        out = np.zeros_like(p.position)
        force_only = per_step(lambda: force.accumulate(p, p.position, p.velocity, 0.0, out), 0.5, 200)
        pairs = len(force.neighbour_pairs(p.position))
        naive = float("nan")
        brute = per_step(lambda: chunked_bruteforce(p.position, p.mass, alpha, force.beta, zeta,
                                                    force.cutoff), 0.3, 3 if len(p) <= 2000 else 1)
        if len(p) <= 2000:
            naive = per_step(lambda: naive_fluid(p.position.tolist(), p.mass.tolist(), alpha,
                                                 force.beta, zeta, force.cutoff), 0.1, 1)
        print(f"{len(p):>9} {pairs:>8} | {step * 1e3:>6.2f} ms {force_only * 1e3:>7.2f} ms | "
              f"{brute * 1e3:>7.1f} ms {naive * 1e3:>7.0f} ms {brute / force_only:>7.0f}x "
              f"{naive / force_only:>7.0f}x")
    print("step = a whole symplectic step (neighbour list with Verlet skin, forces, box collisions,"
          " stability check); references compute the force only, over all N^2 pairs.")


def chunked_bruteforce(position, mass, alpha, beta, zeta, cutoff, rows: int = 500):
    """All N² pairs with numpy, a block of rows at a time (bounded memory)."""
    out = np.zeros_like(position)
    for start in range(0, len(position), rows):
        block = slice(start, start + rows)
        diff = position[block, None, :] - position[None, :, :]
        dist = np.linalg.norm(diff, axis=2)
        dist[np.arange(dist.shape[0]), np.arange(start, start + dist.shape[0])] = np.inf
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.where(dist < cutoff, -alpha / (dist + zeta) ** 2 + beta / dist ** 4, 0.0)
        scale *= mass[block, None] * mass[None, :]
        out[block] = np.einsum("ij,ijk->ik", scale, diff)
    return out


def naive_fluid(position, mass, alpha, beta, zeta, cutoff):
    """The lecture's all-pairs sum in plain Python."""
    n = len(position)
    force = [[0.0, 0.0, 0.0] for _ in range(n)]
    for i in range(n):
        xi = position[i]
        for j in range(i + 1, n):
            xj = position[j]
            d = (xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2])
            dist = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
            if dist >= cutoff:
                continue
            s = mass[i] * mass[j] * (-alpha / (dist + zeta) ** 2 + beta / dist ** 4)
            for a in range(3):
                force[i][a] += s * d[a]
                force[j][a] -= s * d[a]
    return force


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes only")
    args = parser.parse_args()
    print(f"OPENBLAS_NUM_THREADS={os.environ['OPENBLAS_NUM_THREADS']}, "
          f"{os.cpu_count()} CPUs (shared: figures are noisy, compare ratios)")
    bench_cloth([32] if args.quick else [32, 64, 128], 1 / 60)
    swing_energy()
    bench_fluid([1000] if args.quick else [1000, 10000])


if __name__ == "__main__":
    main()
