"""Marker sets: the segment tree, three markers per segment, and virtual markers.

A marker set is a TOML file (DESIGN 3.1)::

    name = "example"

    [[segment]]
    name = "pelvis"                 # the root: no parent
    markers = ["SACR", "MASI", "LASI"]

    [[segment]]
    name = "l_thigh"
    parent = "pelvis"
    markers = ["LHJC", "LKNE", "LTHI"]
    axes = ["e3", "e2", "-e1"]      # optional, see below

    [[virtual]]                     # midpoint (mean) of two or more markers
    name = "MASI"
    type = "midpoint"
    markers = ["RASI", "LASI"]

    [[virtual]]                     # only when the trial has no marker called SACR
    name = "SACR"
    type = "midpoint"
    markers = ["RPSI", "LPSI"]
    fallback = true

    [[virtual]]                     # a fixed offset (metres) in a three-marker frame
    name = "LKNE_FRONT"
    type = "offset"
    markers = ["LKNE", "LANK", "LTIB"]
    offset = [0.0, 0.0, 0.05]

    [[virtual]]                     # hip joint centre regression
    name = "LHJC"
    type = "hip_joint_centre"
    method = "davis"                # davis | bell | harrington
    side = "left"
    markers = ["RASI", "LASI", "SACR"]
    ankle = "LANK"                  # davis: leg length estimated from ASIS-ankle distance
    # leg_length = 0.87             # davis: or given, metres
    marker_diameter = 0.014         # davis: metres

``markers`` of a segment are origin, axis point and plane point: per frame,
``e1 = unit(p2 - p1)``, ``e3 = unit(e1 x (p3 - p1))``, ``e2 = e3 x e1`` and the
segment's rotation is ``[e1 e2 e3]`` (columns), its origin ``p1``.  The optional
``axes`` (our extension of DESIGN 3.1) relabels those columns with a signed
permutation, so that segments whose markers naturally give a different frame
(a thigh whose exact axis is its long axis) can share one anatomical convention:
``axes = ["e3", "e2", "-e1"]`` makes the segment's x axis e3, its y axis e2 and
its z axis -e1.  The permutation must be a proper rotation (determinant +1).
The optional ``origin`` (also an extension) puts the segment's origin at another
marker than the first, e.g. a joint centre.

Virtual markers may use real markers and other virtual markers (in any order; a
cycle is an error).  A virtual marker replaces a recorded marker of the same name,
unless ``fallback = true``: it is then computed only when the trial has no marker
of that name (so one preset serves files with a sacral marker and files with two
posterior iliac spine markers).

Labels with a subject prefix (Vicon's ``"Matt:LASI"``) match the bare name when
exactly one label has it.

Hip joint centre regressions
----------------------------
All three work in the Plug-in Gait pelvis frame: origin ``O`` = midpoint of the
ASIS markers, ``y = unit(LASI - RASI)`` (left), ``x`` = the component of
``O - SACR`` orthogonal to ``y``, normalised (anterior), ``z = x × y`` (up).
Pelvis width ``PW = |LASI - RASI|`` and depth ``PD = |O - SACR|`` are the
medians over the trial (the pelvis is rigid; per-frame values would add noise).
The hip joint centre is ``O + x·X + y·Y + z·Z`` with ``Y`` positive for the left
hip and negated for the right one.

``davis`` (Davis, Ounpuu, Tyburski & Gage 1991, *Hum Mov Sci* 10:575-587; the
Vicon Plug-in Gait reference guide, section "Hip joint centre"), with leg length
``L`` and marker radius ``r``, lengths in millimetres::

    C  = 0.115 L - 15.3            (ASIS-trochanter distance to HJC, Davis)
    AT = 0.1288 L - 48.56          (ASIS-trochanter distance, Plug-in Gait)
    theta = 0.5 rad, beta = 0.314 rad
    X = C cos(theta) sin(beta) - (AT + r) cos(beta)
    Y = -(C sin(theta) - PW / 2)
    Z = -C cos(theta) cos(beta) - (AT + r) sin(beta)

``L`` is ``leg_length`` when given, else estimated per trial as the 95th
percentile of the distance from the hip's ASIS to the ``ankle`` marker of the
same side (on the eight Plug-in Gait walking trials of the biomechzoo study and
pyCGM's sample, within 1-6 % of the measured leg length; an error of 20 mm in
``L`` moves the centre by about 3 mm).

``bell`` (Bell, Pedersen & Brand 1990, *J Biomech* 23:617-621)::

    X = -0.19 PW,  Y = 0.36 PW,  Z = -0.30 PW

``harrington`` (Harrington, Zavatsky, Lawson, Yuan & Theologis 2007,
*J Biomech* 40:595-602, the width-and-depth regression), in millimetres::

    X = -0.24 PD - 9.9,  Y = 0.33 PW + 7.3,  Z = -0.30 PW - 10.9
"""
from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from mocap.errors import MocapError
from mocap.trial import Trial

