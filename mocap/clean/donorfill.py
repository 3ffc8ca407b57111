"""Filling a marker's gap from the other markers of its rigid segment (its donors).

Three or more donors fix the marker's position; two leave one coordinate free, its
turn about the donors' axis (predicted from the other markers of the trial on
request); one leaves it on a sphere.  Every fill is corrected to meet the recorded
trajectory at both edges of the gap.  The driver is :func:`mocap.clean.gapfill.fill_gaps`.
"""
from __future__ import annotations

import numpy as np


def rigid_fill(points: np.ndarray, missing: np.ndarray, start: int, length: int,
                marker: int, donors: list[int],
                reference: np.ndarray | None = None,
                predictors: list[int] | None = None) -> list[int]:
    """Fill ``points[start:start+length, marker]`` from donors on the same rigid body.

    Donors seen throughout the gap and on both edges carry the marker.  Three or
    more donors fix the marker's position (best-fit rigid transform, Kabsch,
    from each edge, blended across the gap).  Two leave its turn about their
    axis free: its cylindrical coordinates about that axis (the angle from
    ``reference`` or a lab direction orthogonal to the axis) are predicted from
    ``predictors`` (other markers seen throughout the gap,
    :func:`_predicted_coordinates`) with the prediction's residual interpolated
    by a cubic through the valid frames next to the gap, or without predictors
    the coordinates themselves are interpolated so (:func:`_circle_place`).
    One leaves it on a sphere about the donor: the direction
    from the donor is interpolated the same way.  Whatever the method, the fill
    is then corrected by the linear blend of its misfit at the two edge frames,
    so it meets the recorded trajectory at both ends of the gap.  Returns the
    donors used (none: nothing filled).
    """
    before, after = start - 1, start + length
    usable = [d for d in donors if not missing[before:after + 1, d].any()]
    if not usable:
        return []
    span = slice(before, after + 1)                                          # gap + edges
    weight = (np.arange(0, length + 2) / (length + 1))[:, None]              # (gap+2, 1)
    edges = np.array([before, after])
    donor_edges = points[edges][:, usable]                                   # (2, k, 3)
    marker_edges = points[edges, marker]                                     # (2, 3)
    current = points[span][:, usable]                                        # (gap+2, k, 3)
    frames = np.arange(before, after + 1)
    if len(usable) >= 3:
        estimates = [_kabsch_place(donor_edges[e], marker_edges[e], current) for e in (0, 1)]
        placed = estimates[0] * (1 - weight) + estimates[1] * weight
    else:
        window = _edge_window(missing, marker, usable, start, length)
        if len(usable) == 1:
            placed = _sphere_place(points, marker, usable[0], window, frames)
        else:
            placed = _circle_place(points, marker, usable, window, frames, reference,
                                   missing, predictors)
    misfit = placed[[0, -1]] - marker_edges                                  # (2, 3)
    placed = placed - (misfit[0] * (1 - weight) + misfit[1] * weight)
    points[start:after, marker] = placed[1:-1]
    return usable



def _edge_window(missing: np.ndarray, marker: int, donors: list[int], start: int,
                 length: int, reach: int = 8) -> np.ndarray:
    """Up to ``reach`` frames on each side of a gap where the marker and donors are seen."""
    seen = ~missing[:, marker]
    for d in donors:
        seen &= ~missing[:, d]
    before = [f for f in range(start - 1, max(start - 1 - reach * 3, -1), -1) if seen[f]][:reach]
    after_first = start + length
    after = [f for f in range(after_first, min(after_first + reach * 3, len(seen)))
             if seen[f]][:reach]
    return np.array(sorted(before) + after)


def _interpolate(window: np.ndarray, values: np.ndarray, frames: np.ndarray) -> np.ndarray:
    """Cubic (or lower, with few samples) through ``values`` at ``window``, at ``frames``."""
    if len(window) >= 4:
        from scipy.interpolate import CubicSpline   # deferred: scipy's start-up, see fill_gaps
        return CubicSpline(window, values, axis=0)(frames)
    out = np.empty((len(frames),) + values.shape[1:])
    flat = values.reshape(len(window), -1)
    for j in range(flat.shape[1]):
        out.reshape(len(frames), -1)[:, j] = np.interp(frames, window, flat[:, j])
    return out


def _sphere_place(points: np.ndarray, marker: int, donor: int, window: np.ndarray,
                  frames: np.ndarray) -> np.ndarray:
    """One donor: interpolate the direction donor → marker, keep the distance."""
    offset = points[window, marker] - points[window, donor]                  # (w, 3)
    radius = np.linalg.norm(offset, axis=1).mean()
    direction = _interpolate(window, offset / np.linalg.norm(offset, axis=1, keepdims=True),
                             frames)
    direction /= np.maximum(np.linalg.norm(direction, axis=1, keepdims=True), 1e-12)
    return points[frames, donor] + radius * direction


