"""Force plates assigned to feet: which foot stood on which plate, and when.

A plate's loaded stretch (vertical force over the plate threshold, at marker frames:
:func:`mocap.io.c3d.forceplates.plate_forces` with ``rate="marker"``) is given to the
foot nearest its centre of pressure (:func:`nearest_foot`), and kept only when the
contact is clean (:func:`assign_plates`):

* the foot's heel and toe markers stay over the plate's outline on every loaded frame
  (a foot partly off the plate puts part of its load on the floor);
* the other foot is never planted on the plate while it is loaded (two feet on one plate
  cannot be told apart): its heel or toe marker slower than :data:`PLANTED_SPEED`, over
  the outline and within :data:`FOOT_MARKER_HEIGHT` of the surface (a foot swinging over
  the plate, or standing on the next stair step, is not on it).

Otherwise the stretch is refused with a note naming the plate, the foot and the
frames: that foot has no measured reaction on that stance.

Units: metres, newtons, frames (0-based indices into the trial).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocap.io.c3d.forceplates import PlateForces
from mocap.trial import runs

#: Horizontal speed (m/s) under which a foot marker counts as planted: a foot on the ground
#: moves a few cm/s (rolling over), a swinging one 1-5 m/s.
PLANTED_SPEED = 0.5
#: Height (m) above a plate's surface within which a foot marker is on it: heel and toe
#: markers of a foot standing on the ground sit 2-8 cm above the sole; a stair step
#: (15-20 cm) is above this, so the foot on the next step is not on the plate.
FOOT_MARKER_HEIGHT = 0.12
#: Loaded stretches shorter than this many frames are impacts or noise, not stances.
MIN_STANCE_FRAMES = 3


@dataclass(frozen=True)
class Stance:
    """One foot on one plate.

    Attributes
    ----------
    side : str
        ``"l"`` or ``"r"``.
    plate : int
        0-based plate number (FORCE_PLATFORM order).
    start, stop : int
        Loaded frames ``start … stop - 1``.
    clean : bool
        True when the plate measures that foot alone, wholly on it.
    reason : str
        Why not clean ("" when clean).
    """

    side: str
    plate: int
    start: int
    stop: int
    clean: bool
    reason: str = ""


def _inside(points: np.ndarray, plate: PlateForces, near: bool = False) -> np.ndarray:
    """Whether points (frames, 3) lie over the plate's outline, (frames,) bool (NaN: False);
    with ``near``, also at most :data:`FOOT_MARKER_HEIGHT` above its surface (and not
    more than half that below it).
    """
    info = plate.plate
    local = (points - info.centre) @ info.axes                   # plate axes, from its centre
    half = np.abs((info.corners - info.centre) @ info.axes).max(axis=0)
    # the plate's Z may point down (Vicon's) or up: up is where the reaction points
    up = 1.0 if np.nansum(plate.force @ info.axes[:, 2]) >= 0 else -1.0
    height = up * local[:, 2]
    with np.errstate(invalid="ignore"):
        over = (np.abs(local[:, 0]) <= half[0]) & (np.abs(local[:, 1]) <= half[1])
        if not near:
            return over
        return over & (height >= -FOOT_MARKER_HEIGHT / 2) & (height <= FOOT_MARKER_HEIGHT)


def _segment_distance(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance (frames,) from ``point`` to the segment a–b, each (frames, 3)."""
    p = point
    ab = b - a
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(np.sum((p - a) * ab, axis=1) / np.sum(ab * ab, axis=1), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)


def nearest_foot(cop: np.ndarray, feet: dict) -> str | None:
    """The side whose foot (heel–toe line) lies nearest the centre of pressure.

    Parameters
    ----------
    cop : ndarray (frames, 3), metres
        NaN where the plate is unloaded.
    feet : dict side -> (heel, toe)
        Marker arrays (frames, 3), metres.

    Returns
    -------
    str or None
        The side with the smallest median distance over the frames where
        both are known; None when no foot is.

    Examples
    --------
    >>> cop = np.array([[0.0, 0.1, 0.0]])
    >>> left = (np.array([[-0.1, 0.1, 0.0]]), np.array([[0.1, 0.1, 0.0]]))
    >>> right = (np.array([[-0.1, -0.1, 0.0]]), np.array([[0.1, -0.1, 0.0]]))
    >>> nearest_foot(cop, {"l": left, "r": right})
    'l'
    """
    best, side_best = np.inf, None
    for side, (heel, toe) in feet.items():
        d = _segment_distance(cop, heel, toe)
        d = d[np.isfinite(d)]
        if d.size and np.median(d) < best:
            best, side_best = float(np.median(d)), side
    return side_best


def _planted(heel: np.ndarray, toe: np.ndarray, rate: float) -> np.ndarray:
    """Frames (frames,) where the heel or the toe marker moves slower than PLANTED_SPEED."""
    def speed(x: np.ndarray) -> np.ndarray:
        if len(x) < 2:
            return np.zeros(len(x))
        return np.linalg.norm(np.gradient(x[:, :2], 1.0 / rate, axis=0), axis=1)
    with np.errstate(invalid="ignore"):
        return (speed(heel) < PLANTED_SPEED) | (speed(toe) < PLANTED_SPEED)


def assign_plates(plates: list[PlateForces], feet: dict) -> list[Stance]:
    """Each plate's loaded stretches, given to a foot, clean or not.

    Parameters
    ----------
    plates : list of PlateForces
        At marker frames (``plate_forces(trial, rate="marker")``: the feet's rate); plates whose
        geometry is not believable (``plate.problem``) are skipped.
    feet : dict side -> (heel, toe)
        Heel and toe marker arrays (frames, 3), metres, of ``"l"`` and ``"r"``.

    Returns
    -------
    list of Stance, by start frame.
    """
    out: list[Stance] = []
    rate = plates[0].rate if plates else 1.0
    planted = {side: _planted(heel, toe, rate) for side, (heel, toe) in feet.items()}
    for result in plates:
        if result.plate is None or result.plate.problem:
            continue
        loaded = np.isfinite(result.cop).all(axis=1)
        starts, lengths = runs(loaded)
        for start, length in zip(starts, lengths):
            if length < MIN_STANCE_FRAMES:
                continue
            stop = int(start + length)
            window = {side: (heel[start:stop], toe[start:stop])
                      for side, (heel, toe) in feet.items()}
            side = nearest_foot(result.cop[start:stop], window)
            if side is None:
                continue
            reason = ""
            heel, toe = window[side]
            if not (_inside(heel, result) & _inside(toe, result)).all():
                reason = "partly off the plate"
            for other, (o_heel, o_toe) in window.items():
                over = _inside(o_heel, result, True) | _inside(o_toe, result, True)
                if other != side and (over & planted[other][start:stop]).any():
                    reason = "both feet on the plate"
            out.append(Stance(side, result.plate.index, int(start), stop, not reason, reason))
    return sorted(out, key=lambda s: (s.start, s.plate))


__all__ = ["FOOT_MARKER_HEIGHT", "MIN_STANCE_FRAMES", "PLANTED_SPEED", "Stance", "assign_plates", "nearest_foot"]
