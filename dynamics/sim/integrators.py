"""Time integrators for a :class:`dynamics.sim.system.System`.

- :func:`explicit_euler_step`    x⁺ = x + Δt v,  v⁺ = v + Δt a(x, v)
- :func:`symplectic_euler_step`  v⁺ = v + Δt a(x, v),  x⁺ = x + Δt v⁺  (the lecture's
  "explicit Euler" code, which updates the velocity first: semi-implicit / symplectic)
- :func:`rk4_step`               classical fourth-order Runge–Kutta on (x, v)
- :func:`implicit_euler_step`    backward Euler, with three solvers:

  * ``"direct"``: the lecture's system A v⁺ = b with A = M/Δt + G + Δt K, assembled as a
    scipy.sparse matrix from the spring Jacobians and factorised (SuperLU, the sparse
    counterpart of the lecture's LDLᵀ); the factorisation is reused while A is unchanged.
  * ``"cg"``: the same system by Jacobi-preconditioned conjugate gradients.
  * ``"projective"`` (default): Liu et al. 2013 "Fast simulation of mass-spring
    systems": backward Euler as an energy minimisation, alternating a local step (each
    spring's direction at its rest length) and a global step whose matrix
    M + Δt (D + L_γ) + Δt² L_k is constant, so it is factorised once per Δt, pinned set
    and stiffness. Spring damping enters that matrix isotropically (γ_s (v_j − v_i)
    rather than only along the spring), which is what keeps the matrix constant.

Pinned particles are kinematic in every integrator: x += Δt v, v unchanged.

:func:`advance` is the one call a step loop needs: it integrates, resolves collisions,
diffuses heat, ages particles and stops an unstable run with :class:`SimulationUnstable`.
"""
from __future__ import annotations

import numba
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from mocap.errors import MocapError

from dynamics.sim.collisions import resolve_collisions
from dynamics.sim.pairs import add_pair_force, separation
from dynamics.sim.springs import spring_jacobian_blocks

#: Names accepted by :func:`advance` (and the scene file's ``integrator`` key).
INTEGRATORS = ("explicit-euler", "symplectic-euler", "rk4", "implicit-euler")
#: Solvers of :func:`implicit_euler_step`.
IMPLICIT_SOLVERS = ("projective", "direct", "cg")


class SimulationUnstable(MocapError):
    """The run blew up (non-finite or absurd velocities); names the step and a remedy."""


# -- explicit integrators -------------------------------------------------------------------
def _acceleration(system, position, velocity, time, out=None) -> np.ndarray:
    force = system.compute_forces(position, velocity, time, out)
    force *= system.particles.inverse_mass[:, None]
    return force


def explicit_euler_step(system, dt: float) -> None:
    """Forward Euler: positions move with the old velocity (unstable for undamped springs)."""
    p = system.particles
    a = _acceleration(system, p.position, p.velocity, system.time)
    p.position += dt * p.velocity
    p.velocity += dt * a


def symplectic_euler_step(system, dt: float) -> None:
    """Semi-implicit (symplectic) Euler: v⁺ = v + Δt a(x, v), then x⁺ = x + Δt v⁺."""
    p = system.particles
    buffer = system.cache.get("force_buffer")
    if buffer is None or buffer.shape != p.position.shape:
        buffer = system.cache["force_buffer"] = np.empty_like(p.position)
    a = system.compute_forces(p.position, p.velocity, system.time, buffer)
    a *= p.inverse_mass[:, None]
    _kick_drift(p.position, p.velocity, a, dt)


@numba.njit(cache=True, nogil=True)
def _kick_drift(position, velocity, acceleration, dt):
    for i in range(position.shape[0]):
        for c in range(3):
            velocity[i, c] += dt * acceleration[i, c]
            position[i, c] += dt * velocity[i, c]


def rk4_step(system, dt: float) -> None:
    """Classical fourth-order Runge–Kutta on the first-order system (x, v)."""
    p = system.particles
    x0, v0, t0 = p.position.copy(), p.velocity.copy(), system.time
    k1x, k1v = v0, _acceleration(system, x0, v0, t0)
    k2x = v0 + 0.5 * dt * k1v
    k2v = _acceleration(system, x0 + 0.5 * dt * k1x, k2x, t0 + 0.5 * dt)
    k3x = v0 + 0.5 * dt * k2v
    k3v = _acceleration(system, x0 + 0.5 * dt * k2x, k3x, t0 + 0.5 * dt)
    k4x = v0 + dt * k3v
    k4v = _acceleration(system, x0 + dt * k3x, k4x, t0 + dt)
    p.position[...] = x0 + dt / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x)
    p.velocity[...] = v0 + dt / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)


