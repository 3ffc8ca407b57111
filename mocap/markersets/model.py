"""Marker sets: the segment tree, three markers per segment, and virtual markers.

:class:`MarkerSet` holds :class:`Segment` and :class:`VirtualMarker` objects as read from a
marker-set TOML file (``docs/formats/markerset-toml.md``; reading and validation in
:mod:`mocap.markersets.parse`, the virtual-marker computations in
:mod:`mocap.markersets.virtual`, the three-marker frame in :mod:`mocap.markersets.axes`).

Labels with a subject prefix (Vicon's ``"Matt:LASI"``) match the bare name when
exactly one label has it.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from mocap.errors import MocapError
from mocap.markersets.axes import axes_matrix
from mocap.markersets.virtual import virtual_positions
from mocap.trial import Trial


class MissingMarkerWarning(UserWarning):
    """A marker has no data: a fallback stands in for it, or segments stay empty."""


@dataclass(frozen=True)
class Segment:
    """One rigid segment of a marker set.

    Attributes
    ----------
    name : str
    parent : str or None
        Name of the parent segment; None for a root (angles relative to the lab).
    markers : tuple of 3 str
        Origin, axis point and plane point (real or virtual marker names).
    axes : tuple of 3 str
        Which signed column of ``[e1 e2 e3]`` becomes the segment's x, y and z
        axis; ``("e1", "e2", "e3")`` (the default) keeps ``docs/formats/markerset-toml.md``'s frame.
    origin : str or None
        Marker placed at the segment's origin when it is not ``markers[0]``
        (a joint centre, while the frame comes from other markers).
    """

    name: str
    parent: str | None
    markers: tuple[str, str, str]
    axes: tuple[str, str, str] = ("e1", "e2", "e3")
    origin: str | None = None

    @property
    def origin_marker(self) -> str:
        """The marker at the segment's origin."""
        return self.origin or self.markers[0]

    @property
    def required(self) -> tuple[str, ...]:
        """Every marker the segment needs."""
        return self.markers + ((self.origin,) if self.origin else ())

    @property
    def axes_matrix(self) -> np.ndarray:
        """Signed permutation P, shape (3, 3): segment frame = [e1 e2 e3] @ P."""
        return axes_matrix(self.axes)


@dataclass(frozen=True)
class VirtualMarker:
    """A marker computed from others (see the module docstring for each type).

    Attributes
    ----------
    name : str
    type : str
        ``"midpoint"``, ``"offset"``, ``"hip_joint_centre"`` or ``"joint_centre"``.
    markers : tuple of str
        Inputs: two or more for a midpoint; frame markers (origin, axis point,
        plane point) for an offset; RASI, LASI and SACR (or a stand-in) for a
        hip joint centre.
    fallback : bool
        Compute only when the trial has no marker of this name.
    offset : tuple of 3 float or None
        Offset in metres in the frame of ``markers`` (``"offset"`` only).
    method, side : str or None
        Regression (``"hip_joint_centre"`` only) and side (``"left"``/``"right"``).
    joint : str or None
        ``"knee"`` or ``"ankle"`` (``"joint_centre"`` only).
    leg_length : float or None
        Metres (davis); when None it is estimated from ``ankle``.
    ankle : str or None
        Ankle marker of the same side, to estimate the leg length (davis).
    marker_diameter : float
        Metres (davis; a joint centre when the trial stores no MarkerDiameter),
        default 0.014.
    """

    name: str
    type: str
    markers: tuple[str, ...]
    fallback: bool = False
    offset: tuple[float, float, float] | None = None
    method: str | None = None
    side: str | None = None
    joint: str | None = None
    leg_length: float | None = None
    ankle: str | None = None
    marker_diameter: float = 0.014

    @property
    def inputs(self) -> tuple[str, ...]:
        """Every marker this one is computed from."""
        return self.markers + ((self.ankle,) if self.ankle else ())


