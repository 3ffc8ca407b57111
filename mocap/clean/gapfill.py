"""Gap filling of marker trajectories that stays inside its gap.

Gaps are filled from *donors* when some are given and seen throughout the gap (the
other markers of the same rigid segment: the filled marker keeps its distances to them,
so a long gap in a fast-turning segment keeps the segment's shape,
:mod:`mocap.clean.donorfill`), otherwise by a cubic spline through the marker's own samples.
Nothing is invented where it cannot be known: gaps longer than the maximum, or at the
start or end of a trajectory (which would need extrapolation), stay NaN and are
reported.  Only the gap's frames are written, and the frames a fill wrote are
recorded (``Trial.filled``) so that whole-trial estimates skip them.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mocap.clean.donorfill import rigid_fill
from mocap.errors import MocapError
from mocap.trial import Trial, runs


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
        keeping the marker rigid with them (see :func:`mocap.clean.donorfill.rigid_fill`), unless
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
        For a marker filled from two donors, predict its cylindrical
        coordinates about the donors' axis (its free turn, and its distances
        along and from the axis) from the other markers seen throughout the
        gap, by a regression trained on the trial's recorded frames, and
        interpolate only the prediction's residual across the gap
        (:func:`mocap.clean.donorfill._predicted_coordinates`); otherwise
        interpolate the coordinates themselves.  Off by default:
        measured on Plug-in Gait walks only (:func:`mocap.plugingait.clinical.fill_plugingait`
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
        starts, lengths = runs(missing[:, m])
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
                used = rigid_fill(points, missing, s, n, m, columns, reference, others)
                if used:
                    names = ",".join(trial.labels[d] for d in used)
                    report.filled.append(Gap(label, s, n, method=f"rigid {names}"))
                else:
                    points[s:s + n, m] = spline(all_frames[s:s + n])
                    report.filled.append(Gap(label, s, n, method="spline"))
    out = trial.with_points(points)
    out.filled = filled_masks(trial, report)
    return out, report


def filled_masks(trial: Trial, report: GapReport) -> dict[str, np.ndarray]:
    """Per label, the frames a fill wrote (bool (frames,)), merged with earlier fills.

    Whole-trial estimates (leg length, pelvis width, joint-centre offsets) skip
    these frames, so a fill never changes them (``Trial.filled``).
    """
    masks = {label: np.array(mask, dtype=bool)
             for label, mask in ((trial.filled or {})).items()}
    for gap in report.filled:
        mask = masks.setdefault(gap.label, np.zeros(trial.frames, dtype=bool))
        mask[gap.start:gap.start + gap.length] = True
    return masks


def recorded_frames(trial: Trial, labels) -> np.ndarray:
    """Frames where none of ``labels`` was written by a gap fill, bool (frames,)."""
    masks = (trial.filled or {})
    keep = np.ones(trial.frames, dtype=bool)
    for label in labels:
        mask = masks.get(label)
        if mask is not None and len(mask) == trial.frames:
            keep &= ~np.asarray(mask, dtype=bool)
    return keep


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
        if not rigid_fill(window, holes, local, length, marker, donors,
                           None if reference is None else reference[lo:hi], predictors):
            continue
        rigid = window[local:local + length, marker]
        errors["rigid"] += float(np.mean(np.sum((rigid - truth) ** 2, axis=1)))
        errors["spline"] += float(np.mean(np.sum((spline - truth) ** 2, axis=1)))
        rehearsed += 1
    return rehearsed == 0 or errors["rigid"] <= errors["spline"]