# -- implicit Euler ----------------------------------------------------------------------------
def _velocity_coefficients(system) -> np.ndarray:
    """(N,) Σ γ of the forces linear in velocity (drag, wind), N·s/m."""
    gamma = np.zeros(len(system.particles))
    for force in system.forces:
        coefficients = getattr(force, "velocity_coefficients", None)
        if coefficients is not None:
            gamma += coefficients(system.particles)
    return gamma


def implicit_euler_step(system, dt: float, solver: str = "projective", iterations: int = 10,
                        tolerance: float = 1e-6) -> None:
    """Backward Euler step.

    Parameters
    ----------
    system : System
    dt : float, seconds
    solver : "projective" | "direct" | "cg" (see the module docstring)
    iterations : int, local/global iterations of the projective solver
        (more = closer to the exact backward-Euler solution, less numerical damping)
    tolerance : float, relative residual for conjugate gradients
    """
    if solver == "projective":
        _projective_step(system, dt, iterations)
    elif solver in ("direct", "cg"):
        _linearised_step(system, dt, solver, tolerance)
    else:
        raise MocapError(f"unknown implicit solver {solver!r}; use one of "
                         + ", ".join(IMPLICIT_SOLVERS))


def _free_index(pinned: np.ndarray) -> np.ndarray:
    """(N,) position of each particle among the free ones, −1 for pinned particles."""
    index = np.full(len(pinned), -1, dtype=np.int64)
    free = np.flatnonzero(~pinned)
    index[free] = np.arange(len(free))
    return index


