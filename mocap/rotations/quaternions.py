"""Unit quaternions and rotation matrices, in numpy, vectorised over any leading axes.

The conventions and algorithms are scipy's (``Rotation.from_matrix(...).as_quat()`` and
``Rotation.from_quat(...).as_matrix()``): quaternions stored x, y, z, w; a matrix turned
into a quaternion by Markley's method (the best conditioned of four formulas, then
normalised), a matrix that is not orthogonal to 1e-12 first replaced by its nearest
rotation (``U Vᵀ`` of its SVD). The results equal scipy's to the last bit or so (tests
compare them); they live here because importing ``scipy.spatial.transform`` costs about
0.4 s of CPU, more than the whole ``mocap check`` of a real walk without it.
"""
from __future__ import annotations

import numpy as np

from mocap.errors import MocapError


def normalise_quaternions(quats: np.ndarray) -> np.ndarray:
    """Quaternions (…, 4) scaled to unit length.

    Raises
    ------
    MocapError
        For a quaternion of zero length (NaN ones stay NaN, as in scipy).
    """
    x, y, z, w = quats[..., 0], quats[..., 1], quats[..., 2], quats[..., 3]
    norms = np.sqrt(x * x + y * y + z * z + w * w)     # summed in this order, as scipy
    if np.any(norms == 0):
        raise MocapError("a quaternion has zero length")
    return quats / norms[..., None]


def quaternions_to_matrices(quats: np.ndarray) -> np.ndarray:
    """Rotation matrices of quaternions (normalised first).

    Parameters
    ----------
    quats : ndarray, shape (…, 4)
        x, y, z, w.

    Returns
    -------
    ndarray, shape (…, 3, 3)
        ``R`` with ``R @ v`` the rotated vector.

    Examples
    --------
    >>> quaternions_to_matrices(np.array([0.0, 0.0, 1.0, 1.0])).round(12) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    q = normalise_quaternions(np.asarray(quats, dtype=float))
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    x2, y2, z2, w2 = x * x, y * y, z * z, w * w
    xy, zw, xz, yw, yz, xw = x * y, z * w, x * z, y * w, y * z, x * w
    out = np.empty(q.shape[:-1] + (9,))
    out[..., 0] = x2 - y2 - z2 + w2
    out[..., 1] = 2 * (xy - zw)
    out[..., 2] = 2 * (xz + yw)
    out[..., 3] = 2 * (xy + zw)
    out[..., 4] = -x2 + y2 - z2 + w2
    out[..., 5] = 2 * (yz - xw)
    out[..., 6] = 2 * (xz - yw)
    out[..., 7] = 2 * (yz + xw)
    out[..., 8] = -x2 - y2 + z2 + w2
    return out.reshape(q.shape[:-1] + (3, 3))


def matrices_to_quaternions(matrices: np.ndarray) -> np.ndarray:
    """Unit quaternions of rotation matrices (Markley's method, as scipy).

    Parameters
    ----------
    matrices : ndarray, shape (…, 3, 3)
        Rotations (``R @ v`` rotates ``v``); one that is not orthogonal to 1e-12 is
        replaced by the nearest rotation first.

    Returns
    -------
    ndarray, shape (…, 4)
        x, y, z, w; the sign is that of the formula chosen (not made continuous).

    Raises
    ------
    MocapError
        For a matrix whose determinant is not positive (a mirror or a degenerate frame).

    Examples
    --------
    >>> matrices_to_quaternions(np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])).round(6)
    array([0.      , 0.      , 0.707107, 0.707107])
    """
    m = np.asarray(matrices, dtype=float)
    flat = np.ascontiguousarray(m.reshape(-1, 9).T)          # (9, n): one row per entry
    a, b, c, d, e, f, g, h, i = flat                         # views: the SVD fix shows
    if np.any(a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g) <= 0):
        raise MocapError("a rotation matrix has a non-positive determinant")
    # R Rᵀ = I to scipy's tolerance (np.isclose: atol 1e-12, rtol 1e-5), else U Vᵀ
    unit, zero = 1e-12 + 1e-5, 1e-12
    orthogonal = ((np.abs(a * a + b * b + c * c - 1) <= unit)
                  & (np.abs(d * d + e * e + f * f - 1) <= unit)
                  & (np.abs(g * g + h * h + i * i - 1) <= unit)
                  & (np.abs(a * d + b * e + c * f) <= zero)
                  & (np.abs(a * g + b * h + c * i) <= zero)
                  & (np.abs(d * g + e * h + f * i) <= zero))
    if not orthogonal.all():
        u, _, vt = np.linalg.svd(flat[:, ~orthogonal].T.reshape(-1, 3, 3),
                                 full_matrices=False)
        flat[:, ~orthogonal] = (u @ vt).reshape(-1, 9).T
    trace = a + e + i
    # the largest of a, e, i, trace (the first on ties, as np.argmax)
    choice = np.zeros(a.shape, dtype=np.intp)
    best = a.copy()
    for k, value in ((1, e), (2, i), (3, trace)):
        better = value > best
        choice[better] = k
        np.copyto(best, value, where=better)
    t0, t1, t2, t3 = 1 - trace + 2 * a, 1 - trace + 2 * e, 1 - trace + 2 * i, 1 + trace
    s1, s2, s3, d1, d2, d3 = d + b, g + c, h + f, h - f, c - g, d - b
    q = np.stack([np.choose(choice, [t0, s1, s2, d1]), np.choose(choice, [s1, t1, s3, d2]),
                  np.choose(choice, [s2, s3, t2, d3]), np.choose(choice, [d1, d2, d3, t3])])
    x, y, z, w = q
    q /= np.sqrt(x * x + y * y + z * z + w * w)            # summed in this order, as scipy
    return np.ascontiguousarray(q.T).reshape(m.shape[:-2] + (4,))
