"""Segment frames from three markers per segment, vectorised over frames.

``docs/formats/markerset-toml.md``: with markers ``(p1, p2, p3)`` = origin, axis point, plane point,

    e1 = unit(p2 - p1);  e3 = unit(e1 × (p3 - p1));  e2 = e3 × e1;  R = [e1 e2 e3]

(columns), origin ``p1``; a segment's optional ``axes`` relabel the columns
(``R @ P`` with a signed permutation ``P``) and its optional ``origin`` names
another marker for the origin (see :mod:`mocap.markersets`).
"""
from __future__ import annotations

from typing import Iterator

import numpy as np

from mocap.markersets import MarkerSet
from mocap.markersets.axes import frame_components
from mocap.trial import Trial

#: Frames per block: the arithmetic runs block by block so its temporaries stay
#: in the CPU cache (two to three times faster than whole-trial arrays at
#: 100 000 frames x 15 segments).
BLOCK_FRAMES = 1024


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
    >>> from mocap.markersets import load_markerset   # doctest: +SKIP
    >>> R, o = segment_frames(trial, load_markerset("plugingait-lower"))  # doctest: +SKIP
    >>> R.shape                                       # doctest: +SKIP
    (222, 7, 3, 3)
    """
    full = markerset.apply_virtual(trial)
    columns = markerset.marker_columns(full.labels)          # (segments, 4)
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
    frames, segments = points.shape[0], columns.shape[0]
    rotations = np.empty((frames, segments, 3, 3))
    origins = np.empty((frames, segments, 3))
    for block, components in iter_frame_blocks(points, columns, axes):
        rotations[block] = np.moveaxis(components, (0, 1), (2, 3))
        origin = points[block][:, columns[:, 3] if columns.shape[1] > 3 else columns[:, 0], :]
        origin[np.isnan(components[0, 0])] = np.nan
        origins[block] = origin
    return rotations, origins


def iter_frame_blocks(points: np.ndarray, columns: np.ndarray, axes: np.ndarray | None = None
                      ) -> Iterator[tuple[slice, np.ndarray]]:
    """Segment rotations block by block of frames, component-major.

    The fast path under frames_from_points and joint_angles: each block's
    arithmetic runs on contiguous (frames, segments) arrays small enough to
    stay in the CPU cache.

    Parameters
    ----------
    points, columns, axes
        As for frames_from_points.

    Yields
    ------
    block : slice
        The frames of this block.
    components : ndarray, shape (3, 3, block frames, segments)
        ``components[i, j]`` is lab component i of the segment's axis j (NaN
        where the frame is unknown).
    """
    columns = np.asarray(columns, dtype=int)
    permute = axes is not None and not np.array_equal(
        axes, np.broadcast_to(np.eye(3), axes.shape))
    if permute:
        # a signed permutation only reorders and negates columns: index, don't multiply
        source = np.abs(axes).argmax(axis=1)                 # (segments, 3): source column
        sign = axes[np.arange(len(axes))[:, None], source, np.arange(3)[None, :]]
        source_index = source.T[None, :, None, :]             # (1, 3, 1, segments)
        sign = sign.T[None, :, None, :]
    # a Python loop over blocks of frames (not over frames), see BLOCK_FRAMES
    for start in range(0, points.shape[0], BLOCK_FRAMES):
        block = slice(start, min(start + BLOCK_FRAMES, points.shape[0]))
        chunk = points[block]                                # (frames, markers, 3)
        p1 = chunk[:, columns[:, 0]]
        axis = np.moveaxis(chunk[:, columns[:, 1]] - p1, 2, 0)    # (3, frames, segments)
        plane = np.moveaxis(chunk[:, columns[:, 2]] - p1, 2, 0)
        out = frame_components(axis, plane)
        if permute:
            out = np.take_along_axis(out, np.broadcast_to(source_index, out.shape), axis=1)
            out *= sign
        yield block, out
