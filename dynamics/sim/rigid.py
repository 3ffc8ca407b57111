"""Rigid bodies: inertia tensors and Newton–Euler motion with quaternion orientation.

State: centre of mass x, velocity v, orientation q (unit quaternion, scipy order
x, y, z, w; body → world), and angular momentum L in the world frame. With R = R(q) and
I_b the inertia about the centre of mass in body axes,

    m dv/dt = F,    dx/dt = v,    dL/dt = τ,    ω = R I_b⁻¹ Rᵀ L,    dR/dt = [ω]× R.

Integrating L (not ω) keeps angular momentum exactly conserved when τ = 0; the
orientation is advanced by the exact exponential of the mid-step angular velocity
(second order), so the body's kinetic energy drifts only at O(Δt²). A force F applied
at a point p adds the torque (p − x) × F.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from dynamics.sim.integrators import SimulationUnstable


def box_inertia(mass: float, size) -> np.ndarray:
    """(3, 3) inertia of a solid box about its centre, kg·m²: m/12 diag(b²+c², a²+c², a²+b²).

    Parameters
    ----------
    mass : float, kg
    size : (3,) float, metres, edge lengths (a, b, c) along the body axes
    """
    a, b, c = (float(s) for s in size)
    return mass / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def inertia_from_points(masses, points) -> tuple[np.ndarray, np.ndarray]:
    """Centre of mass and inertia tensor of point masses.

    I = Σ m_k (|r_k|² 𝟙 − r_k r_kᵀ) with r_k = p_k − centre (the lecture's I_xx = Σ m (y²+z²),
    I_xy = −Σ m x y …).

    Parameters
    ----------
    masses : (K,) float, kg
    points : (K, 3) float, metres

    Returns
    -------
    centre : (3,) float, metres
    inertia : (3, 3) float, kg·m², about the centre
    """
    masses = np.asarray(masses, float)
    points = np.asarray(points, float).reshape(-1, 3)
    centre = masses @ points / masses.sum()
    r = points - centre
    second = np.einsum("k,ki,kj->ij", masses, r, r)
    return centre, np.trace(second) * np.eye(3) - second


def mesh_inertia(vertices, faces, density: float = 1.0) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia of a closed, outward-oriented triangle mesh.

    Sums signed tetrahedra (origin, a, b, c); each contributes the second moment
    det/120 (Σ v vᵀ + s sᵀ), s = a + b + c, of uniform density.

    Parameters
    ----------
    vertices : (V, 3) float, metres
    faces : (F, 3) int, counter-clockwise seen from outside
    density : float, kg/m³

    Returns
    -------
    mass : float, kg
    centre : (3,) float, metres
    inertia : (3, 3) float, kg·m², about the centre
    """
    v = np.asarray(vertices, float)
    f = np.asarray(faces, np.int64)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    det = np.einsum("ij,ij->i", a, np.cross(b, c))                    # 6 × signed volume
    volume = det.sum() / 6.0
    if not volume > 0:
        raise ValueError("mesh must be closed with outward (counter-clockwise) faces")
    centre = (det[:, None] * (a + b + c)).sum(axis=0) / (24.0 * volume)
    s = a + b + c
    second = (np.einsum("t,ti,tj->ij", det, a, a) + np.einsum("t,ti,tj->ij", det, b, b)
              + np.einsum("t,ti,tj->ij", det, c, c) + np.einsum("t,ti,tj->ij", det, s, s)) / 120.0
    mass = density * volume
    second = density * second - mass * np.outer(centre, centre)
    return mass, centre, np.trace(second) * np.eye(3) - second


def box_mesh(size) -> tuple[np.ndarray, np.ndarray]:
    """(8, 3) corners and (12, 3) outward triangles of a box centred on the origin."""
    half = 0.5 * np.asarray(size, float)
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return signs * half, faces


