"""The :class:`Trial` container: marker trajectories of one capture."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from mocap.errors import MocapError


@dataclass
class Trial:
    """Marker trajectories of one capture.

    Attributes
    ----------
    labels : list of str
        Marker labels, in file order.
    points : ndarray, shape (frames, markers, 3), float
        Marker positions in metres; NaN where a marker is missing.
    rate : float
        Sampling rate of ``points`` in Hz.
    units : str
        Length unit as stored in the source file (``"mm"``, ``"cm"``, ``"m"`` or
        ``""`` when the file does not say); ``points`` are always metres.
    path : str or None
        File the trial was read from.
    format : str or None
        ``"c3d"``, ``"csv"``, ``"trc"`` …
    analogs : ndarray, shape (analog_frames, channels), optional
        Analog channels (force plates, EMG) in file units.
    analog_labels : list of str
    analog_rate : float or None
        Hz.
    metadata : dict
        Anything else worth keeping (the reader used, the manufacturer, the reader's
        ``warnings`` …); what every reader produces has a typed field below.

    first_frame : int
        Number of the first frame in the source file (C3D header, TRC Frame#), 1-based.
    start_time : float or None
        Time of the first frame on the source file's clock, seconds (TRC/CSV time column);
        None: ``(first_frame - 1) / rate``.
    frame_numbers, frame_times : ndarray, shape (frames,), or None
        A TRC file's Frame# and Time columns as read (kept when the trial is written again).
    events : list of dict
        Gait events of the file (C3D EVENT group): ``label``, ``context``, ``time`` (s
        from the trial's first frame), ``frame`` (0-based index into ``points``).
    parameters : dict
        The C3D parameter groups, ``group → name → value`` (force plates in
        ``FORCE_PLATFORM``, subject measurements in ``PROCESSING``); empty for other files.
    poses : SegmentPoses or None
        Segment poses of a markerless C3D file (ROTATION group,
        :class:`mocap.io.c3d.rotations.SegmentPoses`: ``labels``, ``rotations``
        (frames, segments, 3, 3), ``positions`` (frames, segments, 3) in metres).
    modelled : dict or None
        Model outputs a C3D stores as points (Vicon's angles, forces, moments, powers …),
        kept apart from the markers: ``labels``, ``kinds``, ``values`` (frames, outputs, 3)
        in the file's units.
    filled : dict or None
        Marker label → boolean mask (frames,) of the samples gap filling made up
        (:func:`mocap.clean.gapfill.fill_gaps`), so whole-trial estimates skip them.
    """

    labels: list[str]
    points: np.ndarray
    rate: float
    units: str = "m"
    path: str | None = None
    format: str | None = None
    analogs: np.ndarray | None = None
    analog_labels: list[str] = field(default_factory=list)
    analog_rate: float | None = None
    metadata: dict = field(default_factory=dict)
    first_frame: int = field(default=1, kw_only=True)
    start_time: float | None = field(default=None, kw_only=True)
    frame_numbers: np.ndarray | None = field(default=None, kw_only=True)
    frame_times: np.ndarray | None = field(default=None, kw_only=True)
    events: list[dict] = field(default_factory=list, kw_only=True)
    parameters: dict[str, dict[str, Any]] = field(default_factory=dict, kw_only=True)
    poses: Any = field(default=None, kw_only=True)
    modelled: dict | None = field(default=None, kw_only=True)
    filled: dict[str, np.ndarray] | None = field(default=None, kw_only=True)

    def __post_init__(self) -> None:
        self.labels = [str(label) for label in self.labels]
        self.points = np.asarray(self.points, dtype=float)
        if self.points.ndim != 3 or self.points.shape[2] != 3:
            raise ValueError(f"points must be (frames, markers, 3), got {self.points.shape}")
        if self.points.shape[1] != len(self.labels):
            raise ValueError(
                f"{len(self.labels)} labels for {self.points.shape[1]} markers in points")
        self.rate = float(self.rate)

    @property
    def frames(self) -> int:
        """Number of frames."""
        return int(self.points.shape[0])

    @property
    def duration(self) -> float:
        """Seconds from the first to the last frame."""
        return (self.frames - 1) / self.rate if self.frames > 1 and self.rate > 0 else 0.0

    @property
    def times(self) -> np.ndarray:
        """Time of each frame in seconds from the first frame, shape (frames,).

        A single frame is at 0 s whatever the rate; several frames without a rate (0, as a
        reader leaves it when the file gives none) have no times: MocapError.
        """
        if self.frames <= 1:
            return np.zeros(self.frames)
        if not self.rate > 0:
            raise MocapError(f"has no sampling rate ({self.rate:g} Hz), so the times of its "
                             f"{self.frames} frames are unknown", self.path)
        return np.arange(self.frames) / self.rate

    def time_base(self) -> tuple[np.ndarray, np.ndarray]:
        """Frame numbers and times of the frames as the source file numbered them.

        A trial read from a TRC file keeps its Frame# and Time columns
        (``frame_numbers``, ``frame_times``); a C3D trial starts at ``first_frame``
        with frame 1 at 0 s (the C3D convention). Other trials, or a trial whose frame count changed since it was
        read, count from frame ``first_frame`` (default 1) at ``start_time``
        (default: (first_frame − 1) / rate).

        Returns
        -------
        frame_numbers : ndarray, shape (frames,), int
        times : ndarray, shape (frames,), seconds
        """
        numbers, times = self.frame_numbers, self.frame_times
        if numbers is not None and times is not None and len(numbers) == self.frames \
                and len(times) == self.frames:
            return np.asarray(numbers, dtype=np.int64), np.asarray(times, dtype=float)
        first = int(self.first_frame or 1)
        start = self.start_time
        if start is None or not np.isfinite(start):
            start = (first - 1) / self.rate if self.rate > 0 else 0.0
        numbers = first + np.arange(self.frames, dtype=np.int64)
        return numbers, float(start) + self.times

    def index(self, label: str) -> int:
        """Column of marker ``label`` in ``points`` (KeyError if absent)."""
        try:
            return self.labels.index(label)
        except ValueError:
            raise KeyError(label) from None

    def marker(self, label: str) -> np.ndarray:
        """Trajectory of one marker, shape (frames, 3), metres."""
        return self.points[:, self.index(label), :]

    def missing_fraction(self) -> dict[str, float]:
        """Fraction of frames in which each marker is missing (label → 0..1)."""
        if self.frames == 0:
            return {label: 0.0 for label in self.labels}
        missing = np.isnan(self.points).any(axis=2).mean(axis=0)
        return {label: float(f) for label, f in zip(self.labels, missing)}

    def with_points(self, points: np.ndarray) -> "Trial":
        """A copy of this trial with other marker positions (same labels and rate)."""
        return self.with_markers(self.labels, points)

    def with_markers(self, labels: list[str], points: np.ndarray) -> "Trial":
        """A copy of this trial with other markers, keeping everything else.

        The one way to rebuild a trial: rate, units, path, format, the analog channels
        and a copy of ``metadata`` (events, force plates, subject measurements …) travel
        with it.

        Parameters
        ----------
        labels : list of str
        points : ndarray, shape (frames, len(labels), 3), metres
            The same frames as this trial.
        """
        points = np.asarray(points, dtype=float)
        if points.shape[:1] != self.points.shape[:1]:
            raise ValueError(f"points must keep the trial's {self.frames} frames, got "
                             f"{points.shape[0]}")
        return replace(self, labels=list(labels), points=points,
                       analog_labels=list(self.analog_labels), metadata=dict(self.metadata),
                       events=list(self.events),
                       filled=None if self.filled is None else dict(self.filled))

    def select(self, labels: list[str]) -> "Trial":
        """A copy holding only the markers ``labels`` (in that order), keeping everything
        else (:meth:`with_markers`); KeyError names a label the trial does not have.

        >>> trial = Trial(["A", "B"], np.zeros((2, 2, 3)), 100.0, analog_rate=1000.0)
        >>> picked = trial.select(["B"])
        >>> picked.labels, picked.points.shape, picked.analog_rate
        (['B'], (2, 1, 3), 1000.0)
        """
        columns = [self.index(label) for label in labels]
        return self.with_markers(labels, self.points[:, columns, :])

    def slice(self, start: int = 0, stop: int | None = None) -> "Trial":
        """A copy holding frames ``start:stop`` (0-based, as Python slices), keeping
        everything else in step: the analog samples of those frames, the events inside
        them (``frame`` and ``time`` re-counted from the new first frame), ``first_frame`` and
        ``start_time`` (so :meth:`time_base` gives each kept frame its old number and
        time), a TRC file's Frame# and Time columns, segment poses, model outputs and
        gap-filling masks.

        >>> trial = Trial(["A"], np.arange(12.0).reshape(4, 1, 3), 100.0, first_frame=11,
        ...               events=[{"label": "Foot Strike", "frame": 2, "time": 0.12}])
        >>> part = trial.slice(1, 3)
        >>> part.frames, part.first_frame, part.time_base()[1]
        (2, 12, array([0.11, 0.12]))
        >>> event = part.events[0]
        >>> event["frame"], event["time"]
        (1, 0.11)
        """
        begin, end, _ = slice(start, stop).indices(self.frames)
        end = max(end, begin)
        numbers, times = self.time_base()
        picked = slice(begin, end)
        analogs = self.analogs
        if analogs is not None and self.analog_rate and self.rate > 0 and self.frames:
            per_frame = analogs.shape[0] / self.frames
            analogs = analogs[int(round(begin * per_frame)):int(round(end * per_frame))].copy()
        shift = begin / self.rate if self.rate > 0 else 0.0
        events = [dict(event, frame=int(event["frame"]) - begin,
                       **({"time": float(event["time"]) - shift} if "time" in event else {}))
                  for event in self.events if begin <= int(event.get("frame", -1)) < end]
        poses = self.poses
        if poses is not None:
            poses = replace(poses, rotations=poses.rotations[picked],
                            positions=poses.positions[picked])
        modelled = self.modelled
        if modelled is not None:
            modelled = dict(modelled, values=np.asarray(modelled["values"])[picked])
        keep_columns = self.frame_numbers is not None and self.frame_times is not None \
            and len(self.frame_numbers) == self.frames
        return replace(
            self, points=self.points[picked].copy(), analogs=analogs,
            analog_labels=list(self.analog_labels), metadata=dict(self.metadata),
            events=events, poses=poses, modelled=modelled,
            first_frame=int(numbers[begin]) if end > begin else int(self.first_frame),
            start_time=float(times[begin]) if end > begin else self.start_time,
            frame_numbers=self.frame_numbers[picked].copy() if keep_columns else None,
            frame_times=self.frame_times[picked].copy() if keep_columns else None,
            filled=None if self.filled is None else
            {label: mask[picked].copy() for label, mask in self.filled.items()})


def runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Starts and lengths of the runs of True in a 1-D boolean array (frames,).

    >>> runs(np.array([True, True, False, True]))
    (array([0, 3]), array([2, 1]))
    """
    padded = np.concatenate([[False], mask, [False]])
    edges = np.flatnonzero(np.diff(padded.astype(np.int8)))
    starts, ends = edges[0::2], edges[1::2]
    return starts, ends - starts