#: Kinds of virtual markers.
VIRTUAL_TYPES = ("midpoint", "offset", "hip_joint_centre")
#: Hip joint centre regressions.
HJC_METHODS = ("davis", "bell", "harrington")
_AXIS_NAMES = {"e1": 0, "e2": 1, "e3": 2}


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
        axis; ``("e1", "e2", "e3")`` (the default) keeps DESIGN 3.1's frame.
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
        ``"midpoint"``, ``"offset"`` or ``"hip_joint_centre"``.
    markers : tuple of str
        Inputs: two or more for a midpoint; frame markers (origin, axis point,
        plane point) for an offset; RASI, LASI and SACR (or a stand-in) for a
        hip joint centre.
    fallback : bool
        Compute only when the trial has no marker of this name.
    offset : tuple of 3 float or None
        Offset in metres in the frame of ``markers`` (``"offset"`` only).
    method, side : str or None
        Regression and hip (``"left"``/``"right"``) (``"hip_joint_centre"`` only).
    leg_length : float or None
        Metres (davis); when None it is estimated from ``ankle``.
    ankle : str or None
        Ankle marker of the same side, to estimate the leg length (davis).
    marker_diameter : float
        Metres (davis), default 0.014.
    """

    name: str
    type: str
    markers: tuple[str, ...]
    fallback: bool = False
    offset: tuple[float, float, float] | None = None
    method: str | None = None
    side: str | None = None
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
        segment(s), which move rigidly with it (``labels`` as found in the trial)."""
        find = _LabelIndex(labels).find
        donors: dict[str, list[str]] = {}
        for segment in self.segments:
            present = [labels[i] for i in (find(name) for name in segment.markers)
                       if i is not None]
            for label in present:
                donors.setdefault(label, [])
                donors[label] += [d for d in present if d != label and d not in donors[label]]
        return donors

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

        for v in self.virtual:
            existing = index.find(v.name)
            if v.fallback and existing is not None:
                continue
            if any(index.find(m) is None for m in v.inputs):
                continue  # not needed by any segment (check_trial passed)
            value = _compute_virtual(v, get, trial)
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
        return Trial(labels, points, trial.rate, trial.units, trial.path, trial.format,
                     trial.analogs, trial.analog_labels, trial.analog_rate,
                     dict(trial.metadata))

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


def axes_matrix(axes: tuple[str, str, str] | list[str]) -> np.ndarray:
    """Signed permutation for a segment's ``axes`` entry, shape (3, 3).

    Column k of the result picks the signed column of ``[e1 e2 e3]`` that
    becomes the segment's k-th axis.
    """
    matrix = np.zeros((3, 3))
    for k, text in enumerate(axes):
        sign = -1.0 if text.startswith("-") else 1.0
        matrix[_AXIS_NAMES[text.lstrip("+-")], k] = sign
    return matrix


def frame_from_markers(p1: np.ndarray, p2: np.ndarray, p3: np.ndarray
                       ) -> np.ndarray:
    """Rotation of the DESIGN 3.1 frame of three markers, vectorised.

    Parameters
    ----------
    p1, p2, p3 : ndarray, shape (..., 3), metres
        Origin, axis point and plane point.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Columns e1, e2, e3; NaN where a marker is missing or the markers are
        (nearly) collinear or coincident.
    """
    p1, p2, p3 = (np.moveaxis(np.asarray(p, dtype=float), -1, 0) for p in (p1, p2, p3))
    return np.moveaxis(frame_components(p2 - p1, p3 - p1), (0, 1), (-2, -1))


