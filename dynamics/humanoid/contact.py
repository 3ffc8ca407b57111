"""Ground contact of the humanoid: foot contact points, forces in friction pyramids, the floor.

Ground reaction forces at the foot points in contact, each inside a friction pyramid
(non-negative least squares over the pyramid edges, DESIGN 3.5 step 3): what they cannot
supply is the residual — the non-physical "hand of God". Also where the contact points
are, where the floor is, and how much the feet skate.
"""
from __future__ import annotations

import numba
import numpy as np

from mocap.skeleton import Motion

from dynamics.humanoid.model import Humanoid


@numba.njit(cache=True)
def _solve_passive(gram: np.ndarray, rhs: np.ndarray, passive: np.ndarray):
    """Indices of the passive set and the solution of G[P, P] x = h[P]."""
    index = np.flatnonzero(passive)
    sub = np.empty((index.size, index.size))
    for a in range(index.size):
        for b in range(index.size):
            sub[a, b] = gram[index[a], index[b]]
    return index, np.linalg.solve(sub, rhs[index])


@numba.njit(cache=True)
def _fnnls(gram: np.ndarray, rhs: np.ndarray, tolerance: float,
           start: np.ndarray) -> np.ndarray:
    """Fast NNLS (Bro & de Jong 1997): min ½xᵀGx − hᵀx, x ≥ 0, for a positive-definite G.

    ``start`` (bool, n) is a guess of the variables that end up positive: they seed the
    passive set (pruned until its solution is positive, which gives a feasible start), so a
    good guess leaves few active-set iterations.
    """
    n = rhs.shape[0]
    x = np.zeros(n)
    passive = start.copy()
    while passive.any():
        index, solution = _solve_passive(gram, rhs, passive)
        if solution.min() > 0.0:
            x[index] = solution
            break
        for a in range(index.size):
            if solution[a] <= 0.0:
                passive[index[a]] = False
    gradient = rhs - gram @ x
    for _ in range(3 * n + 10):
        best, pick = tolerance, -1
        for i in range(n):
            if not passive[i] and gradient[i] > best:
                best, pick = gradient[i], i
        if pick < 0:
            break
        passive[pick] = True
        for _inner in range(3 * n + 10):
            index, solution = _solve_passive(gram, rhs, passive)
            if solution.min() > 0.0:
                x[:] = 0.0
                x[index] = solution
                break
            # Step back to the boundary and drop the variables that reach zero.
            alpha = 1.0
            for a in range(index.size):
                if solution[a] <= 0.0:
                    step = x[index[a]] / (x[index[a]] - solution[a])
                    if step < alpha:
                        alpha = step
            for a in range(index.size):
                i = index[a]
                x[i] += alpha * (solution[a] - x[i])
                if x[i] <= tolerance:
                    x[i] = 0.0
                    passive[i] = False
            if not passive.any():
                break
        gradient = rhs - gram @ x
    return x


@numba.njit(cache=True)
def _fnnls_batch(gram: np.ndarray, rhs: np.ndarray, start: np.ndarray) -> np.ndarray:
    """:func:`_fnnls` for every frame: gram (F, n, n), rhs (F, n), start (F, n) bool."""
    frames, n = rhs.shape
    out = np.zeros((frames, n))
    for f in range(frames):
        scale = np.abs(rhs[f]).max()
        if scale > 0.0:
            out[f] = _fnnls(gram[f], rhs[f], 1e-12 * scale, start[f])
    return out


