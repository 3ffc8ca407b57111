"""Cleaning marker trajectories: gap filling and zero-lag low-pass.

Gaps are filled from *donors* when some are given and seen throughout the gap (the
other markers of the same rigid segment: the filled marker keeps its distances to them,
so a long gap in a fast-turning segment keeps the segment's shape), otherwise by a cubic
spline through the marker's own samples.  With two donors one coordinate is left free
(the turn about the donors' axis); on request (``correlate``) it is predicted from the
other markers of the trial by a regression on its recorded frames, and only the
prediction's residual is interpolated across the gap.
Both never invent data where they cannot know it: gaps
longer than the maximum, or at the start or end of a trajectory (which would
need extrapolation), stay NaN and are reported; the filter runs separately on
each contiguous run of valid samples, so a gap never smears into its
neighbours.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mocap.errors import MocapError
from mocap.trial import Trial


@dataclass(frozen=True)
class Gap:
    """A run of missing frames of one marker.

    Attributes
    ----------
    label : str
    start : int
        First missing frame.
    length : int
        Number of missing frames.
    reason : str
        Why it was not filled (``"longer than N frames"``, ``"at the start"``,
        ``"at the end"``, ``"marker never seen"``), or ``"filled"``.
    method : str
        How a filled gap was filled: ``"spline"`` or ``"rigid <donor>,…"``.
    """

    label: str
    start: int
    length: int
    reason: str = "filled"
    method: str = ""


@dataclass
class GapReport:
    """What fill_gaps did.

    Attributes
    ----------
    max_gap_frames : int
        Longest gap that was filled.
    filled : list of Gap
    unfilled : list of Gap
        Gaps left NaN, with the reason.
    """

    max_gap_frames: int
    filled: list[Gap] = field(default_factory=list)
    unfilled: list[Gap] = field(default_factory=list)

    @property
    def unfilled_frames(self) -> int:
        """Marker-frames still missing."""
        return sum(g.length for g in self.unfilled)

    def summary(self) -> str:
        """One line per marker with unfilled gaps, after a count line."""
        lines = [f"filled {len(self.filled)} gap(s) of up to {self.max_gap_frames} frames; "
                 f"{len(self.unfilled)} gap(s) left missing ({self.unfilled_frames} "
                 f"marker-frames)"]
        by_label: dict[str, list[Gap]] = {}
        for gap in self.unfilled:
            by_label.setdefault(gap.label, []).append(gap)
        for label, gaps in by_label.items():
            parts = [f"frames {g.start}-{g.start + g.length - 1} ({g.reason})" for g in gaps]
            lines.append(f"  {label}: " + "; ".join(parts))
        return "\n".join(lines)


def _runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Starts and lengths of the runs of True in a 1-D boolean array."""
    padded = np.concatenate([[False], mask, [False]])
    edges = np.flatnonzero(np.diff(padded.astype(np.int8)))
    starts, ends = edges[0::2], edges[1::2]
    return starts, ends - starts


def _max_gap(trial: Trial, max_gap_frames: int | None, max_gap_seconds: float | None) -> int:
    if (max_gap_frames is None) == (max_gap_seconds is None):
        raise MocapError("give the longest gap to fill either in frames or in seconds "
                         "(not both)", trial.path)
    if max_gap_seconds is not None:
        if not np.isfinite(max_gap_seconds) or max_gap_seconds < 0:
            raise MocapError(f"the longest gap to fill must be >= 0 s, not {max_gap_seconds}",
                             trial.path)
        return int(np.floor(max_gap_seconds * trial.rate + 1e-9))
    if int(max_gap_frames) != max_gap_frames or max_gap_frames < 0:
        raise MocapError(f"the longest gap to fill must be a whole number of frames >= 0, "
                         f"not {max_gap_frames}", trial.path)
    return int(max_gap_frames)


