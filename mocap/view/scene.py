"""What a view shows, as plain arrays: marker and skeleton layers, force plates, estimated
ground reactions and joint-angle curves, all in one lab frame.

Everything here is numpy and the project's own readers' containers (:class:`~mocap.trial.Trial`,
:class:`~mocap.skeleton.Motion`, :class:`~mocap.rotations.angles.JointAngles`); turning it into a page
is :mod:`mocap.view.page`.

The lab of a view is Z up (X anterior, Y left: C3D and Vicon) as soon as one of its layers
is, otherwise Y up (BVH, ASF/AMC and OpenSim files). A Y-up motion shown in a Z-up lab is
turned by the project's one turn between the two (:data:`mocap.body.retarget.Z_UP_TO_Y_UP`),
so a motion built from a marker trial lands on that trial's markers; a Y-up marker file
(OpenSim TRC) by :data:`mocap.io.lab.Z_TO_Y_UP`, the turn ``--up y`` writes such files with.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mocap.body.retarget import Z_UP_TO_Y_UP
from mocap.errors import MocapError
from mocap.io.c3d.outputs import computed_positions
from mocap.io.lab import Z_TO_Y_UP
from mocap.markersets import MarkerSet, load_markerset, preset_names
from mocap.skeleton import Motion
from mocap.trial import Trial

#: Vertical force (N) under which a plate's arrow is hidden (its COP is undefined).
PLATE_THRESHOLD = 20.0


@dataclass
class Layer:
    """One moving point cloud of a view: a trial's markers or a motion's joints.

    Attributes
    ----------
    name : str
        Shown in the legend (the file name).
    kind : {"markers", "skeleton"}
    points : ndarray, shape (frames, points, 3), float, metres
        In the view's lab frame; NaN where a marker is missing (drawn as a gap).
    labels : list of str
        One per point (shown on hover).
    bones : ndarray, shape (bones, 2), int
        Pairs of point indices drawn as lines.
    rate : float, Hz
    up : {"z", "y"}
        The vertical axis of ``points``.
    virtual : ndarray, shape (points,), bool
        Points computed from others (a marker set's joint centres), drawn smaller.
    skeleton : str
        What the bones come from: a marker set's name, "hierarchy", or "" without bones.
    """

    name: str
    kind: str
    points: np.ndarray
    labels: list[str]
    bones: np.ndarray
    rate: float
    up: str
    virtual: np.ndarray | None = None
    skeleton: str = ""

    def __post_init__(self) -> None:
        self.points = np.asarray(self.points, dtype=float)
        self.bones = np.asarray(self.bones, dtype=int).reshape(-1, 2)
        if self.virtual is None:
            self.virtual = np.zeros(self.points.shape[1], bool)

    @property
    def frames(self) -> int:
        return int(self.points.shape[0])

    @property
    def duration(self) -> float:
        """Seconds from the first to the last frame."""
        return (self.frames - 1) / self.rate if self.frames > 1 else 0.0

    def turned(self, up: str) -> "Layer":
        """The layer in a lab whose vertical axis is ``up`` (the same layer if it is)."""
        if up == self.up:
            return self
        if (up, self.up) != ("z", "y"):
            raise ValueError("a view's lab is Z up or Y up; only Y-up layers are turned")
        # row vectors: z_up = turn.T @ y_up, i.e. points @ turn
        turn = Z_UP_TO_Y_UP if self.kind == "skeleton" else Z_TO_Y_UP
        return Layer(self.name, self.kind, self.points @ turn, self.labels, self.bones,
                     self.rate, up, self.virtual, self.skeleton)


@dataclass
class PlateTrack:
    """A force plate: its outline and its ground reaction at the centre of pressure.

    Attributes
    ----------
    name : str
    corners : ndarray, shape (4, 3), metres, lab frame
    force : ndarray, shape (frames, 3), N, lab frame (the reaction on the body)
    cop : ndarray, shape (frames, 3), metres; NaN while the plate is unloaded
    rate : float, Hz (the marker frames')
    """

    name: str
    corners: np.ndarray
    force: np.ndarray
    cop: np.ndarray
    rate: float

    def turned(self, up: str, was: str) -> "PlateTrack":
        """The plate in a lab whose vertical axis is ``up``, from its trial's ``was``
        (the turn of :meth:`Layer.turned` for marker files)."""
        if up == was:
            return self
        if (up, was) != ("z", "y"):
            raise ValueError("a view's lab is Z up or Y up; only Y-up plates are turned")
        return PlateTrack(self.name, self.corners @ Z_TO_Y_UP, self.force @ Z_TO_Y_UP,
                          self.cop @ Z_TO_Y_UP, self.rate)


@dataclass
class ForceTrack:
    """A ground reaction without a plate: the dynamics check's estimate.

    Attributes
    ----------
    name : str
    force : ndarray, shape (frames, 3), N, lab frame
    point : ndarray, shape (frames, 3), metres; NaN where unknown (then drawn under the body)
    rate : float, Hz
    """

    name: str
    force: np.ndarray
    point: np.ndarray
    rate: float


@dataclass
class Curves:
    """Joint-angle curves drawn below the scene, with a cursor at the current time.

    Attributes
    ----------
    times : ndarray, shape (samples,), seconds from the first frame
    columns : list of str
        ``<segment>.<axis>`` names.
    values : ndarray, shape (samples, columns), degrees; NaN where unknown (a gap)
    """

    times: np.ndarray
    columns: list[str]
    values: np.ndarray


@dataclass
class Scene:
    """Everything one view shows (see the module docstring for its lab frame)."""

    layers: list[Layer]
    plates: list[PlateTrack] = field(default_factory=list)
    forces: list[ForceTrack] = field(default_factory=list)
    curves: Curves | None = None
    title: str = ""
    notes: list[str] = field(default_factory=list)
    up: str = "z"


# ----------------------------------------------------------------------------------------
def detect_up(points: np.ndarray) -> str:
    """The vertical axis of a marker cloud, ``"z"`` or ``"y"``.

    A body is taller than it is wide or deep: the axis, of Y and Z, along which the markers
    of one frame spread furthest (the median over frames) is taken as up; Z when unknown.

    Parameters
    ----------
    points : ndarray, shape (frames, markers, 3), metres (NaN allowed)

    Examples
    --------
    >>> standing = np.array([[[0.0, 0.1, 0.0], [0.1, -0.1, 1.7], [0.0, 0.0, 1.0]]])
    >>> detect_up(standing), detect_up(standing[..., [0, 2, 1]])
    ('z', 'y')
    """
    finite = np.isfinite(points).all(axis=2)
    usable = finite.sum(axis=1) >= 3
    if not usable.any():
        return "z"
    cloud = np.where(finite[usable, :, None], points[usable], np.nan)
    spread = np.nanmedian(np.nanmax(cloud, axis=1) - np.nanmin(cloud, axis=1), axis=0)
    return "y" if spread[1] > 1.2 * spread[2] else "z"


def auto_markerset(labels: list[str]) -> MarkerSet | None:
    """The shipped marker set with the most segments whose markers ``labels`` all has."""
    found = [load_markerset(name) for name in preset_names()]
    usable = [m for m in found if not m.missing_markers(labels)]
    return max(usable, key=lambda m: len(m.segments)) if usable else None


def marker_bones(markerset: MarkerSet, labels: list[str]) -> np.ndarray:
    """Lines that draw a marker set's segments, shape (bones, 2), columns of ``labels``.

    Each segment is drawn from its origin marker to its axis and plane markers, and from its
    parent's origin to its own; ``labels`` must already hold the set's virtual markers
    (:meth:`MarkerSet.apply_virtual`).
    """
    columns = markerset.marker_columns(labels)                 # origin, axis, plane, origin
    pairs = [(c[0], c[1]) for c in columns] + [(c[0], c[2]) for c in columns]
    pairs += [(columns[parent, 3], columns[i, 3])
              for i, parent in enumerate(markerset.parent_index) if parent >= 0]
    bones = {tuple(sorted((int(a), int(b)))) for a, b in pairs if a != b}
    return np.array(sorted(bones), dtype=int).reshape(-1, 2)


def marker_layer(trial: Trial, markerset: MarkerSet | str | None = "auto",
                 name: str | None = None, up: str = "auto") -> Layer:
    """A trial's markers, with its marker set's segments as bones.

    Parameters
    ----------
    trial : Trial
        ``points`` (frames, markers, 3) metres, NaN where missing.
    markerset : MarkerSet, str or None
        A marker set or its name/path; ``"auto"`` takes the shipped set with the most
        segments that the trial's labels satisfy (none: markers only); None or ``"none"``:
        markers only.
    name : str, optional
        Legend name (default: the file name).
    up : {"auto", "z", "y"}
        The trial's vertical axis (``"auto"``: :func:`detect_up`).

    Returns
    -------
    Layer
        The recorded markers, then the set's virtual markers (flagged ``virtual``, as are
        a C3D file's computed positions: :func:`mocap.io.c3d.outputs.computed_positions`).
    """
    if isinstance(markerset, str):
        markerset = None if markerset == "none" else auto_markerset(trial.labels) \
            if markerset == "auto" else load_markerset(markerset)
    recorded = len(trial.labels)
    bones = np.zeros((0, 2), int)
    if markerset is not None:
        trial = markerset.apply_virtual(trial)
        bones = marker_bones(markerset, trial.labels)
    if up == "auto":
        up = str(trial.metadata.get("up") or detect_up(trial.points))
    # a model's outputs stored as points (axis points, joint centres, centre of mass) are
    # computed, not captured: drawn as the set's virtual markers are
    computed = computed_positions(trial.labels[:recorded]) if trial.format == "c3d" else {}
    virtual = (np.arange(len(trial.labels)) >= recorded) | \
        np.isin(np.arange(len(trial.labels)), [trial.labels.index(c) for c in computed])
    return Layer(name or _file_name(trial.path, "markers"), "markers", trial.points,
                 list(trial.labels), bones, _rate(trial.rate, trial.path), up, virtual,
                 markerset.name if markerset is not None else "")


def skeleton_layer(motion: Motion, name: str | None = None) -> Layer:
    """A motion's joints (segment origins, then end sites) and its hierarchy as bones
    (none from a root that is a transform node: :meth:`mocap.skeleton.Skeleton.transform_root`).

    Parameters
    ----------
    motion : Motion
        Y up, metres; positions by its forward kinematics (segment origins, then the
        end sites, as :meth:`~mocap.skeleton.Motion.all_points`).
    """
    skeleton = motion.skeleton
    world = motion.forward_kinematics()
    ends, end_points = motion.end_site_positions(world)
    points = np.concatenate([world[1], end_points], axis=1)
    # no line from a root that is a transform node (a BVH's joint_Root, metres away)
    skip = 0 if skeleton.transform_root() else -1
    bones = [(p, i) for i, p in enumerate(skeleton.parents) if p >= 0 and p != skip]
    bones += [(segment, skeleton.count + k) for k, segment in enumerate(ends)]
    labels = list(skeleton.names) + [f"{skeleton.names[s]} (end)" for s in ends]
    return Layer(name or _file_name(motion.metadata.get("source"), "motion"), "skeleton",
                 points, labels, np.array(bones, int), motion.rate, "y",
                 skeleton="hierarchy")


def plate_tracks(trial: Trial, threshold: float = PLATE_THRESHOLD) -> list[PlateTrack]:
    """The force plates of a C3D trial at its marker frames (empty without plates).

    Plates whose corners are not believable (:attr:`ForcePlate.problem`) are left out.
    """
    from mocap.io.c3d.forceplates import plate_forces    # deferred: only C3D files have plates
    if trial.analogs is None or not np.size(trial.analogs):
        return []
    tracks = []
    for part in plate_forces(trial, rate="marker", threshold=threshold):
        if part.plate.problem or part.samples == 0:
            continue
        force, cop = part.force[:trial.frames], part.cop[:trial.frames]
        tracks.append(PlateTrack(f"plate {part.plate.index + 1}", part.plate.corners,
                                 force, cop, trial.rate))
    return tracks


def check_forces(check: dict, source: str = "check") -> list[ForceTrack]:
    """The estimated ground reaction of a ``mocap check --json`` object (Y up): one track
    per foot when it has ``ground_reaction.feet``, else the total.

    ``ground_reaction`` must hold ``times_s`` and ``force_N`` (frames × 3, N); ``point_m``
    (frames × 3, metres, null where no foot pushes) places each arrow.
    """
    series = check.get("ground_reaction") if isinstance(check, dict) else None
    try:
        times = np.asarray(series["times_s"], dtype=float).reshape(-1)
        parts = series.get("feet") or {"total": series}
        tracks = [(name, _vectors(part["force_N"], len(times)),
                   _vectors(part.get("point_m"), len(times))) for name, part in parts.items()]
    except (TypeError, KeyError, ValueError, AttributeError):
        raise MocapError("is not the output of mocap check --json: it needs a "
                         "ground_reaction object with times_s and force_N (frames × 3)",
                         source) from None
    if len(times) < 1 or not np.isfinite(times).all():
        raise MocapError("ground_reaction.times_s holds no usable times", source)
    rate = 1.0 / float(np.median(np.diff(times))) if len(times) > 1 else 1.0
    if not (np.isfinite(rate) and rate > 0):
        raise MocapError("ground_reaction.times_s does not increase", source)
    return [ForceTrack(f"check {name}" if name != "total" else "check: estimated reaction",
                       force, point, rate) for name, force, point in tracks]


def _vectors(rows, frames: int) -> np.ndarray:
    """JSON rows of 3 numbers (null: unknown) as (frames, 3) floats; all NaN for None."""
    if rows is None:
        return np.full((frames, 3), np.nan)
    return np.asarray([[np.nan] * 3 if row is None else row for row in rows],
                      dtype=float).reshape(frames, 3)


def turn_force(track: ForceTrack, up: str) -> ForceTrack:
    """A check's Y-up force track in a lab with vertical axis ``up``."""
    if up == "y":
        return track
    return ForceTrack(track.name, track.force @ Z_UP_TO_Y_UP, track.point @ Z_UP_TO_Y_UP,
                      track.rate)


def angle_curves(angles, columns: list[str] | None = None, source=None) -> Curves:
    """Chosen columns of joint angles (:class:`~mocap.rotations.angles.JointAngles`).

    Parameters
    ----------
    angles : JointAngles
    columns : list of str, optional
        ``<segment>.<axis>`` names (default: the hip, knee and ankle flexions of clinical
        angles, else the first six columns).
    source : path, optional
        The file the angles were read from, for messages.
    """
    names = list(angles.columns[1:])
    flat = angles.values.reshape(angles.frames, -1)
    flexions = [c for c in names if c.endswith(("hip.flexion", "knee.flexion", "ankle.flexion"))]
    chosen = columns or (flexions or names)[:6]
    unknown = [c for c in chosen if c not in names]
    if unknown:
        raise MocapError(f"no angle column {', '.join(unknown)}; the file has "
                         + ", ".join(names[:12]) + (" …" if len(names) > 12 else ""), source)
    index = [names.index(c) for c in chosen]
    return Curves(np.asarray(angles.times, float), chosen, flat[:, index])


def scene_up(layers: list[Layer]) -> str:
    """Z up when any layer is (see the module docstring), else Y up."""
    return "z" if any(layer.up == "z" for layer in layers) or not layers else "y"


def _rate(rate: float, path) -> float:
    if not (np.isfinite(rate) and rate > 0):
        raise MocapError(f"has no usable frame rate ({rate:g} Hz) to play it at", path)
    return float(rate)


def _file_name(path, default: str) -> str:
    return Path(path).name if path else default