def pyramid_edges(mu: float, edges: int = 4) -> np.ndarray:
    """Unit edge directions of a friction pyramid about +Y, shape (edges, 3)."""
    angles = 2.0 * np.pi * np.arange(edges) / edges
    d = np.stack([mu * np.cos(angles), np.ones(edges), mu * np.sin(angles)], axis=1)
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def solve_contact_forces(wrench: np.ndarray, levers: np.ndarray, active: np.ndarray,
                         mu: float = 0.8, edges: int = 4, regularisation: float = 1e-6
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Contact forces inside friction pyramids that best supply a wrench, frame by frame.

    Solves ``min ‖A λ − W‖² + ε‖λ‖², λ ≥ 0`` per frame, with one column ``[d; r × d]`` per
    pyramid edge ``d`` of each active contact point at lever ``r``: a non-negative
    combination of edges is exactly a force inside the pyramid. The matrices are built for
    all frames at once; the unconstrained ridge solution ``Aᵀ(AAᵀ + εI)⁻¹W`` (batched 6 × 6
    solves) is kept where it is non-negative, and the remaining frames are solved by a
    compiled active-set method on the normal equations (Bro & de Jong's fast NNLS).

    Parameters
    ----------
    wrench : ndarray, shape (frames, 6)
        Required wrench: force (N) then torque (N·m) about the lever origin, world axes.
    levers : ndarray, shape (frames, points, 3), metres
        Contact points relative to the torque's reference point.
    active : ndarray, shape (frames, points), bool
        Which points touch the floor.
    mu : float
        Friction coefficient.
    edges : int
        Edges of each friction pyramid.
    regularisation : float
        Weight ε of ``ε‖λ‖²`` added to the objective: among the (many) force distributions
        that supply the wrench, the smallest; its bias on the residual is of order ε‖λ‖.

    Returns
    -------
    forces : ndarray, shape (frames, points, 3), N
    residual : ndarray, shape (frames, 6)
        ``W − Σ (f, r × f)``: what the contacts cannot supply.
    """
    frames, points = active.shape
    d = pyramid_edges(mu, edges)                                         # (E, 3)
    # Columns for every point and edge, batched over frames: (F, P, E, 6).
    moments = np.cross(levers[:, :, None, :], d[None, None, :, :])
    columns = np.concatenate([np.broadcast_to(d, moments.shape), moments], axis=3)
    columns = columns * active[:, :, None, None]
    matrix = columns.reshape(frames, points * edges, 6).transpose(0, 2, 1)   # (F, 6, P·E)
    # A small ridge (min-norm among exact solutions) spreads the load over the points in
    # contact instead of a vertex solution where feet push against each other sideways.
    # Fast path, all frames at once: the unconstrained ridge solution
    # Aᵀ(AAᵀ + εI)⁻¹W (6 × 6 solves) is the answer wherever it is non-negative — the usual
    # case for a load well inside the pyramids; the other frames go to the active-set solver.
    small = np.einsum("fkn,fln->fkl", matrix, matrix) + regularisation * np.eye(6)
    weights = np.einsum("fkn,fk->fn", matrix, np.linalg.solve(small, wrench[..., None])[..., 0])
    busy = active.any(axis=1) & (weights.min(axis=1) < 0.0)
    if busy.any():
        gram = np.einsum("fkn,fkm->fnm", matrix[busy], matrix[busy])
        gram += regularisation * np.eye(points * edges)
        rhs = np.einsum("fkn,fk->fn", matrix[busy], wrench[busy])
        weights[busy] = _fnnls_batch(gram, rhs, weights[busy] > 0.0)
    forces = np.einsum("fpe,ek->fpk", weights.reshape(frames, points, edges), d)
    supplied = np.einsum("fkn,fn->fk", matrix, weights)
    return forces, wrench - supplied


def estimate_floor(body: Motion, humanoid: Humanoid, still_speed: float = 0.15) -> float:
    """Floor height (m) of a motion: the median height of each foot's lowest contact point
    over the frames where that foot stands still (all its points slower than
    ``still_speed`` m/s); 0 when a foot never stands still."""
    world_r, world_p = body.forward_kinematics()
    contacts = contact_positions(humanoid, world_r, world_p)
    speed = np.linalg.norm(np.gradient(contacts, 1.0 / body.rate, axis=0), axis=2)
    heights = []
    for foot in sorted(set(humanoid.contact_segments)):
        points = [k for k, s in enumerate(humanoid.contact_segments) if s == foot]
        still = (speed[:, points] < still_speed).all(axis=1)
        heights.append(contacts[still][:, points, 1].min(axis=1))
    found = np.concatenate(heights) if heights else np.zeros(0)
    return float(np.median(found)) if found.size else 0.0


def contact_positions(humanoid: Humanoid, world_r: np.ndarray, world_p: np.ndarray
                       ) -> np.ndarray:
    """World positions (frames, points, 3) of the contact points."""
    seg = humanoid.contact_segments
    return world_p[:, seg] + np.einsum("fpij,pj->fpi", world_r[:, seg], humanoid.contact_points)


def foot_skate(contacts: np.ndarray, height: float, speed: float, rate: float
                ) -> tuple[float, float]:
    """Foot skating of contact points, (mean mm per frame, skating ratio).

    A pair of consecutive frames counts when the point is below ``height`` in both and its
    horizontal speed is below ``speed`` (the contact definition of the force solve): a
    swinging foot passes within a centimetre or two of the floor in normal walking (toe
    clearance) but far faster. The skating ratio is the fraction of those pairs faster than
    0.5 m/s (captured walking scores about 0.03–0.07).
    """
    if contacts.shape[0] < 2:
        return 0.0, 0.0
    near = contacts[:, :, 1] < height
    step = np.linalg.norm((contacts[1:] - contacts[:-1])[..., [0, 2]], axis=2)
    both = near[1:] & near[:-1] & (step * rate < speed)
    if not both.any():
        return 0.0, 0.0
    moved = step[both]
    return 1000.0 * float(moved.mean()), float(np.mean(moved * rate > 0.5))
