"""A Pinocchio humanoid: inverse dynamics and the physical-plausibility check of a motion.

The body is built from a 15-segment :class:`~mocap.skeleton.Skeleton` (free-flyer root at
the pelvis, spherical joints elsewhere) with de Leva (1996) inertias scaled by body mass
and the skeleton's segment lengths (:mod:`mocap.body.anthropometry`), and six contact
points per foot (heel and ball, medial and lateral, plus heel and toe on the long axis).

The check (DESIGN 3.5), for a motion on the floor y = 0 (world Y up):

1. q, v, a on the configuration manifold: quaternions made sign-continuous, smoothed and
   differentiated with a Savitzky–Golay filter (exact for constant, linear and quadratic
   motion, so a still pose and a free fall are known answers); angular velocity and
   acceleration in each joint's frame are ``2 Im(q* ⊗ q̇)`` and ``2 Im(q* ⊗ q̈)``; the root's
   linear velocity is in its own frame (Pinocchio's free-flyer convention). Tests compare
   them with ``pin.difference`` of neighbouring configurations.
2. RNEA for all frames at once (``pin.rneaInParallel``): ``tau[:6]`` is the wrench a
   fictitious actuator at the root would need.
3. Ground reaction forces at the foot points in contact, each inside a friction pyramid
   (non-negative least squares over the pyramid edges): what they cannot supply is the
   residual — the non-physical "hand of God".
4. Joint torques with those contact forces taken off, foot skating, penetration, floating,
   and a verdict with reasons.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np
from scipy.signal import savgol_filter
from scipy.spatial.transform import Rotation

from mocap.errors import MocapError
from mocap.skeleton import BODY_SEGMENTS, LOWER_BODY, Motion, Skeleton, reduce_to_segments

from mocap.body.anthropometry import (SegmentInertia, foot_points, lumped_segments,
                                    segment_inertias)

GRAVITY = 9.81
#: The joint at the proximal end of each body segment (joint torques are named by segment).
JOINT_OF_SEGMENT = {"thorax": "lumbar", "head": "neck", "upperarm": "shoulder",
                    "forearm": "elbow", "hand": "wrist", "thigh": "hip", "shank": "knee",
                    "foot": "ankle"}
#: Floor tolerance (m) for penetration and floating, as in the motion-synthesis literature.
FLOOR_TOLERANCE = 0.005


@dataclass
class Humanoid:
    """The constant description of the body: Pinocchio model, inertias and contact points.

    Attributes
    ----------
    model : pinocchio.Model
        Free-flyer root (nq 7, nv 6) then one spherical joint (nq 4, nv 3) per segment, in
        skeleton order; gravity -9.81 m/s² along Y.
    skeleton : Skeleton
        The 15-segment body.
    mass : float, kg
    inertias : list of SegmentInertia
    contact_points : ndarray, shape (points, 3), metres
        Contact points in their segment's frame.
    contact_segments : list of int
        Segment index of each contact point.
    contact_names : list of str
        ``<foot>.<point>``.
    contact_frames : list of int
        Pinocchio frame id of each contact point.
    lumped : list of (name, segment index, SegmentInertia)
        Body segments the skeleton lacks (a lower-body marker set: head, arms, trunk),
        carried rigidly by a present segment (``mocap.body.anthropometry.lumped_segments``).
    """

    model: object
    skeleton: Skeleton
    mass: float
    inertias: list[SegmentInertia]
    contact_points: np.ndarray
    contact_segments: list[int]
    contact_names: list[str]
    contact_frames: list[int]
    lumped: list = field(default_factory=list)

    @property
    def weight(self) -> float:
        """Body weight in newtons."""
        return self.mass * GRAVITY

    @property
    def nq(self) -> int:
        return int(self.model.nq)

    @property
    def nv(self) -> int:
        return int(self.model.nv)


def build_humanoid(skeleton: Skeleton, body_mass: float = 75.0, sex: str = "male"
                   ) -> Humanoid:
    """A Pinocchio model of the 15-segment body.

    Parameters
    ----------
    skeleton : Skeleton
        With the segment names of ``mocap.skeleton.BODY_SEGMENTS`` (reduce foreign
        skeletons with ``reduce_to_segments``); end sites give the hands, head top and toes.
    body_mass : float, kg
    sex : {"male", "female"}
        Which de Leva table.

    Returns
    -------
    Humanoid
    """
    import pinocchio as pin

    names = skeleton.names
    if not set(LOWER_BODY) <= set(names) <= set(BODY_SEGMENTS) or \
            names != [n for n in BODY_SEGMENTS if n in names]:
        raise MocapError("the body model needs the 15 body segments ("
                         + ", ".join(BODY_SEGMENTS) + "), or at least the pelvis and legs, "
                         f"in that order; got {', '.join(names)}")
    if not body_mass > 0:
        raise MocapError(f"body mass must be positive, got {body_mass}")
    try:
        inertias = segment_inertias(skeleton, body_mass, sex)
        lumped = lumped_segments(skeleton, body_mass, sex)
    except ValueError as error:
        raise MocapError(str(error)) from None
    model = pin.Model()
    model.name = "humanoid"
    model.gravity = pin.Motion(np.array([0.0, -GRAVITY, 0.0, 0.0, 0.0, 0.0]))
    joint_ids = []
    for i, (name, parent) in enumerate(zip(skeleton.names, skeleton.parents)):
        if parent < 0:
            joint = pin.JointModelFreeFlyer()
            placement = pin.SE3.Identity()
            parent_joint = 0
        else:
            joint = pin.JointModelSpherical()
            placement = pin.SE3(np.eye(3), skeleton.offsets[i].copy())
            parent_joint = joint_ids[parent]
        joint_id = model.addJoint(parent_joint, joint, placement, name)
        segment = inertias[i]
        model.appendBodyToJoint(joint_id, pin.Inertia(segment.mass, segment.com.copy(),
                                                      segment.inertia.copy()),
                                pin.SE3.Identity())
        model.addJointFrame(joint_id)
        joint_ids.append(joint_id)
    for _, host, part in lumped:
        model.appendBodyToJoint(joint_ids[host], pin.Inertia(part.mass, part.com.copy(),
                                                             part.inertia.copy()),
                                pin.SE3.Identity())
    points, segments, names, frames = [], [], [], []
    for foot in ("l_foot", "r_foot"):
        index = skeleton.index(foot)
        for label, point in foot_points(skeleton.end_sites[index]).items():
            frame = pin.Frame(f"{foot}.{label}", joint_ids[index], pin.SE3(np.eye(3), point),
                              pin.FrameType.OP_FRAME)
            frames.append(model.addFrame(frame, False))
            points.append(point)
            segments.append(index)
            names.append(f"{foot}.{label}")
    return Humanoid(model, skeleton, float(body_mass), inertias, np.array(points), segments,
                    names, frames, lumped)


# ----------------------------------------------------------------------------------------
# Kinematics on the manifold
# ----------------------------------------------------------------------------------------
def _quat_conj_product_vector(q: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Vector part of conj(q) ⊗ d for quaternions (…, 4) stored x, y, z, w:
    ``w·d_v − d_w·q_v − q_v × d_v`` (written out: np.cross is slow on small last axes)."""
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    a, b, c, e = d[..., 0], d[..., 1], d[..., 2], d[..., 3]
    return np.stack([w * a - e * x - (y * c - z * b),
                     w * b - e * y - (z * a - x * c),
                     w * c - e * z - (x * b - y * a)], axis=-1)


