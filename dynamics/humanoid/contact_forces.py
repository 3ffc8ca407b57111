"""Ground reaction forces at the foot points in contact, each inside a friction pyramid
(non-negative least squares over the pyramid edges, the check's third step, ``docs/check.md``): what they cannot
supply is the residual — the non-physical "hand of God". The friction-pyramid problem is
solved for all frames at once by :func:`ridge_nnls` (numpy, no compiled code). Which
points are in contact, and where the floor is, is :mod:`dynamics.humanoid.contact`.

Load preference. Among the contact forces that supply the same wrench the solve prefers
points nearest their floor and slowest, like a compliant sole: each point's share of the
ridge term is weighted by ``1 + (h / H)² + (v / V)²`` with H = 10 mm and V = 0.1 m/s
(its height above its floor and speed). This decides how the load is shared between the
heel of the leading foot and the toes of the trailing one in double support, which the
wrench alone does not fix.

A prior centre of pressure. ``centres`` adds, per group of points (a foot), two rows to
the fit: the horizontal moment of the group's forces about a given point, fitted to zero
— a linear way to say "this foot's centre of pressure is near there" (its misfit is the
load times the distance, as a torque). :func:`dynamics.humanoid.check.check_motion` uses
it with the heel-to-toe roll-over of :func:`dynamics.humanoid.contact.rollover_centres`.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: Height and speed scales of the load preference (module docstring).
PREFERENCE_HEIGHT = 0.010
PREFERENCE_SPEED = 0.1
#: Ridge cost of a contact force along its preferred direction, relative to the edges.
PREFERRED_COST = 0.1


def preference_weights(heights: np.ndarray, speeds: np.ndarray) -> np.ndarray:
    """Ridge weights of the contact points, ``1 + (h/H)² + (v/V)²`` (module docstring)."""
    h = np.clip(heights, 0.0, None) / PREFERENCE_HEIGHT
    return 1.0 + h ** 2 + (speeds / PREFERENCE_SPEED) ** 2


def ridge_nnls(matrix: np.ndarray, target: np.ndarray, ridge: float,
               iterations: int = 60, start: np.ndarray | None = None) -> np.ndarray:
    """``min ½‖A λ − b‖² + ½ε‖λ‖², λ ≥ 0`` for many small problems at once (numpy only).

    Solved in the residual ``r = b − Aλ`` (6 unknowns a frame, whatever the number of
    generators): at the optimum ``λ = max(0, Aᵀr) / ε``, so ``r`` minimises the strongly
    convex, piecewise quadratic ``Φ(r) = ½‖r‖² − bᵀr + ‖max(0, Aᵀr)‖² / 2ε``. Newton's
    method on Φ (its Hessian ``I + A_S A_Sᵀ / ε`` over the generators S with ``Aᵀr > 0``)
    with a backtracking line search converges in a handful of steps and is exact once S
    settles; every step is a batch of 6 × 6 solves, so there is no per-frame loop and no
    compiled code.

    Parameters
    ----------
    matrix : ndarray, shape (frames, m, n)
    target : ndarray, shape (frames, m)
    ridge : float
        ε > 0.
    start : ndarray, shape (frames, m), optional
        A first guess of the residual (e.g. that of the unconstrained ridge solution,
        ``ε (AAᵀ + εI)⁻¹ b``, whose positive generators are usually the final ones).

    Returns
    -------
    ndarray, shape (frames, n)
    """
    frames, m, n = matrix.shape
    transposed = np.swapaxes(matrix, 1, 2)
    r = np.array(target if start is None else start, dtype=float)
    eye = np.eye(m)
    scale = 1.0 + np.linalg.norm(target, axis=1)

    def objective(goal: np.ndarray, res: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Φ at ``res``, given ``z = Aᵀ res``."""
        z = np.maximum(z, 0.0)
        return 0.5 * (res * res).sum(axis=1) - (goal * res).sum(axis=1) \
            + 0.5 * (z * z).sum(axis=1) / ridge

    todo = np.arange(frames)
    at = transposed                         # the unfinished frames' Aᵀ, gathered once a step
    previous = np.full((frames, n), 2, np.int8)            # 2: no set seen yet
    accepted = None                         # Aᵀr of the step the line search accepted
    for _ in range(iterations):
        if not todo.size:
            break
        a, res = np.swapaxes(at, 1, 2), r[todo]
        z = (at @ res[..., None])[..., 0] if accepted is None else accepted
        on = z > 0.0
        gradient = res - target[todo] + (a @ (np.where(on, z, 0.0) / ridge)[..., None])[..., 0]
        # Done: stationary, or the generator set settled after a full step (Φ is quadratic
        # on it, so that step was exact).
        done = (np.linalg.norm(gradient, axis=1) <= 1e-12 * scale[todo]) | \
            (on == previous[todo]).all(axis=1)
        previous[todo] = on
        keep = ~done
        if not keep.all():
            todo, at, z, on, res, gradient = (todo[keep], at[keep], z[keep], on[keep],
                                              res[keep], gradient[keep])
            a = np.swapaxes(at, 1, 2)
        if not todo.size:
            break
        goal = target[todo]
        hessian = eye + (a * on[:, None, :]) @ at / ridge
        step = -np.linalg.solve(hessian, gradient[..., None])[..., 0]
        slope = (gradient * step).sum(axis=1)
        before = objective(goal, res, z)
        t = np.ones(todo.size)
        accepted = None
        for _ in range(30):
            trial = res + t[:, None] * step
            z = (at @ trial[..., None])[..., 0]
            worse = objective(goal, trial, z) > before + 1e-4 * t * slope
            if not worse.any():
                accepted = z                    # r becomes this trial, bit for bit
                break
            t = np.where(worse, 0.5 * t, t)
        r[todo] = res + t[:, None] * step
        previous[todo[t < 1.0]] = 2             # a damped step: not settled yet
    return np.maximum((transposed @ r[..., None])[..., 0], 0.0) / ridge


