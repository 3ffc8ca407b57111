"""Plug-in Gait's chord function: a joint centre from a wand, the proximal joint centre and
the marker on the joint (the knee and ankle joint centres of :mod:`mocap.plugingait.model` and of
the marker sets' ``joint_centre`` virtual markers), and the subject values it takes from a
trial's PROCESSING group.
"""
from __future__ import annotations

import numpy as np


def processing_number(trial, name: str) -> float | None:
    """A number of the trial's PROCESSING group (Vicon's subject values), by name in any
    case; None when absent, not a number or 0 (Vicon's "not measured")."""
    parameters = getattr(trial, "parameters", None) or {}
    group = {str(k).upper(): v for k, v in (parameters.get("PROCESSING") or {}).items()}
    try:
        value = float(np.ravel(group.get(name.upper()))[0])
    except (TypeError, ValueError, IndexError):
        return None
    return value if np.isfinite(value) and value != 0 else None


def _unit(v: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore", divide="ignore"):
        return v / np.linalg.norm(v, axis=-1, keepdims=True)


def rotate_about(v: np.ndarray, axis: np.ndarray, angle: float | np.ndarray) -> np.ndarray:
    """Rodrigues rotation of vectors ``v`` about unit ``axis`` by ``angle`` radians."""
    c, s = np.cos(angle), np.sin(angle)
    dot = np.sum(axis * v, axis=-1, keepdims=True)
    return v * c + np.cross(axis, v) * s + axis * dot * (1.0 - c)


def chord(plane: np.ndarray, joint: np.ndarray, marker: np.ndarray, delta: float,
          rotation: float = 0.0, iterations: int = 6) -> np.ndarray:
    """Plug-in Gait's chord function: a joint centre from three points.

    The centre ``J`` lies at ``delta`` from ``marker`` and sees ``joint`` and
    ``marker`` at a right angle (``(J - marker) ⟂ (J - joint)``: ``J`` is on
    the sphere with diameter joint–marker), in the plane of (``plane``,
    ``joint``, ``marker``) turned about the segment axis ``joint - J`` by
    ``rotation``.

    Parameters
    ----------
    plane, joint, marker : ndarray, shape (frames, 3), metres
        Wand (plane) marker, proximal joint centre, the marker on the joint
        (any one length unit: the construction is scale-free).
    delta : float
        Metres, or the unit of the points (half the joint width plus the marker
        radius).
    rotation : float
        Radians: the angle about the segment axis from the wand's plane to the
        plane (joint, J, marker) (Plug-in Gait's thigh / shank rotation
        offsets).  The axis depends on ``J``, so the centre is found by a fixed
        number of vectorised fixed-point ``iterations`` (the angle converges
        geometrically; 6 give < 1e-9 m for offsets below 30 degrees).

    Returns
    -------
    ndarray, shape (frames, 3), the points' unit; NaN where an input is NaN.
    """
    axis = joint - marker                                    # v2
    length = np.linalg.norm(axis, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        theta = np.arccos(np.clip(delta / length, -1.0, 1.0))
        direction = axis / length
    middle = (joint + marker) / 2.0

    def solve(point: np.ndarray) -> np.ndarray:
        normal = _unit(np.cross(point - marker, axis))        # v3
        # v2 rotated about v3 by 2θ (v3 ⟂ v2), scaled to half |v2|, from the midpoint
        rotated = (direction * np.cos(2 * theta)
                   + np.cross(normal, direction) * np.sin(2 * theta))
        return middle + rotated * (length / 2.0)

    centre = solve(plane)
    if rotation:
        for _ in range(iterations):    # a few whole-trial passes, not a frame loop
            long_axis = _unit(joint - centre)
            turned = centre + rotate_about(plane - centre, long_axis, rotation)
            centre = solve(turned)
    return centre