@dataclass
class RigidBody:
    """A rigid body's constant description and its state.

    Attributes
    ----------
    mass : float, kg
    inertia : (3, 3) float, kg·m², about the centre of mass, body axes
    position : (3,) float, metres, centre of mass in the world
    orientation : (4,) float, unit quaternion (x, y, z, w), body → world
    velocity : (3,) float, m/s
    angular_momentum : (3,) float, kg·m²/s, world frame
    vertices : (V, 3) float, metres, body-frame points to draw (e.g. box corners)
    force, torque : (3,) float, accumulated for the next step (N, N·m; world)
    """

    mass: float
    inertia: np.ndarray
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    orientation: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 0.0, 1.0]))
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    angular_momentum: np.ndarray = field(default_factory=lambda: np.zeros(3))
    vertices: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    torque: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        self.inertia = np.asarray(self.inertia, float).reshape(3, 3)
        self.position = np.asarray(self.position, float).reshape(3).copy()
        q = np.asarray(self.orientation, float).reshape(4)
        self.orientation = q / np.linalg.norm(q)
        self.velocity = np.asarray(self.velocity, float).reshape(3).copy()
        self.angular_momentum = np.asarray(self.angular_momentum, float).reshape(3).copy()
        self.vertices = np.asarray(self.vertices, float).reshape(-1, 3)
        self._inverse_inertia = np.linalg.inv(self.inertia)

    @classmethod
    def box(cls, mass: float, size, **state) -> "RigidBody":
        """A solid box of edge lengths ``size`` (metres) with its corners as vertices."""
        corners, _ = box_mesh(size)
        return cls(mass, box_inertia(mass, size), vertices=corners, **state)

    @property
    def rotation(self) -> np.ndarray:
        """(3, 3) body → world rotation matrix."""
        return Rotation.from_quat(self.orientation).as_matrix()

    def inertia_world(self) -> np.ndarray:
        """(3, 3) inertia about the centre of mass in world axes, R I_b Rᵀ."""
        r = self.rotation
        return r @ self.inertia @ r.T

    def angular_velocity(self, rotation: np.ndarray | None = None) -> np.ndarray:
        """(3,) world angular velocity ω = R I_b⁻¹ Rᵀ L, rad/s."""
        r = self.rotation if rotation is None else rotation
        return r @ (self._inverse_inertia @ (r.T @ self.angular_momentum))

    def set_angular_velocity(self, omega) -> None:
        """Set L = I_world ω for a world angular velocity ``omega`` (rad/s)."""
        self.angular_momentum = self.inertia_world() @ np.asarray(omega, float).reshape(3)

    def kinetic_energy(self) -> float:
        """½ m |v|² + ½ ω·L, joules."""
        return 0.5 * self.mass * float(self.velocity @ self.velocity) + 0.5 * float(
            self.angular_velocity() @ self.angular_momentum)

    def apply_force(self, force, point=None) -> None:
        """Accumulate a world force (N) acting at world ``point`` (default: the centre)."""
        force = np.asarray(force, float).reshape(3)
        self.force = self.force + force
        if point is not None:
            self.torque = self.torque + np.cross(np.asarray(point, float) - self.position, force)

    def apply_torque(self, torque) -> None:
        """Accumulate a world torque, N·m."""
        self.torque = self.torque + np.asarray(torque, float).reshape(3)

    def world_vertices(self) -> np.ndarray:
        """(V, 3) the body's vertices in the world, metres."""
        return self.position + self.vertices @ self.rotation.T


def newton_euler_step(body: RigidBody, dt: float, gravity=None,
                      speed_limit: float = float("inf")) -> None:
    """Advance ``body`` by ``dt`` with its accumulated force and torque, then clear them.

    Translation by symplectic Euler; L += Δt τ; orientation by the exponential map of the
    angular velocity at mid-step (from a half-step orientation), renormalised.

    Parameters
    ----------
    body : RigidBody (updated in place)
    dt : float, seconds
    gravity : (3,) float, m/s², optional, adds m g at the centre of mass
    speed_limit : float, m/s
        The particles' stability rule (:class:`dynamics.sim.system.System`): a non-finite
        state, or a centre of mass or vertex faster than this, raises
        :class:`dynamics.sim.integrators.SimulationUnstable` before the orientation update
        (whose quaternion arithmetic would otherwise fail on it).
    """
    force = body.force + (body.mass * np.asarray(gravity, float) if gravity is not None else 0.0)
    body.velocity = body.velocity + dt * force / body.mass
    body.position = body.position + dt * body.velocity
    body.angular_momentum = body.angular_momentum + dt * body.torque
    rotation = Rotation.from_quat(body.orientation)
    omega = body.angular_velocity(rotation.as_matrix())
    reach = float(np.linalg.norm(body.vertices, axis=1).max()) if len(body.vertices) else 0.0
    with np.errstate(over="ignore", invalid="ignore"):     # an absurd push: inf, said below
        speed = float(np.linalg.norm(body.velocity) + np.linalg.norm(omega) * reach)
    state = (body.position, body.velocity, body.angular_momentum, omega)
    if not (all(np.isfinite(v).all() for v in state) and speed <= speed_limit):
        raise SimulationUnstable(f"a rigid body went unstable: speed {speed:.3g} m/s, limit "
                                 f"{speed_limit:g} m/s; use smaller push forces or a smaller dt")
    half = Rotation.from_rotvec(0.5 * dt * omega) * rotation
    omega_mid = body.angular_velocity(half.as_matrix())
    q = (Rotation.from_rotvec(dt * omega_mid) * rotation).as_quat()
    body.orientation = q / np.linalg.norm(q)
    body.force = np.zeros(3)
    body.torque = np.zeros(3)
