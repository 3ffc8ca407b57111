"""Gait events and gait cycles: foot strikes and foot offs, cycles at 0–100 %.

Events come from the C3D EVENT group when the file has them (Vicon's
``Foot Strike`` / ``Foot Off`` with context ``Left`` / ``Right``); otherwise they
are detected from the heel and toe markers with the coordinate method of Zeni,
Richards & Higginson (2008, *Gait & Posture* 27:710-714): along the direction
of progression, relative to the pelvis (the sacrum or PSIS midpoint, else the
ASIS midpoint), a foot strike is a maximum of the heel's forward position and a
foot off a minimum of the toe's.

A side's cycle runs from one foot strike to the next; its angles are resampled
linearly to 101 samples, 0 % to 100 % (:func:`normalise_cycles`).
"""
from __future__ import annotations

import io
import os
import warnings
from dataclasses import dataclass

import numpy as np

from mocap.atomic import atomic_path
from mocap.clean.resample import resample
from mocap.errors import MocapError
from mocap.trial import Trial

#: Samples of a normalised cycle (0, 1, … 100 %).
CYCLE_SAMPLES = 101
FOOT_STRIKE = "Foot Strike"
FOOT_OFF = "Foot Off"


@dataclass(frozen=True)
class GaitEvent:
    """One event: ``side`` "l"/"r", ``label`` FOOT_STRIKE/FOOT_OFF, ``frame`` (0-based
    index into the trial), ``source`` "file" or "detected"."""

    side: str
    label: str
    frame: float
    source: str = "file"


def events_from_file(trial: Trial) -> list[GaitEvent]:
    """Foot strikes and foot offs of the C3D EVENT group, by frame."""
    out = []
    for event in trial.events:
        label = str(event.get("label", "")).strip().lower()
        context = str(event.get("context", "")).strip().lower()
        side = {"left": "l", "right": "r"}.get(context)
        kind = {"foot strike": FOOT_STRIKE, "foot off": FOOT_OFF}.get(label)
        if side and kind:
            out.append(GaitEvent(side, kind, float(event["frame"]), "file"))
    return sorted(out, key=lambda e: e.frame)


def _marker(trial: Trial, name: str) -> np.ndarray | None:
    from mocap.markersets.model import _LabelIndex

    column = _LabelIndex(trial.labels).find(name)
    if column is None:
        return None
    values = trial.points[:, column, :]
    return values if np.isfinite(values).all(axis=1).any() else None


def _pelvis_centre(trial: Trial) -> np.ndarray | None:
    for names in (("SACR",), ("LPSI", "RPSI"), ("LASI", "RASI")):
        parts = [_marker(trial, n) for n in names]
        if all(p is not None for p in parts):
            return np.mean(parts, axis=0)
    return None


def _local_maxima(x: np.ndarray) -> np.ndarray:
    """Indices of the local maxima of ``x``, shape (n,), as ``scipy.signal.find_peaks``
    finds them: a sample (or the middle, rounded down, of a flat run) higher than both
    neighbours; never the first or the last sample."""
    change = np.flatnonzero(np.diff(x) != 0)
    starts = np.concatenate(([0], change + 1))
    ends = np.concatenate((change, [len(x) - 1]))
    inner = (starts >= 1) & (ends <= len(x) - 2)
    starts, ends = starts[inner], ends[inner]
    peak = (x[starts - 1] < x[starts]) & (x[ends + 1] < x[ends])
    return (starts[peak] + ends[peak]) // 2


def _spaced(peaks: np.ndarray, heights: np.ndarray, distance: int) -> np.ndarray:
    """Which ``peaks`` (shape (n,)) stay when, highest first, each removes the peaks
    less than ``distance`` samples from it (``find_peaks``'s ``distance``)."""
    keep = np.ones(len(peaks), dtype=bool)
    for j in np.argsort(heights)[::-1]:          # over peaks, not frames
        if keep[j]:
            near = np.abs(peaks - peaks[j]) < distance
            near[j] = False
            keep &= ~near
    return keep