def fill_gaps(trial: Trial, max_gap_frames: int | None = None,
              max_gap_seconds: float | None = None,
              donors: dict[str, list[str]] | None = None,
              only: list[str] | None = None,
              references: dict[str, np.ndarray] | None = None,
              correlate: bool = False, rehearse: bool = True) -> tuple[Trial, GapReport]:
    """Fill short gaps of every marker from donor markers or with a cubic spline.

    Parameters
    ----------
    trial : Trial
        ``points`` (frames, markers, 3) metres, NaN where missing (a frame is
        missing for a marker when any coordinate is NaN).
    max_gap_frames : int, optional
        Longest gap to fill, in frames.
    max_gap_seconds : float, optional
        Or in seconds (``floor(seconds × rate)`` frames).  Give exactly one.
    donors : dict of str to list of str, optional
        Markers on the same rigid body as each marker (``MarkerSet.donors``).
        A gap is filled from the donors seen throughout the gap and on both edges,
        keeping the marker rigid with them (see :func:`_rigid_fill`), unless
        (``rehearse``) the marker's own spline fills the same gap better where it
        can be rehearsed on recorded data next to it; otherwise by the spline.
    only : list of str, optional
        Fill only these labels (the others are left as they are, not reported).
    references : dict of str to ndarray (frames, 3), optional
        For a marker filled from two donors: a direction that turns with its
        segment about the donors' axis (a joint axis, say), from which the
        marker's angle about that axis is measured; the lab axis most
        orthogonal to the donors' axis otherwise.
    correlate : bool
        For a marker filled from two donors, predict its one free coordinate
        (its angle about the donors' axis) from the other markers seen
        throughout the gap, by a regression trained on the trial's recorded
        frames, and interpolate only the prediction's residual across the gap
        (:func:`_predicted_angle`); otherwise interpolate the angle itself.
        The marker stays rigid with its own donors either way.  Off by default:
        measured on Plug-in Gait walks only (:func:`mocap.clinical.fill_plugingait`
        turns it on for the limbs; docs/plugingait.md).
    rehearse : bool
        Let the marker's own spline replace the rigid fill when it fills the
        same gap better on recorded data next to it
        (:func:`_rigid_rehearses_better`); off, donors seen throughout the gap
        always fill it.

    Returns
    -------
    Trial
        A copy with interior gaps of at most the maximum length filled, by the
        donors or by ``scipy.interpolate.CubicSpline`` (not-a-knot) through all
        valid samples of the marker, per coordinate.
    GapReport
        The gaps filled and those left NaN: longer ones, those at the start or
        end (no extrapolation), and markers with fewer than 2 valid samples.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.sin(np.arange(100) / 10.0)
    >>> points = np.stack([x, 0 * x, 0 * x + 1], axis=1)[:, None, :]
    >>> points[40:45] = np.nan
    >>> filled, report = fill_gaps(Trial(["M"], points, 100.0), max_gap_seconds=0.1)
    >>> bool(np.isfinite(filled.points).all()), report.filled
    (True, [Gap(label='M', start=40, length=5, reason='filled', method='spline')])
    """
    limit = _max_gap(trial, max_gap_frames, max_gap_seconds)
    report = GapReport(limit)
    points = trial.points.copy()
    frames = trial.frames
    missing = ~np.isfinite(points).all(axis=2)                      # (frames, markers)
    points[missing] = np.nan
    all_frames = np.arange(frames)
    index = {label: i for i, label in enumerate(trial.labels)}
    donor_columns = {label: [index[d] for d in names if d in index and d != label]
                     for label, names in (donors or {}).items()}
    # a Python loop over markers (not frames): each marker has its own gaps
    wanted = None if only is None else set(only)
    for m in np.flatnonzero(missing.any(axis=0)):
        label = trial.labels[m]
        if wanted is not None and label not in wanted:
            continue
        starts, lengths = _runs(missing[:, m])
        valid = ~missing[:, m]
        if valid.sum() < 2:
            for s, n in zip(starts, lengths):
                report.unfilled.append(Gap(label, int(s), int(n),
                                           "marker never seen" if not valid.any()
                                           else "only one valid sample"))
            continue
        # deferred: scipy.interpolate costs ~0.2 s of start-up, and only gap filling needs it
        from scipy.interpolate import CubicSpline
        spline = CubicSpline(all_frames[valid], points[valid, m, :], axis=0)
        for s, n in zip(starts, lengths):
            s, n = int(s), int(n)
            if s == 0:
                report.unfilled.append(Gap(label, s, n, "at the start"))
            elif s + n == frames:
                report.unfilled.append(Gap(label, s, n, "at the end"))
            elif n > limit:
                report.unfilled.append(Gap(label, s, n, f"longer than {limit} frames"))
            else:
                guess = spline(all_frames[s:s + n])
                reference = (references or {}).get(label)
                columns = donor_columns.get(label, [])
                others = []
                if correlate:
                    span = missing[s - 1:s + n + 1]
                    others = [k for k in range(len(trial.labels))
                              if k != m and k not in columns and not span[:, k].any()]
                if columns and rehearse and not _rigid_rehearses_better(
                        points, missing, s, n, m, columns, reference, others):
                    columns = []
                used = _rigid_fill(points, missing, s, n, m, columns, guess, reference, others)
                if used:
                    names = ",".join(trial.labels[d] for d in used)
                    report.filled.append(Gap(label, s, n, method=f"rigid {names}"))
                else:
                    points[s:s + n, m] = guess
                    report.filled.append(Gap(label, s, n, method="spline"))
    out = trial.with_points(points)
    out.metadata["filled"] = filled_masks(trial, report)
    return out, report