def _circle_place(points: np.ndarray, marker: int, donors: list[int], window: np.ndarray,
                  frames: np.ndarray, reference: np.ndarray | None = None,
                  missing: np.ndarray | None = None, predictors: list[int] | None = None
                  ) -> np.ndarray:
    """Two donors: fill the marker's cylindrical coordinates about their axis.

    The coordinates are the position along the axis from the first donor (m), the
    distance from the axis (m) and the angle about it (radians, from
    ``reference`` (frames, 3) or a lab direction, projected normal to the axis).
    Two donors fix none of them (skin and wand move on the bone, and a joint
    centre donor is an estimate); the angle is the segment's free turn.

    With ``predictors`` (other markers seen throughout ``frames``) and the
    trial's ``missing`` mask, the three are predicted from those markers
    (:func:`_predicted_coordinates`) and only the prediction's residual at the
    recorded frames of ``window`` is interpolated across the gap (a cubic);
    otherwise the coordinates themselves are interpolated so.  Returns the
    marker's positions at ``frames`` (frames, 3)."""
    def unit_axis(f):
        axis = points[f, donors[1]] - points[f, donors[0]]
        return axis / np.maximum(np.linalg.norm(axis, axis=1, keepdims=True), 1e-12)

    # one lab reference for the whole gap: the lab axis most orthogonal to the
    # donors' axis (a reference that switched mid-gap would make the angle jump)
    lab = np.eye(3)[np.argmin(np.abs(unit_axis(window).mean(axis=0)))]

    def cylinder(f):
        first = points[f, donors[0]]
        axis = unit_axis(f)
        ref = lab if reference is None else reference[f]
        u = ref - np.sum(ref * axis, axis=1, keepdims=True) * axis
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        v = np.cross(axis, u)
        return first, axis, u, v

    def raw_coordinates(f):
        first, axis, u, v = cylinder(f)
        rel = points[f, marker] - first
        along = np.sum(rel * axis, axis=1)
        radial = rel - along[:, None] * axis
        return np.stack([along, np.linalg.norm(radial, axis=1),
                         np.arctan2(np.sum(radial * v, axis=1), np.sum(radial * u, axis=1))],
                        axis=1)                                               # (f, 3)

    # the angle on the branch nearest its mean on the window (it spans far less than a turn)
    centre = float(np.unwrap(raw_coordinates(window)[:, 2]).mean())

    def coordinates_at(f):
        out = raw_coordinates(f)
        out[:, 2] = centre + np.angle(np.exp(1j * (out[:, 2] - centre)))
        return out

    known = coordinates_at(window)                                           # (w, 3)
    predicted = None
    if predictors and missing is not None:
        # the average of a few ridge models (model averaging: less variance than any one)
        models = [_predicted_coordinates(points, missing, marker, donors, predictors, frames,
                                         window, coordinates_at, cylinder, ridge, lags)
                  for ridge, lags in ENSEMBLE]
        models = [m for m in models if m is not None]
        if models:
            predicted = tuple(np.mean([m[k] for m in models], axis=0) for k in (0, 1))
    if predicted is None:
        filled = _interpolate(window, known, frames)
    else:
        on_window, in_gap = predicted
        filled = in_gap + _interpolate(window, known - on_window, frames)
    along, radius, phi = filled.T
    first, axis, u, v = cylinder(frames)
    return (first + along[:, None] * axis
            + radius[:, None] * (np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * v))


#: Frames on each side of a gap whose recorded data train the coordinates' prediction.
TRAINING_REACH = 1000
#: The ridge models whose predictions of the coordinates are averaged: (penalty per
#: training frame, on standardised features; frames before each frame whose donor
#: accelerations enter, for a wand or skin marker swings behind its segment's
#: acceleration as a damped spring does; none for the last).  The spread of plausible
#: penalties and memories is averaged rather than one chosen: alone, each of the first
#: five fails 193 to 201 of the 408 limb-marker gaps of benchmarks/gapfill.py by more
#: than 1 degree (the first, the former only model, 197: 97 on the even-numbered walks,
#: 100 on the odd); the mean of the five fails 180 (88 and 92), with the sixth 169
#: (77 and 92), as their errors are partly independent.
ENSEMBLE = ((1e-3, (0, 4, 8)), (1e-3, (0, 2, 4, 6, 8, 10, 12)), (1e-2, (0, 4, 8)),
            (1e-3, (0, 4, 8, 12, 16)), (1e-4, (0, 4, 8)), (1e-3, ()))