def _quaternion_matrices(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (…, 3, 3) of unit quaternions (…, 4) stored x, y, z, w."""
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], axis=-2)


def _continuous_quaternions(rotations: np.ndarray) -> np.ndarray:
    """Quaternions (frames, joints, 4) of rotation matrices, sign-continuous over frames."""
    frames, joints = rotations.shape[:2]
    quats = Rotation.from_matrix(rotations.reshape(-1, 3, 3)).as_quat().reshape(frames, joints, 4)
    if frames > 1:
        dots = np.einsum("fjk,fjk->fj", quats[1:], quats[:-1])
        flips = np.cumprod(np.where(dots < 0, -1.0, 1.0), axis=0)
        quats[1:] *= flips[..., None]
    return quats


def _window(frames: int, rate: float, seconds: float) -> tuple[int, int]:
    """Savitzky–Golay window length (odd, ≤ frames) and polynomial order."""
    if frames < 3:
        raise MocapError(f"inverse dynamics needs at least 3 frames, the motion has {frames}")
    length = int(round(seconds * rate)) | 1
    length = max(3, min(length, frames if frames % 2 else frames - 1))
    return length, (2 if length < 5 else 3)


@dataclass
class Kinematics:
    """Configurations, velocities and accelerations of a motion, frame by frame.

    Attributes
    ----------
    q : ndarray, shape (frames, nq)
    v, a : ndarray, shape (frames, nv)
    rotations : ndarray, shape (frames, segments, 3, 3)
        Smoothed joint rotations (relative to the parent), as used in ``q``.
    root : ndarray, shape (frames, 3), metres
        Smoothed world position of the root.
    """

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    rotations: np.ndarray
    root: np.ndarray


def motion_kinematics(motion: Motion, smoothing: float = 0.1) -> Kinematics:
    """q, v, a of a 15-segment motion for the Pinocchio model (vectorised over frames).

    Parameters
    ----------
    motion : Motion
        On the body skeleton (segment order = model joint order).
    smoothing : float, seconds
        Savitzky–Golay window (polynomial order 3; 0 gives central differences).

    Returns
    -------
    Kinematics
    """
    dt = 1.0 / motion.rate
    window, order = _window(motion.frames, motion.rate, smoothing)
    quats = _continuous_quaternions(motion.rotations)                   # (F, J, 4)
    root = motion.skeleton.offsets[0] + motion.root_translation         # (F, 3)

    def smooth(x: np.ndarray, deriv: int) -> np.ndarray:
        return savgol_filter(x, window, order, deriv=deriv, delta=dt, axis=0, mode="interp")

    q0, q1, q2 = (smooth(quats, d) for d in (0, 1, 2))
    norm2 = np.einsum("fjk,fjk->fj", q0, q0)[..., None]
    omega = 2.0 * _quat_conj_product_vector(q0, q1) / norm2             # body frame
    alpha = 2.0 * _quat_conj_product_vector(q0, q2) / norm2
    q0 = q0 / np.sqrt(norm2)
    p0, p1, p2 = (smooth(root, d) for d in (0, 1, 2))
    rotations = _quaternion_matrices(q0)                                # (F, J, 3, 3)
    root_r = rotations[:, 0]
    v_lin = np.einsum("fji,fj->fi", root_r, p1)                         # Rᵀ ṗ
    a_lin = np.einsum("fji,fj->fi", root_r, p2) - np.cross(omega[:, 0], v_lin)
    frames = motion.frames
    q = np.concatenate([p0, q0.reshape(frames, -1)], axis=1)
    v = np.concatenate([v_lin, omega.reshape(frames, -1)], axis=1)
    a = np.concatenate([a_lin, alpha.reshape(frames, -1)], axis=1)
    return Kinematics(q, v, a, rotations, p0)


def configurations(motion: Motion) -> np.ndarray:
    """Pinocchio configurations of every frame, unsmoothed, shape (frames, nq)."""
    quats = _continuous_quaternions(motion.rotations)
    root = motion.skeleton.offsets[0] + motion.root_translation
    return np.concatenate([root, quats.reshape(motion.frames, -1)], axis=1)


def rnea_batch(humanoid: Humanoid, q: np.ndarray, v: np.ndarray, a: np.ndarray,
               threads: int = 1) -> np.ndarray:
    """Joint torques of many frames at once (``pin.rneaInParallel``).

    Parameters
    ----------
    q : ndarray, shape (frames, nq)
    v, a : ndarray, shape (frames, nv)
    threads : int

    Returns
    -------
    ndarray, shape (frames, nv)
        ``[:, :6]`` is the root wrench (force then torque about the root origin, root frame).
    """
    import pinocchio as pin

    frames = q.shape[0]
    pool = _pool(humanoid, max(threads, 1))
    tau = pin.rneaInParallel(max(threads, 1), pool, np.asfortranarray(q.T),
                             np.asfortranarray(v.T), np.asfortranarray(a.T))
    return np.asarray(tau).T.reshape(frames, humanoid.nv)


_POOL: list = []        # [(model, size, ModelPool)]: the last pool, with its model kept alive


def _pool(humanoid: Humanoid, size: int):
    """A Pinocchio ModelPool for this model (reused while the same model is asked for)."""
    import pinocchio as pin

    if not _POOL or _POOL[0][0] is not humanoid.model or _POOL[0][1] != size:
        _POOL[:] = [(humanoid.model, size, pin.ModelPool(humanoid.model, size))]
    return _POOL[0][2]


# ----------------------------------------------------------------------------------------
# Contact forces in friction pyramids
# ----------------------------------------------------------------------------------------
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


# ----------------------------------------------------------------------------------------
# The check
# ----------------------------------------------------------------------------------------
@dataclass
class Thresholds:
    """Limits above which the check calls a motion implausible.

    Attributes
    ----------
    residual_rms_pct_bw : float
        RMS residual force, % body weight (a static 20° lean gives about 7 %).
    residual_peak_pct_bw : float
        Peak residual force, % body weight.
    residual_torque_rms_nm : float
        RMS residual torque about the centre of mass, N·m, for a 75 kg body (scaled in
        proportion to body mass); OpenSim's guidance for captured data is below 50 N·m.
    penetration_mm : float
        Deepest point below the floor.
    skate_speed : float, m/s
        Mean horizontal speed of foot points in contact (captured walking: 0.06–0.12).
    floating_fraction : float
        Fraction of frames off the floor while needing support (residual above
        ``floating_residual_pct_bw``) that counts as floating.
    """

    residual_rms_pct_bw: float = 5.0
    residual_peak_pct_bw: float = 25.0
    residual_torque_rms_nm: float = 50.0
    penetration_mm: float = 20.0
    skate_speed: float = 0.2
    floating_fraction: float = 0.1
    floating_residual_pct_bw: float = 10.0


@dataclass
class CheckReport:
    """Result of :func:`check_motion` (per-frame series and summary figures).

    Per-frame arrays have ``frames`` rows; forces in N, torques in N·m, lengths in mm.
    """

    mass_kg: float
    frames: int
    rate: float
    times: np.ndarray
    residual_force: np.ndarray           # (F, 3) world
    residual_torque: np.ndarray          # (F, 3) world, about the centre of mass
    contact_forces: np.ndarray           # (F, P, 3) world
    contact_active: np.ndarray           # (F, P) bool
    contact_names: list[str]
    joint_torques: np.ndarray            # (F, J-1, 3) in each joint's frame
    joint_names: list[str]               # the segment each joint moves (l_thigh = left hip)
    lowest_point_mm: np.ndarray          # (F,) height of the lowest body point
    foot_skate_mm: float
    skating_ratio: float
    penetration_mm: float
    floating_mm: float
    floating_frames: int
    verdict: str
    reasons: list[str]
    thresholds: Thresholds = field(default_factory=Thresholds)
    lumped_segments: list[str] = field(default_factory=list)
    floor_m: float = 0.0

    @property
    def weight(self) -> float:
        return self.mass_kg * GRAVITY

    def summary(self) -> dict:
        """The DESIGN 3.5 JSON object (plain Python types)."""
        force = np.linalg.norm(self.residual_force, axis=1)
        torque = np.linalg.norm(self.residual_torque, axis=1)
        peaks = np.linalg.norm(self.joint_torques, axis=2).max(axis=0) if self.frames else []
        return {
            "mass_kg": round(self.mass_kg, 3),
            "frames": self.frames,
            "rate_hz": self.rate,
            "residual_force_rms_N": _r(_rms(force)),
            "residual_force_peak_N": _r(force.max()),
            "residual_force_rms_pct_bw": _r(100.0 * _rms(force) / self.weight),
            "residual_force_peak_pct_bw": _r(100.0 * force.max() / self.weight),
            "residual_torque_rms_Nm": _r(_rms(torque)),
            "residual_torque_peak_Nm": _r(torque.max()),
            "foot_skate_mm": _r(self.foot_skate_mm),
            "skating_ratio": _r(self.skating_ratio),
            "penetration_mm": _r(self.penetration_mm),
            "floating_mm": _r(self.floating_mm),
            "floating_frames": self.floating_frames,
            "peak_joint_torque_Nm": {n: _r(p) for n, p in zip(self.joint_names, peaks)},
            "verdict": self.verdict,
            "reasons": list(self.reasons),
            "lumped_segments": list(self.lumped_segments),
            "floor_m": _r(self.floor_m),
        }


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x.size else 0.0


def _r(x: float) -> float:
    return round(float(x), 3)


def check_motion(motion: Motion, body_mass: float = 75.0, sex: str = "male",
                 mu: float = 0.8, contact_height: float = 0.03,
                 contact_speed: float = 1.0, smoothing: float = 0.1,
                 thresholds: Thresholds | None = None, threads: int = 1,
                 humanoid: Humanoid | None = None, floor: float | str = 0.0) -> CheckReport:
    """Check a motion for physical plausibility (DESIGN 3.5).

    Parameters
    ----------
    motion : Motion
        Any skeleton with recognisable joint names (reduced to the 15-segment body with
        ``reduce_to_segments``; pelvis and legs are enough, the rest is then lumped into the
        pelvis); floor y = 0, Y up, metres.
    body_mass : float, kg
    sex : {"male", "female"}
    mu : float
        Friction coefficient of the floor.
    contact_height : float, m
        A foot point lower than this, and slower than ``contact_speed`` (m/s), may push on
        the floor.
    smoothing : float, s
        Savitzky–Golay window for velocities and accelerations.
    thresholds : Thresholds, optional
    threads : int
        Threads of ``pin.rneaInParallel``.
    humanoid : Humanoid, optional
        A model built before (its skeleton must be the motion's reduced skeleton).
    floor : float or "auto"
        Height of the floor in the motion (m, Y up); "auto" takes the median height of the
        lowest foot point over the frames where a foot stands still (for files whose floor
        is not at y = 0). The check then works with the floor at 0.

    Returns
    -------
    CheckReport
    """
    thresholds = thresholds or Thresholds()
    body = reduce_to_segments(motion, partial=True)
    if humanoid is None:
        humanoid = build_humanoid(body.skeleton, body_mass, sex)
    floor_height = estimate_floor(body, humanoid) if floor == "auto" else float(floor)
    if floor_height:
        body = Motion(body.skeleton, body.root_translation - [0.0, floor_height, 0.0],
                      body.rotations, body.rate, dict(body.metadata))
    frames, rate = body.frames, body.rate
    kin = motion_kinematics(body, smoothing)
    tau = rnea_batch(humanoid, kin.q, kin.v, kin.a, threads)

    # Root wrench in world axes about the root origin.
    root_r = Rotation.from_quat(kin.q[:, 3:7]).as_matrix()
    force_w = np.einsum("fij,fj->fi", root_r, tau[:, :3])
    torque_w = np.einsum("fij,fj->fi", root_r, tau[:, 3:6])
    wrench = np.concatenate([force_w, torque_w], axis=1)

    smoothed = Motion(body.skeleton, kin.root - body.skeleton.offsets[0], kin.rotations, rate)
    world_r, world_p = smoothed.forward_kinematics()
    contact_world = _contact_positions(humanoid, world_r, world_p)          # (F, P, 3)
    speed = np.linalg.norm(np.gradient(contact_world, 1.0 / rate, axis=0), axis=2)
    active = (contact_world[:, :, 1] < contact_height) & (speed < contact_speed)
    levers = contact_world - kin.root[:, None, :]
    forces, residual = solve_contact_forces(wrench, levers, active, mu)

    # Residual torque about the centre of mass.
    com = _centre_of_mass(humanoid, world_r, world_p)
    residual_torque = residual[:, 3:] - np.cross(com - kin.root, residual[:, :3])

    joint_torques = tau[:, 6:].reshape(frames, -1, 3) - contact_joint_torques(
        humanoid, world_r, world_p, contact_world, forces)

    # Geometry of the raw (unsmoothed) motion: floor contact, skating.
    raw_r, raw_p = body.forward_kinematics()
    raw_contacts = _contact_positions(humanoid, raw_r, raw_p)
    _, ends = body.end_site_positions((raw_r, raw_p))
    every = np.concatenate([raw_p, ends, raw_contacts], axis=1)
    lowest = every[:, :, 1].min(axis=1)
    skate_mm, skating_ratio = _foot_skate(raw_contacts, contact_height, contact_speed, rate)
    below = np.clip(-lowest - FLOOR_TOLERANCE, 0.0, None)
    penetration_mm = 1000.0 * float(below.max()) if frames else 0.0
    above = lowest > FLOOR_TOLERANCE
    floating_mm = 1000.0 * float(lowest[above].mean()) if above.any() else 0.0
    residual_pct = 100.0 * np.linalg.norm(residual[:, :3], axis=1) / humanoid.weight
    unsupported = above & (residual_pct > thresholds.floating_residual_pct_bw)

    torque_rms = _rms(np.linalg.norm(residual_torque, axis=1))
    torque_limit = thresholds.residual_torque_rms_nm * humanoid.mass / 75.0
    reasons = _reasons(residual_pct, penetration_mm, skate_mm * rate / 1000.0,
                       unsupported, floating_mm, thresholds)
    if torque_rms > torque_limit:
        after_force = sum(r.startswith("residual force") for r in reasons)
        reasons.insert(after_force, f"residual torque RMS {torque_rms:.0f} N·m "
                       f"(limit {torque_limit:.0f} N·m)")
    names = body.skeleton.names
    return CheckReport(
        mass_kg=float(humanoid.mass), frames=frames, rate=rate, times=body.times,
        residual_force=residual[:, :3], residual_torque=residual_torque,
        contact_forces=forces, contact_active=active, contact_names=humanoid.contact_names,
        joint_torques=joint_torques, joint_names=names[1:],
        lowest_point_mm=1000.0 * lowest, foot_skate_mm=skate_mm, skating_ratio=skating_ratio,
        penetration_mm=penetration_mm, floating_mm=floating_mm,
        floating_frames=int(unsupported.sum()),
        verdict="implausible" if reasons else "plausible", reasons=reasons,
        thresholds=thresholds, lumped_segments=[name for name, _, _ in humanoid.lumped],
        floor_m=floor_height)


def estimate_floor(body: Motion, humanoid: Humanoid, still_speed: float = 0.15) -> float:
    """Floor height (m) of a motion: the median height of each foot's lowest contact point
    over the frames where that foot stands still (all its points slower than
    ``still_speed`` m/s); 0 when a foot never stands still."""
    world_r, world_p = body.forward_kinematics()
    contacts = _contact_positions(humanoid, world_r, world_p)
    speed = np.linalg.norm(np.gradient(contacts, 1.0 / body.rate, axis=0), axis=2)
    heights = []
    for foot in sorted(set(humanoid.contact_segments)):
        points = [k for k, s in enumerate(humanoid.contact_segments) if s == foot]
        still = (speed[:, points] < still_speed).all(axis=1)
        heights.append(contacts[still][:, points, 1].min(axis=1))
    found = np.concatenate(heights) if heights else np.zeros(0)
    return float(np.median(found)) if found.size else 0.0


def _contact_positions(humanoid: Humanoid, world_r: np.ndarray, world_p: np.ndarray
                       ) -> np.ndarray:
    """World positions (frames, points, 3) of the contact points."""
    seg = humanoid.contact_segments
    return world_p[:, seg] + np.einsum("fpij,pj->fpi", world_r[:, seg], humanoid.contact_points)


def _centre_of_mass(humanoid: Humanoid, world_r: np.ndarray, world_p: np.ndarray
                    ) -> np.ndarray:
    """Whole-body centre of mass (frames, 3)."""
    parts = [(i, s) for i, s in enumerate(humanoid.inertias)]
    parts += [(host, s) for _, host, s in humanoid.lumped]
    owners = [i for i, _ in parts]
    masses = np.array([s.mass for _, s in parts])
    coms = np.stack([s.com for _, s in parts])
    points = world_p[:, owners] + np.einsum("fsij,sj->fsi", world_r[:, owners], coms)
    return np.einsum("s,fsi->fi", masses, points) / masses.sum()


def contact_joint_torques(humanoid: Humanoid, world_r: np.ndarray, world_p: np.ndarray,
                          contacts: np.ndarray, forces: np.ndarray,
                          points: list[int] | None = None) -> np.ndarray:
    """Torques the contact forces put on each spherical joint, (frames, J-1, 3).

    A force f at contact point c below joint j adds ``(c − p_j) × f`` about the joint, in
    joint j's frame — the joint rows of ``J_cᵀ f``. RNEA assumed no contact, so a joint's
    torque with contacts is ``tau[6:] −`` this.

    Parameters
    ----------
    world_r, world_p : (frames, segments, 3, 3) and (frames, segments, 3) segment poses
    contacts, forces : (frames, points, 3) contact positions (m) and forces (N), world
    points : list of int, optional
        Only these contact points (default: all).
    """
    sk = humanoid.skeleton
    frames = world_p.shape[0]
    chosen = range(len(humanoid.contact_segments)) if points is None else points
    result = np.zeros((frames, sk.count - 1, 3))
    for j in range(1, sk.count):
        below = set(sk.subtree(j))
        on = [k for k in chosen if humanoid.contact_segments[k] in below]
        if not on:
            continue
        moment = np.cross(contacts[:, on] - world_p[:, j, None], forces[:, on]).sum(axis=1)
        result[:, j - 1] = np.einsum("fji,fj->fi", world_r[:, j], moment)
    return result


def _foot_skate(contacts: np.ndarray, height: float, speed: float, rate: float
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


def _reasons(residual_pct: np.ndarray, penetration_mm: float, skate_speed: float,
             unsupported: np.ndarray, floating_mm: float, limits: Thresholds) -> list[str]:
    reasons = []
    rms = _rms(residual_pct)
    if rms > limits.residual_rms_pct_bw:
        reasons.append(f"residual force RMS {rms:.1f} % body weight "
                       f"(limit {limits.residual_rms_pct_bw:g} %)")
    if residual_pct.size and residual_pct.max() > limits.residual_peak_pct_bw:
        reasons.append(f"residual force peak {residual_pct.max():.1f} % body weight "
                       f"(limit {limits.residual_peak_pct_bw:g} %)")
    if penetration_mm > limits.penetration_mm:
        reasons.append(f"penetrates the floor by {penetration_mm:.0f} mm")
    if skate_speed > limits.skate_speed:
        reasons.append(f"feet skate: {skate_speed:.2f} m/s while in contact "
                       f"(limit {limits.skate_speed:g} m/s)")
    if unsupported.size and unsupported.mean() > limits.floating_fraction:
        reasons.append(f"floating: {floating_mm:.0f} mm above the floor without support in "
                       f"{100 * unsupported.mean():.0f} % of frames")
    return reasons