def pyramid_edges(mu: float, edges: int = 4) -> np.ndarray:
    """Unit edge directions of a friction pyramid about +Y, shape (edges, 3)."""
    angles = 2.0 * np.pi * np.arange(edges) / edges
    d = np.stack([mu * np.cos(angles), np.ones(edges), mu * np.sin(angles)], axis=1)
    return d / np.linalg.norm(d, axis=1, keepdims=True)


class ContactColumns(NamedTuple):
    """The generators of a contact solve (:func:`contact_columns`), which two solves of the
    same contacts (the check's, with and without the roll-over prior) share."""

    #: Unit generators ``d`` per point: pyramid edges, then the preferred direction;
    #: (frames, points, kinds, 3).
    directions: np.ndarray
    #: ``[d; r × d]`` per point and generator, zero where the point is not in contact;
    #: (frames, points · kinds, 6).
    columns: np.ndarray
    #: Ridge cost of each generator (∞: the preferred direction outside the pyramid);
    #: (frames, points, kinds).
    cost: np.ndarray


def contact_columns(levers: np.ndarray, active: np.ndarray, mu: float = 0.8, edges: int = 4,
                    weights: np.ndarray | None = None, preferred: np.ndarray | None = None
                    ) -> ContactColumns:
    """The generators of :func:`solve_contact_forces` for these contacts (its parameters of
    the same names); pass them back as its ``columns`` to solve again without building them."""
    frames, points = active.shape
    kinds = edges + (preferred is not None)
    # Columns [d; r × d] for every point and generator d, batched over frames: (F, P, K, 6),
    # written in place (np.concatenate and np.cross on these small axes cost more than
    # the solve); the same arithmetic as r × d by np.cross, so the same bits. The generators
    # lie generator-major in memory, as np.concatenate left them: the forces' matmul in
    # solve_contact_forces then sums in the same order as it always did.
    d = np.empty((kinds, frames, points, 3)).transpose(1, 2, 0, 3)
    d[:, :, :edges] = pyramid_edges(mu, edges)
    cost = np.empty((frames, points, kinds))
    cost[:, :, :edges] = 1.0 if weights is None else weights[:, :, None]
    if preferred is not None:
        # One more generator per point: the preferred direction, where inside the pyramid,
        # at a fraction of the ridge cost (so it carries the load unless the wrench needs
        # otherwise).
        unit = preferred / np.maximum(np.linalg.norm(preferred, axis=2, keepdims=True), 1e-12)
        inside = np.hypot(unit[..., 0], unit[..., 2]) <= mu * unit[..., 1]
        d[:, :, edges] = unit
        extra = (weights if weights is not None else np.ones((frames, points))) \
            * PREFERRED_COST
        cost[:, :, edges] = np.where(inside, extra, np.inf)
    columns = np.empty((frames, points, kinds, 6))
    columns[..., :3] = d
    r = levers[:, :, None, :]
    np.subtract(r[..., 1] * d[..., 2], r[..., 2] * d[..., 1], out=columns[..., 3])
    np.subtract(r[..., 2] * d[..., 0], r[..., 0] * d[..., 2], out=columns[..., 4])
    np.subtract(r[..., 0] * d[..., 1], r[..., 1] * d[..., 0], out=columns[..., 5])
    columns *= active[:, :, None, None]
    return ContactColumns(d, columns.reshape(frames, points * kinds, 6), cost)


