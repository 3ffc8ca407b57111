"""The ``docs/formats/markerset-toml.md`` frame of three markers and a segment's signed axis permutation.

``markers`` of a segment are origin, axis point and plane point: per frame,
``e1 = unit(p2 - p1)``, ``e3 = unit(e1 x (p3 - p1))``, ``e2 = e3 x e1`` and the
segment's rotation is ``[e1 e2 e3]`` (columns), its origin ``p1``
(:func:`frame_from_markers`; :func:`frame_components` is its component-major fast path used
by :mod:`mocap.rotations.frames`). A segment's optional ``axes`` entry relabels those columns with a
signed permutation (:func:`axes_matrix`).
"""
from __future__ import annotations

import numpy as np

#: Names of the three marker-frame axes in a segment's ``axes`` entry.
AXIS_NAMES = {"e1": 0, "e2": 1, "e3": 2}


def axes_matrix(axes: tuple[str, str, str] | list[str]) -> np.ndarray:
    """Signed permutation for a segment's ``axes`` entry, shape (3, 3).

    Column k of the result picks the signed column of ``[e1 e2 e3]`` that
    becomes the segment's k-th axis.
    """
    matrix = np.zeros((3, 3))
    for k, text in enumerate(axes):
        sign = -1.0 if text.startswith("-") else 1.0
        matrix[AXIS_NAMES[text.lstrip("+-")], k] = sign
    return matrix


def frame_from_markers(p1: np.ndarray, p2: np.ndarray, p3: np.ndarray
                       ) -> np.ndarray:
    """Rotation of the ``docs/formats/markerset-toml.md`` frame of three markers, vectorised.

    Parameters
    ----------
    p1, p2, p3 : ndarray, shape (..., 3), metres
        Origin, axis point and plane point.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Columns e1, e2, e3; NaN where a marker is missing or the markers are
        (nearly) collinear or coincident.
    """
    p1, p2, p3 = (np.moveaxis(np.asarray(p, dtype=float), -1, 0) for p in (p1, p2, p3))
    return np.moveaxis(frame_components(p2 - p1, p3 - p1), (0, 1), (-2, -1))


def frame_components(axis: np.ndarray, plane: np.ndarray) -> np.ndarray:
    """Frames from component-major arrays (the fast path of frame_from_markers).

    Parameters
    ----------
    axis, plane : ndarray, shape (3, ...)
        ``p2 - p1`` and ``p3 - p1``; ``axis`` is overwritten (normalised).

    Returns
    -------
    ndarray, shape (3, 3, ...)
        ``out[i, j]`` is component i of axis j.
    """
    ax, ay, az = axis
    bx, by, bz = plane
    out = np.empty((3, 3) + ax.shape)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = ax * ax
        scale += ay * ay
        scale += az * az
        np.sqrt(scale, out=scale)
        np.divide(1.0, scale, out=scale)
        ax *= scale
        ay *= scale
        az *= scale
        nx, ny, nz = out[0, 2], out[1, 2], out[2, 2]
        np.multiply(ay, bz, out=nx)
        nx -= az * by
        np.multiply(az, bx, out=ny)
        ny -= ax * bz
        np.multiply(ax, by, out=nz)
        nz -= ay * bx
        length = nx * nx
        length += ny * ny
        length += nz * nz
        # collinear markers leave no plane: refuse rather than return noise
        plane_sq = bx * bx
        plane_sq += by * by
        plane_sq += bz * bz
        length[~(length > 1e-18 * plane_sq)] = np.nan
        np.sqrt(length, out=length)
        np.divide(1.0, length, out=length)
        nx *= length
        ny *= length
        nz *= length
        ax += 0.0 * nx                     # NaN for the whole frame, not half of it
        ay += 0.0 * nx
        az += 0.0 * nx
        out[0, 0], out[1, 0], out[2, 0] = ax, ay, az
        np.multiply(ny, az, out=out[0, 1])
        out[0, 1] -= nz * ay
        np.multiply(nz, ax, out=out[1, 1])
        out[1, 1] -= nx * az
        np.multiply(nx, ay, out=out[2, 1])
        out[2, 1] -= ny * ax
    return out