def _prominences(x: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """Each peak's height above the higher of its two bases, shape (n,): the lowest
    sample on each side before a sample higher than the peak (or the end), as
    ``scipy.signal.peak_prominences`` with no window."""
    out = np.empty(len(peaks))
    for k, p in enumerate(peaks):                # over peaks, not frames
        higher = np.flatnonzero(x > x[p])
        left = higher[higher < p]
        right = higher[higher > p]
        lo = left[-1] + 1 if len(left) else 0
        hi = right[0] if len(right) else len(x)
        out[k] = x[p] - max(x[lo:p + 1].min(), x[p:hi].min())
    return out


def find_peaks(x: np.ndarray, distance: int, prominence: float) -> np.ndarray:
    """``scipy.signal.find_peaks(x, distance=distance, prominence=prominence)[0]``
    in numpy: the same peaks (indices, shape (n,)) without importing scipy.signal,
    which costs ~0.5-1 s of CPU at start-up. ``x`` has no NaN; ``distance`` >= 1
    samples; ``prominence`` in the units of ``x``."""
    x = np.ascontiguousarray(x, dtype=float)
    peaks = _local_maxima(x)
    peaks = peaks[_spaced(peaks, x[peaks], int(np.ceil(distance)))]
    return peaks[prominence <= _prominences(x, peaks)]


def progression_signals(trial: Trial, min_cycle_seconds: float = 0.5,
                        min_travel: float = 0.5):
    """The signals :func:`detect_events` looks for peaks in.

    Yields
    ------
    (side, kind, filled, finite, distance, prominence) :
        side "l"/"r"; kind FOOT_STRIKE (heel) or FOOT_OFF (toe); ``filled`` shape
        (frames,), the marker's forward position relative to the pelvis, in metres,
        negated for the toe, gaps linearly filled; ``finite`` shape (frames,), where
        it was measured; ``distance`` in frames and ``prominence`` in metres, the
        peak conditions.
    """
    pelvis = _pelvis_centre(trial)
    if pelvis is None:
        return
    valid = np.isfinite(pelvis).all(axis=1)
    if valid.sum() < 2:
        return
    idx = np.flatnonzero(valid)
    travel = pelvis[idx[-1], :2] - pelvis[idx[0], :2]
    if np.hypot(*travel) < min_travel:
        return
    forward = np.zeros(3)
    forward[:2] = travel / np.hypot(*travel)
    distance = max(1, int(0.6 * min_cycle_seconds * trial.rate))
    for side in ("l", "r"):
        S = side.upper()
        for name, kind, sign in (("HEE", FOOT_STRIKE, 1.0), ("TOE", FOOT_OFF, -1.0)):
            marker = _marker(trial, S + name)
            if marker is None:
                continue
            signal = sign * ((marker - pelvis) @ forward)
            finite = np.isfinite(signal)
            if finite.sum() < 3:
                continue
            filled = np.interp(np.arange(len(signal)), np.flatnonzero(finite), signal[finite])
            spread = float(np.ptp(filled[finite]))
            yield side, kind, filled, finite, distance, 0.2 * spread


def detect_events(trial: Trial, min_cycle_seconds: float = 0.5, min_travel: float = 0.5
                  ) -> list[GaitEvent]:
    """Foot strikes and foot offs from heel and toe markers (Zeni et al. 2008).

    Parameters
    ----------
    trial : Trial
        Needs L/RHEE, L/RTOE and a pelvis (SACR, L/RPSI or L/RASI).
    min_cycle_seconds : float
        Two events of one kind on one side are at least ``0.6 ×`` this apart.
    min_travel : float
        Metres the pelvis must travel (first to last frame) for a walk; a
        static or turning-on-the-spot trial gives no events.

    Returns
    -------
    list of GaitEvent, by frame (``source="detected"``); a side without its
    heel or toe marker gives none.
    """
    out: list[GaitEvent] = []
    for side, kind, filled, finite, distance, prominence in progression_signals(
            trial, min_cycle_seconds, min_travel):
        peaks = find_peaks(filled, distance, prominence)
        # an extremum at a gap or at the trial's ends is not an event
        peaks = peaks[finite[peaks] & (peaks > 0) & (peaks < len(filled) - 1)]
        out += [GaitEvent(side, kind, float(p), "detected") for p in peaks]
    return sorted(out, key=lambda e: e.frame)


def gait_events(trial: Trial) -> list[GaitEvent]:
    """Per side, the file's events when they bound a cycle, else detected ones.

    A side whose EVENT group entries hold two or more foot strikes keeps them
    (and its foot offs); a side with fewer takes the events detected from its
    heel and toe markers (:func:`detect_events`), so a short walk with one
    labelled strike per side still gives its cycles.
    """
    from_file = events_from_file(trial)
    detected: list[GaitEvent] | None = None
    out: list[GaitEvent] = []
    for side in ("l", "r"):
        mine = [e for e in from_file if e.side == side]
        if sum(e.label == FOOT_STRIKE for e in mine) >= 2:
            out += mine
            continue
        if detected is None:
            detected = detect_events(trial)
        out += [e for e in detected if e.side == side]
    return sorted(out, key=lambda e: e.frame)


@dataclass
class Cycles:
    """Normalised gait cycles of one trial.

    Attributes
    ----------
    side : list of str
        Per cycle, "l" or "r".
    number : list of int
        1, 2, … per side.
    start, end : list of float
        Frames of the foot strikes that bound each cycle.
    foot_off : list of float
        Percent of the cycle at the side's foot off (NaN when none).
    values : ndarray, shape (cycles, 101, joints, 3)
        Degrees, the side's joints in ``joints`` order.
    joints : list of str
        Joint names without the side prefix (``pelvis``, ``hip``, …).
    axes : list of str
    """

    side: list
    number: list
    start: list
    end: list
    foot_off: list
    values: np.ndarray
    joints: list
    axes: list

    def to_dataframe(self):
        """The cycles as a tidy pandas DataFrame, as the cycles CSV: columns ``side``,
        ``cycle``, ``percent`` (0-100) then ``<joint>.<axis>`` in degrees, one row per
        sample of each cycle. Needs pandas (the ``tables`` extra)."""
        from mocap.errors import import_pandas

        pandas = import_pandas()
        count, samples = self.values.shape[:2]
        table = pandas.DataFrame(self.values.reshape(count * samples, -1),
                                 columns=[f"{j}.{a}" for j in self.joints for a in self.axes])
        table.insert(0, "percent", np.tile(np.linspace(0.0, 100.0, samples), count))
        table.insert(0, "cycle", np.repeat(np.asarray(self.number, dtype=int), samples))
        table.insert(0, "side", np.repeat(np.asarray(self.side, dtype=object), samples))
        return table


def normalise_cycles(angles, events: list[GaitEvent], samples: int = CYCLE_SAMPLES
                     ) -> Cycles:
    """Each side's cycles (strike to strike) resampled to ``samples`` points.

    Parameters
    ----------
    angles : JointAngles
        Clinical angles (segments ``l_hip`` …) or any ``<side>_<name>`` set.
    events : list of GaitEvent
    samples : int

    Returns
    -------
    Cycles
        Linear interpolation in frames (:func:`mocap.clean.resample.resample`); a
        sample next to a missing frame is NaN.
    """
    from mocap.rotations.angles import axis_names

    sides: list[str] = []
    numbers: list[int] = []
    starts: list[float] = []
    ends: list[float] = []
    offs: list[float] = []
    blocks = []
    joints = sorted({s.partition("_")[2] for s in angles.segments if s[:2] in ("l_", "r_")},
                    key=[s.partition("_")[2] for s in angles.segments].index)
    frames = np.arange(angles.frames, dtype=float)
    flat = angles.values.reshape(angles.frames, -1)
    for side in ("l", "r"):
        columns = [angles.segments.index(f"{side}_{j}") if f"{side}_{j}" in angles.segments
                   else None for j in joints]
        strikes = sorted(e.frame for e in events if e.side == side and e.label == FOOT_STRIKE)
        off_frames = np.array(sorted(e.frame for e in events
                                     if e.side == side and e.label == FOOT_OFF))
        for n, (a, b) in enumerate(zip(strikes[:-1], strikes[1:]), start=1):
            if b <= a:
                continue
            cycle = resample(frames, flat, a, b, samples).reshape(samples, -1, 3)
            block = np.full((samples, len(joints), 3), np.nan)
            for k, column in enumerate(columns):
                if column is not None:
                    block[:, k] = cycle[:, column]
            inside = off_frames[(off_frames > a) & (off_frames < b)]
            sides.append(side)
            numbers.append(n)
            starts.append(float(a))
            ends.append(float(b))
            offs.append(float(100.0 * (inside[0] - a) / (b - a)) if inside.size else np.nan)
            blocks.append(block)
    values = np.stack(blocks) if blocks else np.zeros((0, samples, len(joints), 3))
    axes = angles.axes or axis_names(angles.sequence)
    return Cycles(sides, numbers, starts, ends, offs, values, joints, list(axes))


def write_cycles_csv(cycles: Cycles, path: str | os.PathLike) -> None:
    """Tidy CSV: ``side,cycle,percent,<joint>.<axis>…`` one row per sample, all-or-nothing."""
    header = ["side", "cycle", "percent"] + [f"{j}.{a}" for j in cycles.joints
                                             for a in cycles.axes]
    count, samples = cycles.values.shape[:2]
    percent = np.linspace(0.0, 100.0, samples)
    buffer = io.StringIO()
    buffer.write(",".join(header) + "\n")
    for c in range(count):
        body = np.column_stack([percent, cycles.values[c].reshape(samples, -1)])
        text = io.StringIO()
        np.savetxt(text, body, fmt="%.6f", delimiter=",")
        prefix = f"{cycles.side[c]},{cycles.number[c]},"
        buffer.write("".join(prefix + line + "\n"
                             for line in text.getvalue().replace("nan", "").splitlines()))
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="") as handle:
            handle.write(buffer.getvalue())