def _predicted_coordinates(points: np.ndarray, missing: np.ndarray, marker: int,
                           donors: list[int], predictors: list[int], frames: np.ndarray,
                           window: np.ndarray, coordinates_at, cylinder,
                           ridge: float = 1e-3, lags: tuple[int, ...] = (0, 4, 8)
                           ) -> tuple[np.ndarray, np.ndarray] | None:
    """The marker's cylindrical coordinates about its two donors' axis, predicted.

    Two donors leave the marker's turn about their axis unknown (an axial
    rotation of its segment; a wand marker's wobble), and its distances along
    and from the axis vary too (skin on bone; a joint-centre donor is an
    estimate from other markers).  Other markers of the trial (the neighbouring
    segments) say much about all three: a linear (ridge) regression of the
    coordinates (``coordinates_at(f)`` -> (f, 3)) on the directions from each
    donor to each predictor marker, in the cylinder's own axes (so the lab
    orientation does not enter), the distances from each donor to each
    predictor, and the donors' accelerations (second differences, in the same
    axes) at each of ``lags`` frames before, is fitted (penalty ``ridge``) on the
    recorded frames within
    :data:`TRAINING_REACH` of the gap (every other gait cycle of a walk) and
    evaluated on ``frames``.  Returns the prediction at ``window`` (w, 3) and at
    ``frames`` (f, 3), or None when fewer than 30 frames can train it.
    """
    lo = max(int(frames[0]) - TRAINING_REACH, 0)
    hi = min(int(frames[-1]) + TRAINING_REACH + 1, len(points))
    used = [marker] + list(donors) + list(predictors)
    recorded = ~missing[:, used].any(axis=1)
    # the donors' accelerations where they and their lagged values are known; without
    # them on the gap and its window, the prediction goes without (as for the pelvis)
    acceleration = np.gradient(np.gradient(points[:, donors], axis=0), axis=0)  # (n, 2, 3)
    known = np.isfinite(acceleration).all(axis=(1, 2))
    lagged = known.copy()
    for lag in lags:
        lagged[lag:] &= known[:len(known) - lag]
        lagged[:lag] = False
    inertia = bool(lagged[frames].all() and lagged[window].all())
    if inertia:
        recorded &= lagged
    train = lo + np.flatnonzero(recorded[lo:hi])
    if len(train) < 30:
        return None

    def features(f):
        _, axis, u, v = cylinder(f)
        out = []
        for d in donors:
            to = points[f][:, predictors] - points[f, d][:, None, :]          # (f, k, 3)
            distance = np.linalg.norm(to, axis=2)                            # (f, k)
            to /= np.maximum(distance, 1e-12)[..., None]
            out += [np.einsum("fkc,fc->fk", to, basis) for basis in (axis, u, v)]
            out.append(distance)
        for lag in lags if inertia else ():
            out += [np.einsum("fdc,fc->fd", acceleration[f - lag], basis)
                    for basis in (axis, u, v)]                               # (f, 2) each
        return np.concatenate(out, axis=1)                                   # (f, 8k + 18)

    coef, mean, scale, offset = _ridge(features(train), coordinates_at(train), ridge)

    def predict(f):
        return ((features(f) - mean) / scale) @ coef + offset

    return predict(window), predict(frames)


def _ridge(x: np.ndarray, y: np.ndarray, penalty: float
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Ridge regression of ``y`` (n, t) on standardised ``x`` (n, d), ``penalty`` per
    row: coefficients
    (d, t), the features' mean and scale (d,), and the offset (t,)."""
    mean, scale = x.mean(axis=0), x.std(axis=0) + 1e-9
    z = (x - mean) / scale
    offset = y.mean(axis=0)
    coef = np.linalg.solve(z.T @ z + penalty * len(z) * np.eye(z.shape[1]), z.T @ (y - offset))
    return coef, mean, scale, offset


def _kabsch_place(reference: np.ndarray, marker: np.ndarray, current: np.ndarray) -> np.ndarray:
    """Carry ``marker`` (3,) with the rigid motion taking ``reference`` (k, 3) onto each
    frame of ``current`` (frames, k, 3); returns (frames, 3)."""
    ref_centre = reference.mean(axis=0)
    cur_centre = current.mean(axis=1)
    h = np.einsum("ki,fkj->fij", reference - ref_centre, current - cur_centre[:, None])
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(np.einsum("fij,fjk->fik", vt.transpose(0, 2, 1),
                                        u.transpose(0, 2, 1))))
    vt[:, 2, :] *= d[:, None]
    rotation = np.einsum("fij,fjk->fik", vt.transpose(0, 2, 1), u.transpose(0, 2, 1))
    return cur_centre + np.einsum("fij,j->fi", rotation, marker - ref_centre)