def frame_components(axis: np.ndarray, plane: np.ndarray) -> np.ndarray:
    """Frames from component-major arrays (the fast path of frame_from_markers).

    Parameters
    ----------
    axis, plane : ndarray, shape (3, ...)
        ``p2 - p1`` and ``p3 - p1``; ``axis`` is overwritten (normalised).

    Returns
    -------
    ndarray, shape (3, 3, ...)
        ``out[i, j]`` is component i of axis j.
    """
    ax, ay, az = axis
    bx, by, bz = plane
    out = np.empty((3, 3) + ax.shape)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = ax * ax
        scale += ay * ay
        scale += az * az
        np.sqrt(scale, out=scale)
        np.divide(1.0, scale, out=scale)
        ax *= scale
        ay *= scale
        az *= scale
        nx, ny, nz = out[0, 2], out[1, 2], out[2, 2]
        np.multiply(ay, bz, out=nx)
        nx -= az * by
        np.multiply(az, bx, out=ny)
        ny -= ax * bz
        np.multiply(ax, by, out=nz)
        nz -= ay * bx
        length = nx * nx
        length += ny * ny
        length += nz * nz
        # collinear markers leave no plane: refuse rather than return noise
        plane_sq = bx * bx
        plane_sq += by * by
        plane_sq += bz * bz
        length[~(length > 1e-18 * plane_sq)] = np.nan
        np.sqrt(length, out=length)
        np.divide(1.0, length, out=length)
        nx *= length
        ny *= length
        nz *= length
        ax += 0.0 * nx                     # NaN for the whole frame, not half of it
        ay += 0.0 * nx
        az += 0.0 * nx
        out[0, 0], out[1, 0], out[2, 0] = ax, ay, az
        np.multiply(ny, az, out=out[0, 1])
        out[0, 1] -= nz * ay
        np.multiply(nz, ax, out=out[1, 1])
        out[1, 1] -= nx * az
        np.multiply(nx, ay, out=out[2, 1])
        out[2, 1] -= ny * ax
    return out


def _median_distance(a: np.ndarray, b: np.ndarray) -> float:
    d = np.linalg.norm(a - b, axis=-1)
    d = d[np.isfinite(d)]
    return float(np.median(d)) if d.size else float("nan")


def _compute_virtual(v: VirtualMarker, get, trial: Trial) -> np.ndarray:
    """Positions of one virtual marker, shape (frames, 3), metres."""
    inputs = [get(name) for name in v.markers]
    if v.type == "midpoint":
        return np.mean(np.stack(inputs), axis=0)
    if v.type == "offset":
        rotation = frame_from_markers(*inputs)
        return inputs[0] + np.einsum("fij,j->fi", rotation, np.asarray(v.offset))
    return _hip_joint_centre(v, *inputs, ankle=get(v.ankle) if v.ankle else None,
                             trial=trial)