def _linearised_step(system, dt: float, solver: str, tolerance: float) -> None:
    """Baraff–Witkin / lecture: (M/Δt + G + Δt K) Δv = f − Δt K v, then v += Δv, x += Δt v."""
    p, springs = system.particles, system.springs
    n = len(p)
    force = system.compute_forces()
    kx, kv = spring_jacobian_blocks(springs, p.position)
    i, j = springs.pairs[:, 0], springs.pairs[:, 1]
    # K v, with (K v)_i = Σ_s K_s (v_i − v_j)
    stretch_rate = np.einsum("sab,sb->sa", kx, p.velocity[j] - p.velocity[i])
    k_times_v = np.zeros((n, 3))
    np.add.at(k_times_v, i, -stretch_rate)
    np.add.at(k_times_v, j, stretch_rate)
    rhs_all = force - dt * k_times_v

    free_index = _free_index(p.pinned)
    nf = int(np.count_nonzero(free_index >= 0))
    if nf == 0:
        p.position += dt * p.velocity
        return
    block = kv + dt * kx                                 # (M, 3, 3)
    fi, fj = free_index[i], free_index[j]
    rows, cols, data = [], [], []
    axes_r = np.repeat(np.arange(3), 3)                  # (9,) row within block
    axes_c = np.tile(np.arange(3), 3)                    # (9,) column within block
    flat = block.reshape(-1, 9)
    for a_index, b_index, sign in ((fi, fi, 1.0), (fj, fj, 1.0), (fi, fj, -1.0), (fj, fi, -1.0)):
        keep = (a_index >= 0) & (b_index >= 0)
        rows.append((3 * a_index[keep, None] + axes_r).ravel())
        cols.append((3 * b_index[keep, None] + axes_c).ravel())
        data.append((sign * flat[keep]).ravel())
    free = free_index >= 0
    diagonal = np.repeat(p.mass[free] / dt + _velocity_coefficients(system)[free], 3)
    rows.append(np.arange(3 * nf))
    cols.append(np.arange(3 * nf))
    data.append(diagonal)
    matrix = sp.csr_matrix((np.concatenate(data), (np.concatenate(rows), np.concatenate(cols))),
                           shape=(3 * nf, 3 * nf))
    matrix.sum_duplicates()
    rhs = rhs_all[free].ravel()

    if solver == "direct":
        cached = system.cache.get("implicit_direct")
        if (cached is not None and cached[0].shape == matrix.shape
                and cached[0].nnz == matrix.nnz
                and np.array_equal(cached[0].indptr, matrix.indptr)
                and np.array_equal(cached[0].indices, matrix.indices)
                and np.array_equal(cached[0].data, matrix.data)):
            factor = cached[1]                           # A unchanged: reuse the factorisation
        else:
            factor = spla.splu(matrix.tocsc(), permc_spec="MMD_AT_PLUS_A",
                               diag_pivot_thresh=0.0, options={"SymmetricMode": True})
            system.cache["implicit_direct"] = (matrix, factor)
        delta = factor.solve(rhs)
    else:
        guess = system.cache.get("implicit_cg_guess")
        if guess is None or guess.shape != rhs.shape:
            guess = np.zeros_like(rhs)
        preconditioner = sp.diags(1.0 / matrix.diagonal())
        delta, info = spla.cg(matrix, rhs, x0=guess, rtol=tolerance,
                              maxiter=max(1000, len(rhs) // 4), M=preconditioner)
        if info != 0:
            raise SimulationUnstable(
                f"conjugate gradients did not converge at step {system.step_count + 1} "
                f"(t = {system.time:.4g} s); use solver = \"direct\" or a smaller dt")
        system.cache["implicit_cg_guess"] = delta
    p.velocity[free] += delta.reshape(-1, 3)
    p.position += dt * p.velocity


@numba.njit(cache=True, nogil=True)
def _projected_spring_rhs(position, pairs, rest, stiffness, out):
    """out_i += k l û, out_j −= k l û with û = unit(x_i − x_j): Liu et al.'s J d."""
    for s in range(pairs.shape[0]):
        k = stiffness[s]
        if k == 0.0 or rest[s] == 0.0:
            continue
        i = pairs[s, 0]
        j = pairs[s, 1]
        d0, d1, d2, length = separation(position, j, i)      # x_i − x_j
        if length < 1e-12:
            continue
        scale = k * rest[s] / length
        add_pair_force(out, i, j, scale * d0, scale * d1, scale * d2)


def _laplacian(n: int, pairs: np.ndarray, weight: np.ndarray) -> sp.csr_matrix:
    """(n, n) weighted graph Laplacian Σ_s w_s (e_i − e_j)(e_i − e_j)ᵀ."""
    i, j = pairs[:, 0], pairs[:, 1]
    rows = np.concatenate([i, j, i, j])
    cols = np.concatenate([i, j, j, i])
    data = np.concatenate([weight, weight, -weight, -weight])
    return sp.csr_matrix((data, (rows, cols)), shape=(n, n))


def _projective_factor(system, dt: float, gamma: np.ndarray):
    """The global-step matrix split into free/pinned blocks, factorised; cached."""
    p, springs = system.particles, system.springs
    key = (dt, len(p), springs.version, len(springs), p.pinned.tobytes(), p.mass.tobytes(),
           gamma.tobytes())
    cached = system.cache.get("projective")
    if cached is not None and cached[0] == key:
        return cached[1]
    n = len(p)
    laplacian_k = _laplacian(n, springs.pairs, springs.stiffness)
    laplacian_g = _laplacian(n, springs.pairs, springs.damping)
    damping = sp.diags(gamma) + laplacian_g
    matrix = (sp.diags(p.mass) + dt * damping + dt * dt * laplacian_k).tocsr()
    free = np.flatnonzero(~p.pinned)
    fixed = np.flatnonzero(p.pinned)
    factor = None
    if len(free):
        factor = spla.splu(matrix[free][:, free].tocsc(), permc_spec="MMD_AT_PLUS_A",
                           diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    coupling = matrix[free][:, fixed].tocsr()
    parts = (factor, coupling, free, fixed, damping.tocsr())
    system.cache["projective"] = (key, parts)
    return parts


def _projective_step(system, dt: float, iterations: int) -> None:
    p, springs = system.particles, system.springs
    gamma = _velocity_coefficients(system)
    factor, coupling, free, fixed, damping = _projective_factor(system, dt, gamma)
    x0 = p.position.copy()
    # explicit external forces: everything except springs, with the velocity-linear part
    # (−γ v of drag and wind) added back because the matrix treats it implicitly
    external = np.zeros_like(x0)
    for force in system.forces:
        force.accumulate(p, x0, p.velocity, system.time, external)
    external += gamma[:, None] * p.velocity
    inertial = x0 + dt * p.velocity                       # y = x + Δt v (pinned: their target)
    base = p.mass[:, None] * inertial + dt * (damping @ x0) + dt * dt * external
    x = inertial.copy()
    if factor is not None:
        pinned_term = coupling @ x[fixed] if len(fixed) else 0.0
        rhs = np.empty_like(x)
        for _ in range(max(1, iterations)):
            rhs[...] = 0.0
            _projected_spring_rhs(x, springs.pairs, springs.rest_length, springs.stiffness, rhs)
            rhs *= dt * dt
            rhs += base
            x[free] = factor.solve(np.asfortranarray(rhs[free] - pinned_term))
    p.velocity[...] = (x - x0) / dt
    p.velocity[fixed] = (inertial[fixed] - x0[fixed]) / dt
    p.position[...] = x


# -- the step loop's one call ----------------------------------------------------------------
def stability_limit(system) -> float:
    """Estimated largest stable Δt of the explicit integrators, seconds (inf if no springs).

    Gershgorin bound on the stiffest mode: ω² ≤ 2 Σ_j k_ij / m_i, Δt < 2/ω, also
    limited by damping (Δt < m_i / Σ γ). Symplectic Euler is stable just below it;
    explicit Euler gains energy at any Δt for undamped springs.
    """
    p, springs = system.particles, system.springs
    n = len(p)
    if n == 0:
        return np.inf
    total_k = np.bincount(springs.pairs.ravel(), np.repeat(springs.stiffness, 2), minlength=n)
    total_g = (np.bincount(springs.pairs.ravel(), np.repeat(springs.damping, 2), minlength=n)
               + _velocity_coefficients(system))
    free = ~p.pinned
    with np.errstate(divide="ignore"):
        limit_k = np.sqrt(2.0 * p.mass[free] / total_k[free])
        limit_g = p.mass[free] / total_g[free]
    limits = np.concatenate([limit_k, limit_g])
    return float(limits.min()) if limits.size else np.inf


_STEPPERS = {
    "explicit-euler": explicit_euler_step,
    "symplectic-euler": symplectic_euler_step,
    "rk4": rk4_step,
    "implicit-euler": implicit_euler_step,
}


def advance(system, dt: float, integrator: str = "symplectic-euler", **options) -> None:
    """One full step: integrate, collide, diffuse heat, age, check stability.

    Parameters
    ----------
    system : System
    dt : float, seconds
    integrator : one of :data:`INTEGRATORS`
    **options : passed to :func:`implicit_euler_step` (``solver``, ``iterations``)

    Raises
    ------
    SimulationUnstable
        When a position or velocity became non-finite or a particle exceeded
        ``system.speed_limit``; the state is left as it was before the step.
    """
    stepper = _STEPPERS.get(integrator)
    if stepper is None:
        raise MocapError(f"unknown integrator {integrator!r}; use one of " + ", ".join(INTEGRATORS))
    p = system.particles
    before = (p.position.copy(), p.velocity.copy())
    stepper(system, dt, **options)
    if system.colliders:
        resolve_collisions(system.colliders, p.position, p.velocity, ~p.pinned)
    if system.heat is not None:
        system.heat.step(system, dt)
    _check_stable(system, dt, integrator, before)
    p.age += dt
    system.time += dt
    system.step_count += 1


def _check_stable(system, dt: float, integrator: str, before) -> None:
    p = system.particles
    speed2 = np.einsum("ij,ij->i", p.velocity, p.velocity) if len(p) else np.zeros(0)
    worst = float(speed2.max()) if speed2.size else 0.0
    if np.isfinite(worst) and worst <= system.speed_limit ** 2 and np.all(np.isfinite(p.position)):
        return
    p.position[...], p.velocity[...] = before
    limit = stability_limit(system)
    smaller = 0.5 * limit if limit < dt else 0.25 * dt
    hint = (f"reduce dt to about {smaller:.3g} s or use integrator = \"implicit-euler\"")
    if limit < np.inf:
        hint += f" (estimated spring stability limit {limit:.3g} s)"
    if integrator == "implicit-euler":
        hint = (f"reduce dt (e.g. to {0.25 * dt:.3g} s), raise the projective solver's "
                "iterations or add damping")
    elif integrator == "explicit-euler":
        hint = ("use integrator = \"symplectic-euler\" or \"implicit-euler\" (explicit Euler "
                f"gains energy at any dt), or reduce dt to about {smaller:.3g} s")
    raise SimulationUnstable(
        f"simulation became unstable at step {system.step_count + 1} (t = {system.time + dt:.4g} s, "
        f"dt = {dt:.3g} s, {integrator}): particle speeds exceeded "
        f"{system.speed_limit:.3g} m/s or became non-finite; {hint}")
