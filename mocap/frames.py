"""Segment frames from three markers per segment, vectorised over frames.

DESIGN 3.1: with markers ``(p1, p2, p3)`` = origin, axis point, plane point,

    e1 = unit(p2 - p1);  e3 = unit(e1 × (p3 - p1));  e2 = e3 × e1;  R = [e1 e2 e3]

(columns), origin ``p1``; a segment's optional ``axes`` relabel the columns
(``R @ P`` with a signed permutation ``P``, see :mod:`mocap.markerset`).
"""
from __future__ import annotations

import numpy as np

from mocap.markerset import MarkerSet, frame_from_markers
from mocap.trial import Trial


def segment_frames(trial: Trial, markerset: MarkerSet) -> tuple[np.ndarray, np.ndarray]:
    """Rotation and origin of every segment in every frame.

    Parameters
    ----------
    trial : Trial
        ``points`` (frames, markers, 3) metres, NaN where missing.  The marker
        set's virtual markers are computed here (see MarkerSet.apply_virtual).
    markerset : MarkerSet

    Returns
    -------
    rotations : ndarray, shape (frames, segments, 3, 3)
        Columns are the segment's x, y, z axes in lab coordinates; NaN in
        frames where one of the segment's markers is missing or its markers are
        collinear.
    origins : ndarray, shape (frames, segments, 3), metres
        NaN together with the rotation.

    Raises
    ------
    MocapError
        When the trial lacks markers the set needs (every one is listed).

    Examples
    --------
    >>> from mocap.markerset import load_markerset   # doctest: +SKIP
    >>> R, o = segment_frames(trial, load_markerset("plugingait-lower"))  # doctest: +SKIP
    >>> R.shape                                       # doctest: +SKIP
    (222, 7, 3, 3)
    """
    full = markerset.apply_virtual(trial)
    columns = markerset.marker_columns(full.labels)          # (segments, 3)
    return frames_from_points(full.points, columns, markerset.axes_matrices)


def frames_from_points(points: np.ndarray, columns: np.ndarray,
                       axes: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Segment frames straight from a marker array (no virtual markers).

    Parameters
    ----------
    points : ndarray, shape (frames, markers, 3), metres
    columns : ndarray of int, shape (segments, 3) or (segments, 4)
        Marker columns of each segment's origin, axis point and plane point,
        optionally followed by the column of the marker placed at the origin
        (default: the first).
    axes : ndarray, shape (segments, 3, 3), optional
        Signed permutations applied on the right (``R @ axes[s]``).

    Returns
    -------
    rotations : ndarray, shape (frames, segments, 3, 3)
    origins : ndarray, shape (frames, segments, 3)
    """
    columns = np.asarray(columns, dtype=int)
    p1 = points[:, columns[:, 0], :]                         # (frames, segments, 3)
    p2 = points[:, columns[:, 1], :]
    p3 = points[:, columns[:, 2], :]
    rotations = frame_from_markers(p1, p2, p3)
    if axes is not None and not _all_identity(axes):
        # a signed permutation only reorders and negates columns: index, don't multiply
        order = np.abs(axes).argmax(axis=1)                  # (segments, 3): source column
        sign = axes[np.arange(len(axes))[:, None], order, np.arange(3)[None, :]]
        rotations = np.take_along_axis(
            rotations, np.broadcast_to(order[None, :, None, :], rotations.shape), axis=3)
        rotations = rotations * sign[None, :, None, :]
    origins = points[:, columns[:, 3], :] if columns.shape[1] > 3 else p1.copy()
    origins[np.isnan(rotations).any(axis=(2, 3))] = np.nan
    return rotations, origins


def _all_identity(axes: np.ndarray) -> bool:
    return bool(np.array_equal(axes, np.broadcast_to(np.eye(3), axes.shape)))
