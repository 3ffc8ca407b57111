"""Colliders: ground planes, spheres, capsules and boxes with restitution and friction.

Collisions are resolved after each integration step by projection: a particle found
inside a collider (closer than the collider's ``margin`` to its surface) is moved onto
the surface along the normal, and its velocity relative to the surface is changed:
the approaching normal part is reversed and scaled by the restitution ``e``
(v_n ← −e v_n) and the tangential part is reduced by Coulomb friction, by at most
μ times the normal velocity change (it stops when friction can hold it).

Spheres and capsules can move (a skeleton's limbs): set their new placement and
velocity every step with ``move_to``, and the response uses the surface velocity.
All work is vectorised over particles.

Examples
--------
>>> arm = Capsule(a=[0, 1.4, 0], b=[0.3, 1.1, 0], radius=0.05)
>>> arm.move_to([0, 1.41, 0], [0.3, 1.12, 0], dt=1 / 120)          # each frame
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np


class Collider(Protocol):
    """Anything that keeps particles out of (or inside) a shape."""

    def resolve(self, position: np.ndarray, velocity: np.ndarray, movable: np.ndarray) -> int:
        """Project penetrating particles; returns how many were in contact."""


def _respond(position: np.ndarray, velocity: np.ndarray, index: np.ndarray,
             normal: np.ndarray, depth: np.ndarray, surface_velocity: np.ndarray,
             restitution: float, friction: float) -> None:
    """Push particles ``index`` out by ``depth`` along ``normal`` and apply the impulse."""
    position[index] += depth[:, None] * normal
    relative = velocity[index] - surface_velocity
    normal_speed = np.einsum("ij,ij->i", relative, normal)
    approaching = normal_speed < 0.0
    if not np.any(approaching):
        return
    rows = np.flatnonzero(approaching)
    vn = normal_speed[rows]
    n = normal[rows]
    tangential = relative[rows] - vn[:, None] * n
    speed_t = np.linalg.norm(tangential, axis=1)
    change_n = -(1.0 + restitution) * vn            # > 0: normal velocity change
    with np.errstate(divide="ignore", invalid="ignore"):
        keep = np.where(speed_t > 0.0, np.maximum(0.0, 1.0 - friction * change_n / speed_t), 0.0)
    new_relative = -restitution * vn[:, None] * n + keep[:, None] * tangential
    sv = surface_velocity if surface_velocity.ndim == 1 else surface_velocity[rows]
    velocity[index[rows]] = new_relative + sv


@dataclass
class Plane:
    """The half-space (x − point)·normal ≥ margin; particles are kept on the normal's side.

    Attributes
    ----------
    point : (3,) float, metres, a point on the plane
    normal : (3,) float, normalised on creation
    restitution : float in [0, 1]
    friction : float, Coulomb coefficient μ ≥ 0
    margin : float, metres, thickness kept between particles and the plane
    """

    point: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]
    normal: np.ndarray = (0.0, 1.0, 0.0)  # type: ignore[assignment]
    restitution: float = 0.0
    friction: float = 0.0
    margin: float = 0.0

    def __post_init__(self) -> None:
        self.point = np.asarray(self.point, dtype=float).reshape(3)
        normal = np.asarray(self.normal, dtype=float).reshape(3)
        norm = np.linalg.norm(normal)
        if not norm > 0:
            raise ValueError("plane normal must be non-zero")
        self.normal = normal / norm

    def signed_distance(self, position: np.ndarray) -> np.ndarray:
        """(N,) distance from the plane (positive on the normal's side) minus margin, m."""
        return (position - self.point) @ self.normal - self.margin

    def resolve(self, position, velocity, movable) -> int:
        distance = self.signed_distance(position)
        index = np.flatnonzero((distance < 0.0) & movable)
        if index.size:
            normal = np.broadcast_to(self.normal, (index.size, 3))
            _respond(position, velocity, index, normal, -distance[index], np.zeros(3),
                     self.restitution, self.friction)
        return int(index.size)


@dataclass
class Sphere:
    """A solid sphere particles cannot enter; may move (set ``velocity`` or use move_to).

    Attributes
    ----------
    centre : (3,) float, metres
    radius : float, metres
    velocity : (3,) float, m/s, the sphere's velocity (for the contact response)
    restitution, friction, margin : as for :class:`Plane`
    """

    centre: np.ndarray
    radius: float
    velocity: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]
    restitution: float = 0.0
    friction: float = 0.0
    margin: float = 0.0

    def __post_init__(self) -> None:
        self.centre = np.asarray(self.centre, dtype=float).reshape(3).copy()
        self.velocity = np.asarray(self.velocity, dtype=float).reshape(3).copy()
        if not self.radius > 0:
            raise ValueError("sphere radius must be positive")

    def move_to(self, centre, dt: float | None = None, velocity=None) -> None:
        """Place the sphere at ``centre``; its velocity is ``velocity`` or the move / dt."""
        centre = np.asarray(centre, dtype=float).reshape(3)
        if velocity is not None:
            self.velocity = np.asarray(velocity, dtype=float).reshape(3).copy()
        elif dt:
            self.velocity = (centre - self.centre) / dt
        self.centre = centre.copy()

    def signed_distance(self, position: np.ndarray) -> np.ndarray:
        """(N,) distance outside the sphere's surface minus margin, metres."""
        return np.linalg.norm(position - self.centre, axis=1) - self.radius - self.margin

    def resolve(self, position, velocity, movable) -> int:
        offset = position - self.centre
        distance = np.linalg.norm(offset, axis=1)
        depth = self.radius + self.margin - distance
        index = np.flatnonzero((depth > 0.0) & movable)
        if index.size:
            normal = _unit_or_up(offset[index], distance[index])
            _respond(position, velocity, index, normal, depth[index], self.velocity,
                     self.restitution, self.friction)
        return int(index.size)