@dataclass
class MarkerSet:
    """A tree of segments, each defined by three markers, plus virtual markers.

    Attributes
    ----------
    name : str
    segments : list of Segment
        Parents before their children, otherwise in file order.
    virtual : list of VirtualMarker
        In dependency order (inputs before the markers computed from them).
    path : str or None
        File the set was read from.
    """

    name: str
    segments: list[Segment]
    virtual: list[VirtualMarker] = field(default_factory=list)
    path: str | None = None

    @property
    def segment_names(self) -> list[str]:
        """Segment names in marker-set order."""
        return [segment.name for segment in self.segments]

    @property
    def parent_index(self) -> list[int]:
        """Index of each segment's parent in ``segments``; -1 for a root."""
        names = self.segment_names
        return [-1 if s.parent is None else names.index(s.parent) for s in self.segments]

    @property
    def virtual_names(self) -> list[str]:
        """Names of the virtual markers."""
        return [v.name for v in self.virtual]

    @property
    def axes_matrices(self) -> np.ndarray:
        """Per-segment signed permutations, shape (segments, 3, 3)."""
        return np.stack([s.axes_matrix for s in self.segments]) if self.segments \
            else np.zeros((0, 3, 3))

    def missing_markers(self, labels: list[str]) -> list[str]:
        """Real markers the set needs that ``labels`` lacks, sorted.

        A marker is needed when a segment uses it, directly or through virtual
        markers; a fallback virtual marker needs its inputs only when ``labels``
        lacks its own name.
        """
        return self._requirements(labels)[1]

    def donors(self, labels: list[str]) -> dict[str, list[str]]:
        """For gap filling: each recorded marker → the other recorded markers of its
        own segment, which move rigidly with it (``labels`` as found in the trial).

        A marker's own segment is the first (parents first) that lists it among
        its three markers: a knee marker that also defines the shank's origin
        belongs to the thigh, so a fill never treats two segments across a
        bending joint as one body.
        """
        find = _LabelIndex(labels).find
        home: dict[str, str] = {}
        members: dict[str, list[str]] = {}
        for segment in self.segments:
            for i in (find(name) for name in segment.markers):
                if i is not None and labels[i] not in home:
                    home[labels[i]] = segment.name
                    members.setdefault(segment.name, []).append(labels[i])
        return {label: [d for d in members[seg] if d != label] for label, seg in home.items()}

    def unavailable_segments(self, labels: list[str]) -> list[str]:
        """Segments that cannot be computed from ``labels``: a marker they need
        is absent, or their parent is unavailable (angles are relative to it)."""
        out: list[str] = []
        for segment in self.segments:
            alone = MarkerSet(self.name, [Segment(segment.name, None, segment.markers,
                                                  segment.axes, segment.origin)],
                              self.virtual)
            if alone.missing_markers(labels) or segment.parent in out:
                out.append(segment.name)
        return out

    def pad_missing(self, trial: Trial) -> tuple[Trial, list[str], list[str]]:
        """The trial with an all-NaN column for every marker the set lacks.

        Returns the padded trial, the markers added and the segments that will
        be NaN because of them.  Raises MocapError (check_trial's message) when
        half the segments or more cannot be computed (the trial was captured
        with another marker set).
        """
        missing = self.missing_markers(trial.labels)
        if not missing:
            return trial, [], []
        empty = self.unavailable_segments(trial.labels)
        if 2 * len(empty) >= len(self.segments):
            self.check_trial(trial)
        points = np.concatenate([trial.points, np.full((trial.frames, len(missing), 3),
                                                       np.nan)], axis=1)
        padded = trial.with_markers(list(trial.labels) + missing, points)
        return padded, missing, empty

    def used_labels(self, labels: list[str]) -> list[str]:
        """The labels (of ``labels``, in their order) the set reads.

        Recorded markers the segments use directly or through virtual markers;
        handy to clean only what the analysis needs.
        """
        return [labels[i] for i in self._requirements(labels)[0]]

    def _requirements(self, labels: list[str]) -> tuple[list[int], list[str]]:
        """Columns of ``labels`` the set reads, and the names it lacks."""
        index = _LabelIndex(labels)
        virtual = {v.name: v for v in self.virtual}
        used: set[int] = set()
        missing: set[str] = set()
        seen: set[str] = set()

        def need(name: str) -> None:
            if name in seen:
                return
            seen.add(name)
            column = index.find(name)
            v = virtual.get(name)
            if v is None or (v.fallback and column is not None):
                if column is None:
                    missing.add(name)
                else:
                    used.add(column)
                if v is not None:     # keep what an empty recorded marker falls back on
                    used.update(c for c in (index.find(i) for i in v.inputs) if c is not None)
                return
            for item in v.inputs:
                need(item)

        for segment in self.segments:
            for name in segment.required:
                need(name)
        return sorted(used), sorted(missing)

    def check_trial(self, trial: Trial) -> None:
        """Raise MocapError listing every marker the trial lacks."""
        missing = self.missing_markers(trial.labels)
        if missing:
            raise MocapError(
                f"marker set '{self.name}' needs {len(missing)} marker(s) the trial lacks: "
                f"{', '.join(missing)} (the trial has {len(trial.labels)} markers"
                f"{': ' + ', '.join(trial.labels[:12]) + (' …' if len(trial.labels) > 12 else '') if trial.labels else ''})",
                trial.path)

    def apply_virtual(self, trial: Trial) -> Trial:
        """The trial with this set's virtual markers added as extra columns.

        Parameters
        ----------
        trial : Trial
            ``points`` (frames, markers, 3) metres, NaN where missing.

        Returns
        -------
        Trial
            A copy whose ``labels`` end with the computed virtual markers (a
            virtual marker replaces a recorded one of the same name in place,
            unless it is a fallback). Frames where an input is missing are NaN.

        Raises
        ------
        MocapError
            When the trial lacks markers the set needs (all of them listed).
        """
        self.check_trial(trial)
        if not self.virtual:
            return trial
        labels = list(trial.labels)
        replaced: dict[int, np.ndarray] = {}
        added: list[np.ndarray] = []
        index = _LabelIndex(labels)

        def get(name: str) -> np.ndarray:
            column = index.find(name)
            if column in replaced:
                return replaced[column]
            if column >= trial.points.shape[1]:
                return added[column - trial.points.shape[1]]
            return trial.points[:, column, :]

        by_name = {v.name: v for v in self.virtual}
        recorded_count = trial.points.shape[1]

        def sources(name: str) -> set[str]:
            """Recorded labels a (virtual) marker is computed from."""
            v = by_name.get(name)
            column = index.find(name)
            if v is None or (v.fallback and column is not None and column < recorded_count
                             and column not in replaced):
                return {labels[column]} if column is not None and column < recorded_count \
                    else set()
            return set().union(*(sources(item) for item in v.inputs))

        for v in self.virtual:
            existing = index.find(v.name)
            if v.fallback and existing is not None:
                # keyed on data, not on the label: an empty recorded marker falls back
                if existing >= recorded_count or \
                        np.isfinite(trial.points[:, existing]).all(axis=1).any():
                    continue
                if any(index.find(m) is None for m in v.inputs):
                    continue
                warnings.warn(f"{trial.path or 'trial'}: {labels[existing]} has no data; "
                              f"using the {v.type} of {', '.join(v.inputs)} instead",
                              MissingMarkerWarning, stacklevel=2)
                replaced[existing] = virtual_positions(v, get, trial)
                continue
            if any(index.find(m) is None for m in v.inputs):
                continue  # not needed by any segment (check_trial passed)
            keep = None
            if v.type == "hip_joint_centre" and trial.filled:
                from mocap.clean.gapfill import recorded_frames
                keep = [recorded_frames(trial, sources(i)) for i in v.inputs]
            value = virtual_positions(v, get, trial, keep)
            if existing is not None and labels[existing] == v.name:
                if existing < trial.points.shape[1]:
                    replaced[existing] = value
                else:
                    added[existing - trial.points.shape[1]] = value
            else:
                labels.append(v.name)
                added.append(value)
                index = _LabelIndex(labels)
        points = trial.points
        if replaced or added:
            points = np.concatenate([points] + [a[:, None, :] for a in added], axis=1) \
                if added else points.copy()
            for column, value in replaced.items():
                points[:, column, :] = value
        return trial.with_markers(labels, points)

    def marker_columns(self, labels: list[str]) -> np.ndarray:
        """Columns of each segment's markers in ``labels``, shape (segments, 4), int.

        Origin-, axis- and plane-point columns, then the origin marker's column
        (the same as the first unless the segment names an ``origin``).
        ``labels`` must already hold the virtual markers (see apply_virtual).
        """
        index = _LabelIndex(labels)
        out = np.empty((len(self.segments), 4), dtype=int)
        for i, segment in enumerate(self.segments):
            for j, name in enumerate(segment.markers + (segment.origin_marker,)):
                column = index.find(name)
                if column is None:
                    raise MocapError(f"marker set '{self.name}': no marker '{name}' for "
                                     f"segment '{segment.name}'", self.path)
                out[i, j] = column
        return out


class _LabelIndex:
    """Finds a marker by name, also behind a subject prefix (``"Matt:LASI"``)."""

    def __init__(self, labels: list[str]):
        self.exact = {}
        for i, label in enumerate(labels):
            self.exact.setdefault(label, i)
        bare: dict[str, list[int]] = {}
        for i, label in enumerate(labels):
            if ":" in label:
                bare.setdefault(label.rsplit(":", 1)[1], []).append(i)
        self.bare = {name: cols[0] for name, cols in bare.items() if len(cols) == 1}

    def find(self, name: str) -> int | None:
        if name in self.exact:
            return self.exact[name]
        return self.bare.get(name)