def check_events(cycles: Cycles, path: str | None = None) -> None:
    """Raise MocapError when no side has a complete cycle."""
    if not cycles.side:
        raise MocapError("no complete gait cycle: fewer than two foot strikes on each side "
                         "(the file has no EVENT group and the heel markers gave none)", path)


#: Colours of the sides in the cycle plot (the gait-lab convention: left red, right green).
SIDE_COLOURS = {"l": "#c0392b", "r": "#1e8449"}


def cycles_figure(cycles: Cycles, title: str = ""):
    """Mean ± SD of each side's cycles, one panel per joint and plane.

    Rows are the joints, columns the planes; the shaded band is ± one standard
    deviation, the dotted vertical line the side's mean foot off.  Returns a
    matplotlib Figure (no pyplot state, nothing global changed).
    """
    from matplotlib.figure import Figure

    rows, columns = len(cycles.joints), len(cycles.axes)
    figure = Figure(figsize=(3.6 * columns, 2.3 * rows))
    axes = figure.subplots(rows, columns, sharex=True, squeeze=False)
    percent = np.linspace(0.0, 100.0, cycles.values.shape[1])
    sides = np.array(cycles.side)
    for side, colour in SIDE_COLOURS.items():
        chosen = cycles.values[sides == side] if sides.size else cycles.values[:0]
        if not len(chosen):
            continue
        with np.errstate(invalid="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)      # all-NaN columns
            mean = np.nanmean(chosen, axis=0)
            sd = np.nanstd(chosen, axis=0)
            off = np.nanmean(np.array(cycles.foot_off)[sides == side])
        for j in range(rows):
            for k in range(columns):
                ax = axes[j][k]
                ax.plot(percent, mean[:, j, k], color=colour, linewidth=1.4,
                        label=f"{'left' if side == 'l' else 'right'} (n={len(chosen)})")
                ax.fill_between(percent, mean[:, j, k] - sd[:, j, k],
                                mean[:, j, k] + sd[:, j, k], color=colour, alpha=0.2,
                                linewidth=0)
                if np.isfinite(off):        # named in the legend: it is not a curve
                    ax.axvline(off, color=colour, linestyle=":", linewidth=1,
                               label=f"{'left' if side == 'l' else 'right'} foot off "
                                     f"({off:.0f} %)")
    for j, joint in enumerate(cycles.joints):
        for k, axis_name in enumerate(cycles.axes):
            ax = axes[j][k]
            ax.set_title(f"{joint} {axis_name}", fontsize=9)
            ax.axhline(0.0, color="0.6", linewidth=0.6)
            ax.grid(alpha=0.3)
            if k == 0:
                ax.set_ylabel("degrees")
            ax.tick_params(labelbottom=True)      # % gait cycle ticks on every panel
    for ax in axes[-1]:
        ax.set_xlabel("% gait cycle")
        ax.set_xlim(0, 100)
    axes[0][0].legend(fontsize=7, loc="best")
    if title:
        figure.suptitle(title, fontsize=10)
    figure.tight_layout()
    return figure