def filled_masks(trial: Trial, report: GapReport) -> dict[str, np.ndarray]:
    """Per label, the frames a fill wrote (bool (frames,)), merged with earlier fills.

    Whole-trial estimates (leg length, pelvis width, joint-centre offsets) skip
    these frames, so a fill never changes them (``Trial.metadata["filled"]``).
    """
    masks = {label: np.array(mask, dtype=bool)
             for label, mask in (trial.metadata.get("filled") or {}).items()}
    for gap in report.filled:
        mask = masks.setdefault(gap.label, np.zeros(trial.frames, dtype=bool))
        mask[gap.start:gap.start + gap.length] = True
    return masks


def recorded_frames(trial: Trial, labels) -> np.ndarray:
    """Frames where none of ``labels`` was written by a gap fill, bool (frames,)."""
    masks = trial.metadata.get("filled") or {}
    keep = np.ones(trial.frames, dtype=bool)
    for label in labels:
        mask = masks.get(label)
        if mask is not None and len(mask) == trial.frames:
            keep &= ~np.asarray(mask, dtype=bool)
    return keep


def _rigid_fill(points: np.ndarray, missing: np.ndarray, start: int, length: int,
                marker: int, donors: list[int], guess: np.ndarray,
                reference: np.ndarray | None = None,
                predictors: list[int] | None = None) -> list[int]:
    """Fill ``points[start:start+length, marker]`` from donors on the same rigid body.

    Donors seen throughout the gap and on both edges keep their distances to the
    marker.  Three or more donors fix the marker's position (best-fit rigid
    transform, Kabsch, from each edge, blended across the gap).  Two leave it on
    a circle about their axis: its angle on that circle (from ``reference`` or
    a lab direction orthogonal to the axis) is predicted from ``predictors``
    (other markers seen throughout the gap, :func:`_predicted_angle`) with the
    prediction's residual interpolated by a cubic through the valid frames next
    to the gap, or without predictors the angle itself is interpolated so.
    One leaves it on a sphere about the donor: the direction
    from the donor is interpolated the same way.  Whatever the method, the fill
    is then corrected by the linear blend of its misfit at the two edge frames,
    so it meets the recorded trajectory at both ends of the gap.  ``guess`` (the
    marker's own spline, (gap, 3)) is unused now but kept for callers.  Returns
    the donors used (none: nothing filled).
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


def _rigid_rehearses_better(points: np.ndarray, missing: np.ndarray, start: int,
                            length: int, marker: int, donors: list[int],
                            reference: np.ndarray | None,
                            predictors: list[int] | None = None) -> bool:
    """Does the rigid fill beat the marker's spline on the same gap rehearsed nearby?

    The gap is replayed on recorded data just before and just after it (where
    the marker and its donors are seen); both methods fill the replayed gaps and
    the one with the smaller position error there is used for the real gap.
    Without room to rehearse, the rigid fill is used.  Only small windows of
    frames are copied.
    """
    errors = {"rigid": 0.0, "spline": 0.0}
    rehearsed = 0
    frames = len(points)
    for trial_start in (start - length - 2, start + length + 2):
        lo, hi = trial_start - 3 * length - 2, trial_start + 4 * length + 2
        if lo < 0 or hi > frames or trial_start < 1 or trial_start + length + 1 > frames:
            continue
        span = slice(trial_start - 1, trial_start + length + 1)
        if missing[span, marker].any() or missing[span][:, donors].any():
            continue
        window = points[lo:hi].copy()
        holes = missing[lo:hi].copy()
        local = trial_start - lo
        truth = window[local:local + length, marker].copy()
        holes[local:local + length, marker] = True
        window[local:local + length, marker] = np.nan
        seen = np.flatnonzero(~holes[:, marker])
        if len(seen) < 4:
            continue
        from scipy.interpolate import CubicSpline   # deferred: scipy's start-up, see fill_gaps
        spline = CubicSpline(seen, window[seen, marker], axis=0)(
            np.arange(local, local + length))
        if not _rigid_fill(window, holes, local, length, marker, donors, spline,
                           None if reference is None else reference[lo:hi], predictors):
            continue
        rigid = window[local:local + length, marker]
        errors["rigid"] += float(np.mean(np.sum((rigid - truth) ** 2, axis=1)))
        errors["spline"] += float(np.mean(np.sum((spline - truth) ** 2, axis=1)))
        rehearsed += 1
    return rehearsed == 0 or errors["rigid"] <= errors["spline"]


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
    """Two donors: keep the position along their axis and the radius about it;
    fill the angle about the axis (from ``reference`` (frames, 3), else a lab
    direction) across the gap.

    With ``predictors`` (other markers seen throughout ``frames``) and the
    trial's ``missing`` mask, the angle is predicted from them
    (:func:`_predicted_angle`) and only its residual at the recorded frames of
    ``window`` is interpolated across the gap; otherwise the angle itself is
    interpolated by a cubic through ``window``."""
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

    def angle_at(f):
        first, axis, u, v = cylinder(f)
        rel = points[f, marker] - first
        radial = rel - np.sum(rel * axis, axis=1, keepdims=True) * axis
        return np.arctan2(np.sum(radial * v, axis=1), np.sum(radial * u, axis=1))

    first, axis, u, v = cylinder(window)
    rel = points[window, marker] - first
    along = np.sum(rel * axis, axis=1)
    radial = rel - along[:, None] * axis
    radius = np.linalg.norm(radial, axis=1)
    angle = np.unwrap(angle_at(window))
    predicted = None
    if predictors and missing is not None:
        predicted = _predicted_angle(points, missing, marker, donors, predictors, frames,
                                     window, angle_at, cylinder, float(angle.mean()))
    if predicted is None:
        phi = _interpolate(window, angle, frames)
    else:
        on_window, in_gap = predicted
        residual = np.unwrap(angle - on_window)
        phi = in_gap + _interpolate(window, residual, frames)
    first, axis, u, v = cylinder(frames)
    return (first + along.mean() * axis
            + radius.mean() * (np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * v))


#: Frames on each side of a gap whose recorded data train the angle's prediction.
TRAINING_REACH = 1000
#: Ridge penalty of the prediction, per training frame (standardised features).
RIDGE = 1e-3


def _predicted_angle(points: np.ndarray, missing: np.ndarray, marker: int,
                     donors: list[int], predictors: list[int], frames: np.ndarray,
                     window: np.ndarray, angle_at, cylinder, centre: float
                     ) -> tuple[np.ndarray, np.ndarray] | None:
    """The marker's angle about its two donors' axis predicted from other markers.

    Two donors leave one unknown: the marker's turn about their axis (an axial
    rotation of its segment; a wand marker's wobble).  Other markers of the
    trial (the neighbouring segments) say much about it: a linear (ridge)
    regression of the angle on the directions from each donor to each predictor
    marker, in the cylinder's own axes (so the lab orientation does not enter),
    is fitted on the recorded frames within :data:`TRAINING_REACH` of the gap
    (every other gait cycle of a walk) and evaluated on ``frames``.  Returns
    the prediction at ``window`` and at ``frames``, or None when fewer than 30
    frames can train it.
    """
    lo = max(int(frames[0]) - TRAINING_REACH, 0)
    hi = min(int(frames[-1]) + TRAINING_REACH + 1, len(points))
    used = [marker] + list(donors) + list(predictors)
    train = lo + np.flatnonzero(~missing[lo:hi][:, used].any(axis=1))
    if len(train) < 30:
        return None

    def features(f):
        _, axis, u, v = cylinder(f)
        out = []
        for d in donors:
            to = points[f][:, predictors] - points[f, d][:, None, :]          # (f, k, 3)
            to /= np.maximum(np.linalg.norm(to, axis=2, keepdims=True), 1e-12)
            out += [np.einsum("fkc,fc->fk", to, basis) for basis in (axis, u, v)]
        return np.concatenate(out, axis=1)                                   # (f, 6k)

    x = features(train)
    # the angle on the branch nearest the window's mean (it spans far less than a turn)
    y = centre + np.angle(np.exp(1j * (angle_at(train) - centre)))
    coef, mean, scale, offset = _ridge(x, y)

    def predict(f):
        return ((features(f) - mean) / scale) @ coef + offset

    return predict(window), predict(frames)


def _ridge(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Ridge regression on standardised features: coefficients, mean, scale, offset."""
    mean, scale = x.mean(axis=0), x.std(axis=0) + 1e-9
    z = (x - mean) / scale
    coef = np.linalg.solve(z.T @ z + RIDGE * len(z) * np.eye(z.shape[1]),
                           z.T @ (y - y.mean()))
    return coef, mean, scale, float(y.mean())


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