def pelvis_frame(rasi: np.ndarray, lasi: np.ndarray, sacr: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Plug-in Gait pelvis frame, vectorised over frames.

    Parameters
    ----------
    rasi, lasi, sacr : ndarray, shape (frames, 3), metres
        Right and left ASIS and the sacrum (or the PSIS midpoint).

    Returns
    -------
    rotation : ndarray, shape (frames, 3, 3)
        Columns x (anterior), y (left), z (up).
    origin : ndarray, shape (frames, 3)
        Midpoint of the ASIS markers.
    """
    origin = 0.5 * (rasi + lasi)
    with np.errstate(invalid="ignore", divide="ignore"):
        y = lasi - rasi
        y = y / np.linalg.norm(y, axis=-1, keepdims=True)
        back = origin - sacr
        x = back - np.sum(back * y, axis=-1, keepdims=True) * y
        x = x / np.linalg.norm(x, axis=-1, keepdims=True)
        z = np.cross(x, y)
    return np.stack([x, y, z], axis=-1), origin


def hip_joint_centre_offset(method: str, side: str, pelvis_width: float,
                            pelvis_depth: float | None = None,
                            leg_length: float | None = None,
                            marker_diameter: float = 0.014) -> np.ndarray:
    """Hip joint centre in the Plug-in Gait pelvis frame, metres, shape (3,).

    Parameters
    ----------
    method : {"davis", "bell", "harrington"}
        Regression (formulas and sources in the module docstring).
    side : {"left", "right"}
    pelvis_width : float
        Inter-ASIS distance, metres.
    pelvis_depth : float, optional
        Mid-ASIS to sacrum (or PSIS midpoint) distance, metres (harrington).
    leg_length : float, optional
        Metres (davis).
    marker_diameter : float
        Metres (davis).

    Examples
    --------
    >>> hip_joint_centre_offset("bell", "left", 0.25).round(4)
    array([-0.0475,  0.09  , -0.075 ])
    """
    sign = 1.0 if side == "left" else -1.0
    if method == "bell":
        x, y, z = -0.19 * pelvis_width, 0.36 * pelvis_width, -0.30 * pelvis_width
    elif method == "harrington":
        pw, pd = pelvis_width * 1000.0, pelvis_depth * 1000.0
        x, y, z = (-0.24 * pd - 9.9) / 1000, (0.33 * pw + 7.3) / 1000, \
            (-0.30 * pw - 10.9) / 1000
    elif method == "davis":
        length = leg_length * 1000.0
        radius = marker_diameter * 1000.0 / 2.0
        c = 0.115 * length - 15.3
        asis_trochanter = 0.1288 * length - 48.56
        theta, beta = 0.5, 0.314
        x = c * np.cos(theta) * np.sin(beta) - (asis_trochanter + radius) * np.cos(beta)
        y = -(c * np.sin(theta) - pelvis_width * 1000.0 / 2.0)
        z = -c * np.cos(theta) * np.cos(beta) - (asis_trochanter + radius) * np.sin(beta)
        x, y, z = x / 1000, y / 1000, z / 1000
    else:
        raise ValueError(f"unknown hip joint centre method {method!r}")
    return np.array([x, sign * y, z])


def _hip_joint_centre(v: VirtualMarker, rasi, lasi, sacr, ankle, trial: Trial) -> np.ndarray:
    rotation, origin = pelvis_frame(rasi, lasi, sacr)
    width = _median_distance(lasi, rasi)
    depth = _median_distance(origin, sacr)
    leg_length = v.leg_length
    if v.method == "davis" and leg_length is None:
        asis = lasi if v.side == "left" else rasi
        d = np.linalg.norm(asis - ankle, axis=-1)
        d = d[np.isfinite(d)]
        leg_length = float(np.percentile(d, 95)) if d.size else float("nan")
    if not np.isfinite(width) or (v.method == "harrington" and not np.isfinite(depth)):
        return np.full_like(rasi, np.nan)
    if v.method == "davis" and not np.isfinite(leg_length):
        return np.full_like(rasi, np.nan)
    local = hip_joint_centre_offset(v.method, v.side, width, depth, leg_length,
                                    v.marker_diameter)
    return origin + np.einsum("fij,j->fi", rotation, local)


# --------------------------------------------------------------------------- loading

def preset_names() -> list[str]:
    """Names of the marker sets shipped with the package."""
    folder = resources.files("mocap.markersets") / "presets"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def load_markerset(name_or_path: str | os.PathLike) -> MarkerSet:
    """A shipped preset by name (``"plugingait-lower"``) or a TOML file.

    Raises
    ------
    MocapError
        Unknown preset, unreadable file, or an invalid marker set (the message
        names the file and the problem).
    """
    text_name = os.fspath(name_or_path)
    path = Path(text_name)
    if path.suffix == ".toml" and not path.exists() and path.parent == Path(".") \
            and path.stem in preset_names():
        text_name, path = path.stem, Path(path.stem)          # "plugingait-lower.toml"
    if not path.suffix and not path.exists():
        folder = resources.files("mocap.markersets") / "presets"
        candidate = folder / f"{text_name}.toml"
        if not candidate.is_file():
            raise MocapError(f"no marker set preset '{text_name}' (presets: "
                             f"{', '.join(preset_names())}; or give a .toml file)")
        return parse_markerset(candidate.read_text(encoding="utf-8"), str(candidate))
    if not path.is_file():
        raise MocapError("marker set file not found", path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise MocapError(f"cannot read marker set: {error}", path) from None
    return parse_markerset(text, str(path))


def parse_markerset(text: str, path: str | None = None) -> MarkerSet:
    """A MarkerSet from TOML text, validated (``path`` names it in errors)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise MocapError(f"not valid TOML: {error}", path) from None
    return markerset_from_dict(data, path)


def _fail(problem: str, path: str | None) -> MocapError:
    return MocapError(f"invalid marker set: {problem}", path)


def _string_list(value: Any, what: str, path: str | None) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
        raise _fail(f"{what} must be a list of marker names", path)
    return tuple(value)


def markerset_from_dict(data: dict, path: str | None = None) -> MarkerSet:
    """A validated MarkerSet from parsed TOML (see the module docstring)."""
    name = data.get("name", Path(path).stem if path else "markerset")
    if not isinstance(name, str):
        raise _fail("'name' must be a string", path)
    known = {"name", "segment", "virtual", "description"}
    unknown = set(data) - known
    if unknown:
        raise _fail(f"unknown top-level key(s) {', '.join(sorted(unknown))} "
                    f"(expected [[segment]], [[virtual]], name, description)", path)
    raw_segments = data.get("segment", [])
    if not isinstance(raw_segments, list) or not raw_segments:
        raise _fail("no [[segment]] tables", path)
    segments = [_parse_segment(i, raw, path) for i, raw in enumerate(raw_segments)]
    _check_names([s.name for s in segments], "segment", path)
    segments = _order_segments(segments, path)

    raw_virtual = data.get("virtual", [])
    if not isinstance(raw_virtual, list):
        raise _fail("'virtual' must be [[virtual]] tables", path)
    virtual = [_parse_virtual(i, raw, path) for i, raw in enumerate(raw_virtual)]
    _check_names([v.name for v in virtual], "virtual marker", path)
    virtual = _order_virtual(virtual, path)
    return MarkerSet(name=name, segments=segments, virtual=virtual, path=path)


def _check_names(names: list[str], what: str, path: str | None) -> None:
    seen: set[str] = set()
    for n in names:
        if n in seen:
            raise _fail(f"duplicate {what} name '{n}'", path)
        seen.add(n)


def _parse_segment(i: int, raw: Any, path: str | None) -> Segment:
    if not isinstance(raw, dict):
        raise _fail(f"segment #{i + 1} is not a table", path)
    name = raw.get("name")
    if not isinstance(name, str) or not name:
        raise _fail(f"segment #{i + 1} has no name", path)
    unknown = set(raw) - {"name", "parent", "markers", "axes", "origin", "description"}
    if unknown:
        raise _fail(f"segment '{name}': unknown key(s) {', '.join(sorted(unknown))}", path)
    parent = raw.get("parent")
    if parent is not None and (not isinstance(parent, str) or not parent):
        raise _fail(f"segment '{name}': 'parent' must be a segment name", path)
    markers = _string_list(raw.get("markers"), f"segment '{name}': 'markers'", path)
    if len(markers) != 3:
        raise _fail(f"segment '{name}' has {len(markers)} markers; exactly 3 are needed "
                    f"(origin, axis point, plane point)", path)
    if len(set(markers)) != 3:
        raise _fail(f"segment '{name}' uses a marker twice: {', '.join(markers)}", path)
    axes = raw.get("axes", ["e1", "e2", "e3"])
    if (not isinstance(axes, list) or len(axes) != 3
            or not all(isinstance(a, str) and a.lstrip("+-") in _AXIS_NAMES for a in axes)
            or sorted(a.lstrip("+-") for a in axes) != ["e1", "e2", "e3"]):
        raise _fail(f"segment '{name}': 'axes' must name e1, e2 and e3 once each, "
                    f"optionally with a sign (e.g. [\"e3\", \"e2\", \"-e1\"])", path)
    if np.linalg.det(axes_matrix(axes)) < 0:
        raise _fail(f"segment '{name}': axes {axes} make a left-handed frame; "
                    f"flip the sign of one axis", path)
    origin = raw.get("origin")
    if origin is not None and (not isinstance(origin, str) or not origin):
        raise _fail(f"segment '{name}': 'origin' must be a marker name", path)
    return Segment(name, parent, markers, tuple(axes), origin)


def _order_segments(segments: list[Segment], path: str | None) -> list[Segment]:
    """Check parents and cycles; return parents before children (stable)."""
    by_name = {s.name: s for s in segments}
    for s in segments:
        if s.parent is not None and s.parent not in by_name:
            raise _fail(f"segment '{s.name}' has unknown parent '{s.parent}'", path)
        if s.parent == s.name:
            raise _fail(f"segment '{s.name}' is its own parent", path)
    for s in segments:
        chain = [s.name]
        current = s
        while current.parent is not None:
            if current.parent in chain:
                cycle = chain[chain.index(current.parent):] + [current.parent]
                raise _fail(f"segment parents form a cycle: {' -> '.join(cycle)}", path)
            chain.append(current.parent)
            current = by_name[current.parent]
    ordered: list[Segment] = []
    placed: set[str] = set()
    while len(ordered) < len(segments):
        for s in segments:
            if s.name not in placed and (s.parent is None or s.parent in placed):
                ordered.append(s)
                placed.add(s.name)
    return ordered


def _parse_virtual(i: int, raw: Any, path: str | None) -> VirtualMarker:
    if not isinstance(raw, dict):
        raise _fail(f"virtual marker #{i + 1} is not a table", path)
    name = raw.get("name")
    if not isinstance(name, str) or not name:
        raise _fail(f"virtual marker #{i + 1} has no name", path)
    kind = raw.get("type")
    if kind not in VIRTUAL_TYPES:
        raise _fail(f"virtual marker '{name}': 'type' must be one of "
                    f"{', '.join(VIRTUAL_TYPES)}, not {kind!r}", path)
    allowed = {"name", "type", "markers", "fallback", "description"} | {
        "midpoint": set(), "offset": {"offset"},
        "hip_joint_centre": {"method", "side", "leg_length", "ankle", "marker_diameter"},
    }[kind]
    unknown = set(raw) - allowed
    if unknown:
        raise _fail(f"virtual marker '{name}' ({kind}): unknown key(s) "
                    f"{', '.join(sorted(unknown))}", path)
    markers = _string_list(raw.get("markers"), f"virtual marker '{name}': 'markers'", path)
    if name in markers:
        raise _fail(f"virtual marker '{name}' is computed from itself", path)
    fallback = raw.get("fallback", False)
    if not isinstance(fallback, bool):
        raise _fail(f"virtual marker '{name}': 'fallback' must be true or false", path)
    fields: dict[str, Any] = {}
    if kind == "midpoint" and len(markers) < 2:
        raise _fail(f"virtual marker '{name}': a midpoint needs 2 or more markers", path)
    if kind in ("offset", "hip_joint_centre") and len(markers) != 3:
        what = ("origin, axis point and plane point" if kind == "offset"
                else "RASI, LASI and SACR (or the PSIS midpoint)")
        raise _fail(f"virtual marker '{name}' ({kind}) has {len(markers)} markers; "
                    f"exactly 3 are needed ({what})", path)
    if kind == "offset":
        offset = raw.get("offset")
        if (not isinstance(offset, list) or len(offset) != 3
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                           and np.isfinite(x) for x in offset)):
            raise _fail(f"virtual marker '{name}': 'offset' must be 3 numbers (metres)", path)
        fields["offset"] = tuple(float(x) for x in offset)
    if kind == "hip_joint_centre":
        method = raw.get("method", "davis")
        if method not in HJC_METHODS:
            raise _fail(f"virtual marker '{name}': 'method' must be one of "
                        f"{', '.join(HJC_METHODS)}, not {method!r}", path)
        side = raw.get("side")
        if side not in ("left", "right"):
            raise _fail(f"virtual marker '{name}': 'side' must be \"left\" or \"right\"", path)
        fields.update(method=method, side=side)
        for key in ("leg_length", "marker_diameter"):
            if key in raw:
                value = raw[key]
                if (not isinstance(value, (int, float)) or isinstance(value, bool)
                        or not np.isfinite(value) or value < 0
                        or (key == "leg_length" and value == 0)):
                    raise _fail(f"virtual marker '{name}': '{key}' must be a positive "
                                f"number of metres", path)
                if key == "leg_length" and value > 3.0:
                    raise _fail(f"virtual marker '{name}': leg_length {value} looks like "
                                f"millimetres; give metres", path)
                fields[key] = float(value)
        if "ankle" in raw:
            if not isinstance(raw["ankle"], str) or not raw["ankle"]:
                raise _fail(f"virtual marker '{name}': 'ankle' must be a marker name", path)
            fields["ankle"] = raw["ankle"]
        if method == "davis" and "leg_length" not in fields and "ankle" not in fields:
            raise _fail(f"virtual marker '{name}': the davis regression needs "
                        f"'leg_length' (metres) or an 'ankle' marker to estimate it", path)
    return VirtualMarker(name=name, type=kind, markers=markers, fallback=fallback, **fields)


def _order_virtual(virtual: list[VirtualMarker], path: str | None) -> list[VirtualMarker]:
    """Inputs before dependants; a cycle among virtual markers is an error."""
    by_name = {v.name: v for v in virtual}
    ordered: list[VirtualMarker] = []
    state: dict[str, int] = {}  # 1 visiting, 2 done

    def visit(v: VirtualMarker, chain: list[str]) -> None:
        if state.get(v.name) == 2:
            return
        if state.get(v.name) == 1:
            cycle = chain[chain.index(v.name):] + [v.name]
            raise _fail(f"virtual markers form a cycle: {' -> '.join(cycle)}", path)
        state[v.name] = 1
        for item in v.inputs:
            # a fallback marker's own name may be recorded; a dependency on
            # it is still a dependency on the virtual definition
            if item in by_name:
                visit(by_name[item], chain + [v.name])
        state[v.name] = 2
        ordered.append(v)

    for v in virtual:
        visit(v, [])
    return ordered