@dataclass
class Capsule:
    """A solid capsule (segment a–b swept by ``radius``): a limb for cloth to rest on.

    Attributes
    ----------
    a, b : (3,) float, metres, the segment's ends
    radius : float, metres
    velocity_a, velocity_b : (3,) float, m/s, velocities of the ends (interpolated along
        the segment for the contact response)
    restitution, friction, margin : as for :class:`Plane`
    """

    a: np.ndarray
    b: np.ndarray
    radius: float
    velocity_a: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]
    velocity_b: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]
    restitution: float = 0.0
    friction: float = 0.0
    margin: float = 0.0

    def __post_init__(self) -> None:
        self.a = np.asarray(self.a, dtype=float).reshape(3).copy()
        self.b = np.asarray(self.b, dtype=float).reshape(3).copy()
        self.velocity_a = np.asarray(self.velocity_a, dtype=float).reshape(3).copy()
        self.velocity_b = np.asarray(self.velocity_b, dtype=float).reshape(3).copy()
        if not self.radius > 0:
            raise ValueError("capsule radius must be positive")

    def move_to(self, a, b, dt: float | None = None, velocity_a=None, velocity_b=None) -> None:
        """Place the capsule's ends at ``a`` and ``b``; velocities given or move / dt."""
        a = np.asarray(a, dtype=float).reshape(3)
        b = np.asarray(b, dtype=float).reshape(3)
        if velocity_a is not None:
            self.velocity_a = np.asarray(velocity_a, dtype=float).reshape(3).copy()
        elif dt:
            self.velocity_a = (a - self.a) / dt
        if velocity_b is not None:
            self.velocity_b = np.asarray(velocity_b, dtype=float).reshape(3).copy()
        elif dt:
            self.velocity_b = (b - self.b) / dt
        self.a, self.b = a.copy(), b.copy()

    def _closest(self, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        axis = self.b - self.a
        length2 = float(axis @ axis)
        t = np.zeros(len(position)) if length2 == 0 else np.clip(
            (position - self.a) @ axis / length2, 0.0, 1.0)
        return self.a + t[:, None] * axis, t

    def signed_distance(self, position: np.ndarray) -> np.ndarray:
        """(N,) distance outside the capsule's surface minus margin, metres."""
        closest, _ = self._closest(position)
        return np.linalg.norm(position - closest, axis=1) - self.radius - self.margin

    def resolve(self, position, velocity, movable) -> int:
        closest, t = self._closest(position)
        offset = position - closest
        distance = np.linalg.norm(offset, axis=1)
        depth = self.radius + self.margin - distance
        index = np.flatnonzero((depth > 0.0) & movable)
        if index.size:
            normal = _unit_or_up(offset[index], distance[index])
            ti = t[index][:, None]
            surface_velocity = (1.0 - ti) * self.velocity_a + ti * self.velocity_b
            _respond(position, velocity, index, normal, depth[index], surface_velocity,
                     self.restitution, self.friction)
        return int(index.size)


@dataclass
class Box:
    """An axis-aligned box that keeps particles inside (a container), top open or closed.

    Attributes
    ----------
    minimum, maximum : (3,) float, metres, opposite corners
    open_top : bool, no lid on the +``up`` face
    up : int, axis index of "up" (1 = Y, the scene convention)
    restitution, friction, margin : as for :class:`Plane`
    """

    minimum: np.ndarray
    maximum: np.ndarray
    open_top: bool = True
    up: int = 1
    restitution: float = 0.0
    friction: float = 0.0
    margin: float = 0.0
    planes: list = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.minimum = np.asarray(self.minimum, dtype=float).reshape(3)
        self.maximum = np.asarray(self.maximum, dtype=float).reshape(3)
        if not np.all(self.maximum > self.minimum):
            raise ValueError("box maximum must exceed minimum on every axis")
        self.planes = []
        for axis in range(3):
            normal = np.zeros(3)
            normal[axis] = 1.0
            self.planes.append(Plane(self.minimum, normal, self.restitution, self.friction,
                                     self.margin))
            if not (self.open_top and axis == self.up):
                self.planes.append(Plane(self.maximum, -normal, self.restitution,
                                         self.friction, self.margin))

    def resolve(self, position, velocity, movable) -> int:
        return sum(plane.resolve(position, velocity, movable) for plane in self.planes)


def _unit_or_up(offset: np.ndarray, distance: np.ndarray) -> np.ndarray:
    """Unit vectors of ``offset`` rows; +Y where a particle sits exactly on the centre."""
    normal = np.empty_like(offset)
    ok = distance > 1e-12
    normal[ok] = offset[ok] / distance[ok, None]
    normal[~ok] = (0.0, 1.0, 0.0)
    return normal


def resolve_collisions(colliders: list, position: np.ndarray, velocity: np.ndarray,
                       movable: np.ndarray) -> int:
    """Resolve every collider in turn (in place); returns the number of contacts."""
    return sum(c.resolve(position, velocity, movable) for c in colliders)