def butterworth_sos(cutoff_hz: float, rate: float, order: int = 4,
                    path: str | None = None) -> np.ndarray:
    """Second-order sections of a Butterworth low-pass, validated.

    Raises
    ------
    MocapError
        ``cutoff_hz`` not in (0, rate / 2), or ``order`` not a positive integer.
    """
    nyquist = rate / 2.0
    if not np.isfinite(cutoff_hz) or cutoff_hz <= 0:
        raise MocapError(f"low-pass cutoff must be a positive frequency in Hz, not "
                         f"{cutoff_hz}", path)
    if cutoff_hz >= nyquist:
        raise MocapError(f"low-pass cutoff {cutoff_hz:g} Hz is not below the Nyquist "
                         f"frequency {nyquist:g} Hz (half the {rate:g} Hz sampling rate)", path)
    if int(order) != order or order < 1:
        raise MocapError(f"filter order must be a positive whole number, not {order}", path)
    # deferred: scipy.signal costs ~0.5 s of start-up, and only low-pass filtering needs it
    from scipy.signal import butter
    return butter(int(order), cutoff_hz, btype="lowpass", fs=rate, output="sos")


def lowpass(trial: Trial, cutoff_hz: float, order: int = 4, short_runs: str = "error"
            ) -> Trial:
    """Zero-lag Butterworth low-pass of every marker, per run of valid samples.

    A Butterworth filter of ``order`` is run forward and backward
    (``scipy.signal.sosfiltfilt``), so there is no phase lag and the magnitude
    response is ``|H(f)|²``: 1 in the pass band, 1/2 (-6 dB) at ``cutoff_hz``,
    falling by ``2 × 6 × order`` dB per octave above.

    Parameters
    ----------
    trial : Trial
    cutoff_hz : float
        Must be below the Nyquist frequency ``rate / 2``.
    order : int
        Order of the single-pass filter (default 4).
    short_runs : {"error", "keep", "drop"}
        What to do with a run of valid samples too short to filter (at most
        ``3 × (2 × sections + 1)`` frames, scipy's padding): raise MocapError
        (default), keep it unfiltered, or make it missing.

    Returns
    -------
    Trial
        A copy with filtered positions; missing samples stay NaN.

    Raises
    ------
    MocapError
        Cutoff at or above Nyquist, bad order, or a too-short run with
        ``short_runs="error"`` (the message names the marker and frames).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(1000) / 100.0
    >>> x = np.sin(2 * np.pi * t) + 0.1 * np.sin(2 * np.pi * 30 * t)   # 1 Hz + 30 Hz
    >>> trial = Trial(["M"], np.stack([x, 0 * x, 0 * x], axis=1)[:, None, :], 100.0)
    >>> smooth = lowpass(trial, cutoff_hz=6.0).points[:, 0, 0]
    >>> bool(np.abs(smooth - np.sin(2 * np.pi * t))[100:-100].max() < 0.01)
    True
    """
    if short_runs not in ("error", "keep", "drop"):
        raise ValueError(f"short_runs must be 'error', 'keep' or 'drop', not {short_runs!r}")
    # deferred: see butterworth_sos
    from scipy.signal import sosfiltfilt
    sos = butterworth_sos(cutoff_hz, trial.rate, order, trial.path)
    padlen = 3 * (2 * len(sos) + 1)
    points = trial.points.copy()
    valid = np.isfinite(points).all(axis=2)
    points[~valid] = np.nan
    complete = valid.all(axis=0)
    if complete.any() and trial.frames > padlen:
        # markers without gaps: one call over all of them
        points[:, complete, :] = sosfiltfilt(sos, points[:, complete, :], axis=0)
    # a Python loop over the other markers and their runs (not frames)
    for m in np.flatnonzero(~complete):
        starts, lengths = _runs(valid[:, m])
        for s, n in zip(starts, lengths):
            s, n = int(s), int(n)
            if n <= padlen:
                if short_runs == "error":
                    raise MocapError(
                        f"marker {trial.labels[m]}: only {n} valid frame(s) in a row at "
                        f"frames {s}-{s + n - 1}, too few for a zero-lag order-{order} "
                        f"filter (needs more than {padlen}); fill the gaps first or "
                        f"keep/drop short runs", trial.path)
                if short_runs == "drop":
                    points[s:s + n, m, :] = np.nan
                continue
            points[s:s + n, m, :] = sosfiltfilt(sos, points[s:s + n, m, :], axis=0)
    return trial.with_points(points)
