"""Cleaning marker trajectories: gap filling and zero-lag low-pass.

Gaps are filled from *donors* when some are given and seen throughout the gap (the
other markers of the same rigid segment: the filled marker keeps its distances to them,
so a long gap in a fast-turning segment keeps the segment's shape), otherwise by a cubic
spline through the marker's own samples.
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
              donors: dict[str, list[str]] | None = None) -> tuple[Trial, GapReport]:
    """Fill short gaps of every marker from a donor marker or with a cubic spline.

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
        keeping the marker rigid with them (see :func:`_rigid_fill`); otherwise by
        the spline.

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
    for m in np.flatnonzero(missing.any(axis=0)):
        label = trial.labels[m]
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
                used = _rigid_fill(points, missing, s, n, m, donor_columns.get(label, []), guess)
                if used:
                    names = ",".join(trial.labels[d] for d in used)
                    report.filled.append(Gap(label, s, n, method=f"rigid {names}"))
                else:
                    points[s:s + n, m] = guess
                    report.filled.append(Gap(label, s, n, method="spline"))
    return trial.with_points(points), report


def _rigid_fill(points: np.ndarray, missing: np.ndarray, start: int, length: int,
                marker: int, donors: list[int], guess: np.ndarray) -> list[int]:
    """Fill ``points[start:start+length, marker]`` from donors on the same rigid body.

    Donors seen throughout the gap and on both edges keep their distances to the
    marker (taken on the edges).  Three or more donors fix the marker's position
    (best-fit rigid transform, Kabsch, from each edge, blended across the gap); two
    leave it on a circle about their axis and one on a sphere about it, where the
    point nearest the spline ``guess`` (gap, 3) is taken.  Returns the donors used
    (none: nothing filled).
    """
    before, after = start - 1, start + length
    usable = [d for d in donors if not missing[before:after + 1, d].any()]
    if not usable:
        return []
    gap = slice(start, after)
    weight = (np.arange(1, length + 1) / (length + 1))[:, None]              # (gap, 1)
    edges = np.array([before, after])
    donor_edges = points[edges][:, usable]                                   # (2, k, 3)
    marker_edges = points[edges, marker]                                     # (2, 3)
    current = points[gap][:, usable]                                         # (gap, k, 3)
    if len(usable) >= 3:
        estimates = [_kabsch_place(donor_edges[e], marker_edges[e], current) for e in (0, 1)]
        points[gap, marker] = estimates[0] * (1 - weight) + estimates[1] * weight
        return usable
    radii = np.linalg.norm(marker_edges[:, None] - donor_edges, axis=2).mean(axis=0)   # (k,)
    first = current[:, 0]
    if len(usable) == 1:
        direction = guess - first
        points[gap, marker] = first + radii[0] * direction / np.maximum(
            np.linalg.norm(direction, axis=1, keepdims=True), 1e-12)
        return usable
    axis = current[:, 1] - first
    separation = np.maximum(np.linalg.norm(axis, axis=1, keepdims=True), 1e-12)
    axis = axis / separation
    along = (separation ** 2 + radii[0] ** 2 - radii[1] ** 2) / (2 * separation)   # (gap, 1)
    centre = first + along * axis
    radius = np.sqrt(np.maximum(radii[0] ** 2 - along ** 2, 0.0))
    offset = guess - centre
    offset -= np.sum(offset * axis, axis=1, keepdims=True) * axis
    points[gap, marker] = centre + radius * offset / np.maximum(
        np.linalg.norm(offset, axis=1, keepdims=True), 1e-12)
    return usable


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