def solve_contact_forces(wrench: np.ndarray, levers: np.ndarray, active: np.ndarray,
                         mu: float = 0.8, edges: int = 4, regularisation: float = 1e-6,
                         torque_length: float = 1.0, weights: np.ndarray | None = None,
                         preferred: np.ndarray | None = None,
                         centres: np.ndarray | None = None, groups: np.ndarray | None = None,
                         centre_length: float = 1.0, columns: ContactColumns | None = None
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Contact forces inside friction pyramids that best supply a wrench, frame by frame.

    Solves ``min ‖A λ − W‖² + ε‖λ‖², λ ≥ 0`` per frame, with one column ``[d; r × d]`` per
    pyramid edge ``d`` of each active contact point at lever ``r``: a non-negative
    combination of edges is exactly a force inside the pyramid. The matrices are built for
    all frames at once; the unconstrained ridge solution ``Aᵀ(AAᵀ + εI)⁻¹W`` (batched 6 × 6
    solves) is kept where it is non-negative, and the remaining frames are solved by a
    batched semi-smooth Newton method on the 6-D dual (:func:`ridge_nnls`).

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
    torque_length : float, m
        The length that makes the wrench norm well posed: the misfit is
        ``‖ΔF‖² + ‖ΔM / L‖²`` (a torque error counts as the force that makes it at lever L).
    weights : ndarray, shape (frames, points), optional
        Per-point weights of the ridge term (``ε Σ w_p ‖λ_p‖²``): which points to load
        first among equivalent distributions (:func:`preference_weights`).
    preferred : ndarray, shape (frames, points, 3), optional
        A preferred force direction per point (the check: towards the centre of mass),
        added as a generator costing :data:`PREFERRED_COST` of the edges where it lies
        inside the pyramid.

    centres : ndarray, shape (frames, points, 3), optional
        A prior centre of pressure for each point's group (its foot), relative to the
        same reference as ``levers`` (NaN: none in that frame): each group adds two rows,
        the horizontal moment of its forces about its centre (``Σ (r_p − c) × f_p``, X
        and Z), fitted to zero, divided by ``centre_length`` as the torque rows are by
        ``torque_length``.
    groups : ndarray, shape (points,), int, optional
        The group (foot) of each point; required with ``centres``.
    centre_length : float, m
        The length the prior rows' moments are divided by.
    columns : ContactColumns, optional
        :func:`contact_columns` of these ``levers``, ``active``, ``mu``, ``edges``,
        ``weights`` and ``preferred``, when an earlier solve made them.

    Returns
    -------
    forces : ndarray, shape (frames, points, 3), N
    residual : ndarray, shape (frames, 6)
        ``W − Σ (f, r × f)``: what the contacts cannot supply.
    """
    if columns is None:
        columns = contact_columns(levers, active, mu, edges, weights, preferred)
    frames, points = active.shape
    d, flat, cost = columns
    kinds = d.shape[2]
    physical = flat.transpose(0, 2, 1)                                 # (F, 6, P·K)
    # Scaled problem: torque rows over L; columns over √cost (λ = μ / √cost keeps λ ≥ 0).
    scale = (1.0 / np.sqrt(cost)).reshape(frames, points * kinds)
    rows = np.array([1.0, 1.0, 1.0] + [1.0 / torque_length] * 3)
    # Products in place, here and below: fewer temporaries of this size, whose fresh pages'
    # first-touch faults cost up to a sixth of the whole check's time.
    target = wrench * rows
    if centres is None:
        matrix = flat * rows
        matrix *= scale[:, :, None]
        matrix = matrix.transpose(0, 2, 1)                             # (F, 6, P·K)
    else:
        member = np.asarray(groups)[:, None] == np.unique(groups)[None, :]  # (P, G)
        matrix = np.empty((frames, 6 + 2 * member.shape[1], points * kinds))
        np.multiply(physical, rows[:, None], out=matrix[:, :6])
        known = active & np.isfinite(centres).all(axis=2)
        x = (levers - np.nan_to_num(centres))[:, :, None, :]
        # X and Z of (r − c) × d, as np.cross computes them: (2, F, P, K)
        about = np.empty((2, frames, points, kinds))
        np.subtract(x[..., 1] * d[..., 2], x[..., 2] * d[..., 1], out=about[0])
        np.subtract(x[..., 0] * d[..., 1], x[..., 1] * d[..., 0], out=about[1])
        about *= known[None, :, :, None]
        about /= centre_length
        # (F, G, 2, P, K): each group's two rows, the other groups' points at zero
        prior = matrix[:, 6:].reshape(frames, member.shape[1], 2, points, kinds)
        np.multiply(about.transpose(1, 0, 2, 3)[:, None],
                    member.T.astype(float)[None, :, None, :, None], out=prior)
        matrix *= scale[:, None, :]
        target = np.concatenate([target, np.zeros((frames, matrix.shape[1] - 6))], axis=1)
    m = matrix.shape[1]
    # A small ridge (min-norm among exact solutions) spreads the load over the points in
    # contact instead of a vertex solution where feet push against each other sideways.
    # Fast path, all frames at once: the unconstrained ridge solution
    # Aᵀ(AAᵀ + εI)⁻¹W (6 × 6 solves) is the answer wherever it is non-negative — the usual
    # case for a load well inside the pyramids; the other frames go to ridge_nnls.
    transposed = np.swapaxes(matrix, 1, 2)                              # (F, P·K, 6)
    small = matrix @ transposed + regularisation * np.eye(m)
    dual = np.linalg.solve(small, target[..., None])[..., 0]
    amounts = (transposed @ dual[..., None])[..., 0]
    busy = active.any(axis=1) & (amounts.min(axis=1) < 0.0)
    if busy.any():
        amounts[busy] = ridge_nnls(matrix[busy], target[busy], regularisation,
                                   start=regularisation * dual[busy])
    amounts = amounts * scale
    forces = (amounts.reshape(frames, points, 1, kinds) @ d)[:, :, 0]
    supplied = (physical @ amounts[..., None])[..., 0]
    return forces, wrench - supplied
