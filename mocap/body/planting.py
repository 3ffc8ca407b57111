"""Plant the feet: the root translation that keeps the supporting contact point still.

Joint angles alone (a synthesised cycle, say) say nothing about where the body is in
the room.  Walking moves the body by what its supporting foot pushes: while a point
of the foot carries the body, that point does not move on the floor.  Given the
contact points of a figure posed with its root fixed, :func:`planted_translation`
returns, per frame, the translation that keeps the lowest contact point fixed
horizontally and on the floor vertically (no skating, no floating, no penetration).
The supporting point is the lowest one in each frame; when it changes, the new one
is planted where it is.  A flight phase (running) is not modelled: the lowest point
always touches the floor.
"""
from __future__ import annotations

import numpy as np


def planted_translation(contacts: np.ndarray, up: int = 2) -> np.ndarray:
    """Per-frame translation that plants the lowest contact point.

    Parameters
    ----------
    contacts : ndarray, shape (frames, points, 3), metres
        Contact points (heels, toes …) of the figure posed with its root fixed.
    up : int
        Index of the vertical axis (2 for a Z-up lab, 1 for BVH's Y up).

    Returns
    -------
    ndarray, shape (frames, 3), metres
        Translation to add to every point of the figure, frame by frame; the first
        frame's horizontal translation is zero.

    Examples
    --------
    >>> import numpy as np
    >>> foot = np.array([[[0.0, 0.0, 0.1]], [[-0.1, 0.0, 0.1]]])   # point slides back
    >>> planted_translation(foot).round(3).tolist()
    [[0.0, 0.0, -0.1], [0.1, 0.0, -0.1]]
    """
    contacts = np.asarray(contacts, dtype=float)
    frames = np.arange(contacts.shape[0])
    lowest = np.argmin(contacts[:, :, up], axis=1)                 # supporting point per frame
    step = np.zeros((contacts.shape[0], 3))
    # how far the previous frame's supporting point moved relative to the root
    step[1:] = contacts[frames[:-1], lowest[:-1]] - contacts[frames[1:], lowest[:-1]]
    translation = np.cumsum(step, axis=0)
    translation[:, up] = -contacts[frames, lowest, up]
    return translation
