"""Inverse dynamics of the humanoid: batched RNEA and the torques contact forces add.

RNEA for all frames at once (``pin.rneaInParallel``, the check's second step, ``docs/check.md``): ``tau[:6]`` is
the wrench a fictitious actuator at the root would need; :func:`contact_joint_torques`
gives the joint rows of ``J_cᵀ f`` that ground reaction forces take off the joint torques.
"""
from __future__ import annotations

import numpy as np

from dynamics.humanoid.model import Humanoid


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
    # deferred: Pinocchio is imported only by the code that builds or runs a model
    import pinocchio as pin

    frames = q.shape[0]
    pool = humanoid.model_pool(max(threads, 1))
    tau = pin.rneaInParallel(max(threads, 1), pool, np.asfortranarray(q.T),
                             np.asfortranarray(v.T), np.asfortranarray(a.T))
    return np.asarray(tau).T.reshape(frames, humanoid.nv)


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
