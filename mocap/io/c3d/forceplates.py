"""Force plates of a C3D trial: ground reaction force, centre of pressure and free moment.

The C3D FORCE_PLATFORM group (C3D User Guide, "Force platforms") describes each plate:
TYPE, CORNERS (4 × 3, lab frame, POINT units), ORIGIN (plate frame), CHANNEL (1-based analog
channels) and, for type 4, CAL_MATRIX. The analog values come from the trial (the C3D reader
has already applied ANALOG:OFFSET, SCALE and GEN_SCALE, so they are in the channels' units).

Plate types (channels in order):

* 1 — Fx, Fy, Fz, COPx, COPy, Tz (COP in plate axes from the plate centre);
* 2 — Fx, Fy, Fz, Mx, My, Mz about the transducer origin (AMTI, Bertec);
* 3 — Kistler eight channels fx12, fx34, fy14, fy23, fz1, fz2, fz3, fz4; ORIGIN = (a, b, az0),
  sensor offsets and plate-surface depth (FPCOPPOLY corrections applied when present);
* 4 — as type 2 with the channels multiplied by CAL_MATRIX (6 × 6).

Plate axes follow ezc3d's construction (X = c1 − c2, Y from c1 − c4, Z = X × Y; c1 … c4
the corners in file order) and ORIGIN is taken pointing down into the plate (sign flipped
when its Z is positive), so the results equal ``ezc3d.c3d(path, extract_forceplat_data=True)``
(tested on every real file with plates). Moments are transferred to the plate's surface
centre; the centre of pressure is where the horizontal moment vanishes on the surface;
the free moment is the moment left about the centre of pressure (vertical in plate axes).

Units: newtons, metres, N·m. Moment channels are in ANALOG:UNITS when those name N·m or
N·mm, else force unit × POINT:UNITS (ezc3d's assumption). The force is the one the plate
reports, in the lab frame: on every plate in the corpus it points up during stance, i.e. the
reaction on the body.

Baseline: with ``baseline=True`` the channels' mean over FORCE_PLATFORM:ZERO (a 1-based
frame range; Vicon writes [1, 10] or [1, 0] for none) is taken off before the arithmetic;
when ZERO names no range, the mean over the plate's quietest 0.1 s (lowest |Fz|, when below
``threshold``) is used instead — a documented removal of an unloaded plate's offset. The
default keeps the channels as stored (ezc3d's behaviour).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocap.errors import MocapError

#: Channels per plate type.
CHANNELS = {1: 6, 2: 6, 3: 8, 4: 6}
#: Vertical force (N) below which a plate counts as unloaded: COP is undefined there.
THRESHOLD = 20.0

_LENGTH = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "dm": 0.1, "in": 0.0254, "inch": 0.0254}
_MOMENT = {"nm": 1.0, "n.m": 1.0, "n*m": 1.0, "n·m": 1.0, "nmm": 1e-3, "n.mm": 1e-3,
           "n*mm": 1e-3, "n·mm": 1e-3, "ntmm": 1e-3, "ntm": 1.0}


@dataclass
class ForcePlate:
    """One plate's description from FORCE_PLATFORM.

    Attributes
    ----------
    index : int
        0-based plate number.
    type : int
        1 … 4.
    corners : ndarray, shape (4, 3), metres, lab frame
    origin : ndarray, shape (3,), metres, plate frame (Z ≤ 0: down into the plate)
    channels : list of int
        0-based analog columns.
    labels : list of str
        Their analog labels.
    cal_matrix : ndarray, shape (6, 6) or None
    axes : ndarray, shape (3, 3)
        Columns: the plate's X, Y, Z axes in the lab frame.
    cop_poly : ndarray, shape (12,) or None
        Kistler COP correction (FPCOPPOLY), type 3 only.
    unit : float
        Metres per file length unit (POINT:UNITS).
    problem : str
        Why the plate's geometry is not believable (corners not a plate 5 cm – 10 m wide
        within 1 km of the origin), "" when it is; such plates are still computed as the
        file says, but left out of :func:`total_forces` and the dynamics check.
    """

    index: int
    type: int
    corners: np.ndarray
    origin: np.ndarray
    channels: list[int]
    labels: list[str]
    cal_matrix: np.ndarray | None
    axes: np.ndarray
    cop_poly: np.ndarray | None = None
    unit: float = 1e-3
    problem: str = ""

    @property
    def centre(self) -> np.ndarray:
        """Mean of the corners, metres (the surface centre)."""
        return self.corners.mean(axis=0)

    @property
    def size(self) -> tuple[float, float]:
        """Lengths of the plate's two sides, metres."""
        c = self.corners
        return float(np.linalg.norm(c[0] - c[1])), float(np.linalg.norm(c[0] - c[3]))


@dataclass
class PlateForces:
    """Ground reaction of one plate (or the total), sample by sample.

    Attributes
    ----------
    rate : float, Hz
    force : ndarray, shape (samples, 3), N, lab frame
    moment : ndarray, shape (samples, 3), N·m about the lab origin, lab frame
    cop : ndarray, shape (samples, 3), metres, lab frame (NaN while unloaded)
    free_moment : ndarray, shape (samples, 3), N·m about the COP, lab frame (0 while unloaded)
    plate : ForcePlate or None
        None for the total over all plates.
    """

    rate: float
    force: np.ndarray
    moment: np.ndarray
    cop: np.ndarray
    free_moment: np.ndarray
    plate: ForcePlate | None = None

    @property
    def samples(self) -> int:
        return int(self.force.shape[0])

    @property
    def times(self) -> np.ndarray:
        return np.arange(self.samples) / self.rate

    def to_dataframe(self):
        """The samples as a pandas DataFrame: index ``time`` (s), columns ``force_x``
        … ``force_z`` (N), ``moment_*`` (N·m about the lab origin), ``cop_*`` (m),
        ``free_moment_*`` (N·m), lab frame. Needs pandas (the ``tables`` extra)."""
        from mocap.errors import import_pandas

        pandas = import_pandas()
        parts = {"force": self.force, "moment": self.moment, "cop": self.cop,
                 "free_moment": self.free_moment}
        columns = {f"{name}_{axis}": values[:, i] for name, values in parts.items()
                   for i, axis in enumerate("xyz")}
        return pandas.DataFrame(columns, index=pandas.Index(self.times, name="time"))


def _param(group: dict, name: str):
    value = group.get(name)
    return value if isinstance(value, np.ndarray) and value.size else None


def _position_factor(trial) -> float:
    units = (trial.units or "").strip().lower().rstrip(".")
    if units in _LENGTH:
        return _LENGTH[units]
    return 1e-3                 # C3D's customary millimetres


def force_plates(trial) -> list[ForcePlate]:
    """The plates a C3D trial describes (empty when FORCE_PLATFORM:USED is 0 or absent).

    Raises
    ------
    MocapError
        A plate of an unsupported type, missing corners, channels or (type 4) calibration,
        or channels the file does not hold.
    """
    params = trial.parameters
    group = params.get("FORCE_PLATFORM", {})
    used = _param(group, "USED")
    count = int(used.reshape(-1)[0]) if used is not None else 0
    if count <= 0:
        return []
    path = trial.path
    types = _param(group, "TYPE")
    corners = _param(group, "CORNERS")
    origins = _param(group, "ORIGIN")
    channel = _param(group, "CHANNEL")
    if types is None or types.size < count:
        raise MocapError(f"FORCE_PLATFORM:TYPE does not describe the {count} plates", path)
    if corners is None or corners.size < 12 * count:
        raise MocapError(f"FORCE_PLATFORM:CORNERS does not describe the {count} plates", path)
    if channel is None or channel.ndim < 1:
        raise MocapError("FORCE_PLATFORM:CHANNEL is missing", path)
    channel = channel.reshape(channel.shape[0], -1)
    corners = corners.reshape(3, 4, -1)
    origins = np.zeros((3, count)) if origins is None else origins.reshape(3, -1)
    factor = _position_factor(trial)
    n_analog = 0 if trial.analogs is None else trial.analogs.shape[1]
    cal = _param(group, "CAL_MATRIX")
    poly = _param(group, "FPCOPPOLY")
    plates = []
    for p in range(count):
        kind = int(types.reshape(-1)[p])
        if kind not in CHANNELS:
            raise MocapError(f"force plate {p + 1} is of type {kind}; types 1-4 are supported",
                             path)
        n = CHANNELS[kind]
        if channel.shape[0] < n or channel.shape[1] <= p:
            raise MocapError(f"FORCE_PLATFORM:CHANNEL lists fewer than {n} channels for plate "
                             f"{p + 1} (type {kind})", path)
        columns = [int(c) - 1 for c in channel[:n, p]]
        if min(columns) < 0 or max(columns) >= n_analog:
            raise MocapError(f"force plate {p + 1} uses analog channels "
                             f"{', '.join(str(c + 1) for c in columns)} but the file holds "
                             f"{n_analog}", path)
        matrix = None
        if kind == 4:
            if cal is None or cal.ndim < 3 or cal.shape[2] <= p or cal.shape[0] < 6 \
                    or cal.shape[1] < 6:
                raise MocapError(f"force plate {p + 1} is of type 4 but FORCE_PLATFORM:"
                                 "CAL_MATRIX does not calibrate it", path)
            matrix = np.asarray(cal[:6, :6, p], dtype=float)
            if not np.isfinite(matrix).all() or not np.abs(matrix).sum() > 0:
                raise MocapError(f"force plate {p + 1}: CAL_MATRIX is empty or not finite", path)
        c = corners[:, :, p].T.astype(float) * factor            # (4, 3)
        if not np.isfinite(c).all():
            raise MocapError(f"force plate {p + 1}: CORNERS are not finite", path)
        x = c[0] - c[1]
        y = c[0] - c[3]
        z = np.cross(x, y)
        y = np.cross(z, x)
        norms = [np.linalg.norm(v) for v in (x, y, z)]
        if min(norms) <= 0:
            raise MocapError(f"force plate {p + 1}: CORNERS do not span a plate", path)
        axes = np.stack([x / norms[0], y / norms[1], z / norms[2]], axis=1)
        origin = origins[:, p].astype(float).copy() if origins.shape[1] > p else np.zeros(3)
        if kind == 1:
            origin[:2] = 0.0
        if origin[2] > 0:
            origin = -origin
        origin = origin * factor
        coefficients = None
        if kind == 3 and poly is not None and poly.size >= 12 * (p + 1):
            coefficients = poly.reshape(-1, order="F")[12 * p:12 * (p + 1)].astype(float)
        width, length = (float(np.linalg.norm(c[0] - c[k])) for k in (1, 3))
        problem = ""
        if not (0.05 <= min(width, length) and max(width, length) <= 10.0
                and np.abs(c).max() < 1000.0):
            problem = (f"corners span {width:.3g} × {length:.3g} m"
                       + (" far from the lab origin" if np.abs(c).max() >= 1000.0 else ""))
        plates.append(ForcePlate(p, kind, c, origin, columns,
                                 [trial.analog_labels[k] for k in columns], matrix, axes,
                                 coefficients, factor, problem))
    return plates


def _moment_factor(trial, plate: ForcePlate) -> float:
    """N·m per moment-channel unit."""
    if plate.type in (2, 4):
        labels = trial.parameters.get("ANALOG", {}).get("UNITS")
        if isinstance(labels, list) and len(labels) > plate.channels[3]:
            unit = str(labels[plate.channels[3]]).strip().lower().replace(" ", "")
            if unit in _MOMENT:
                return _MOMENT[unit]
    return _position_factor(trial)


def _plate_wrench(trial, plate: ForcePlate, data: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Force (N) and moment (N·m) about the plate's surface centre, plate axes, per sample."""
    if plate.type == 1:
        force = data[:, :3]
        cop = np.zeros_like(force)
        cop[:, :2] = data[:, 3:5] * _position_factor(trial)
        tz = np.zeros_like(force)
        tz[:, 2] = data[:, 5] * _position_factor(trial)
        # Moment about the centre from the force at the COP plus the free moment (as ezc3d).
        return force, np.cross(force, cop) - tz
    if plate.type == 3:
        ch = data
        a, b, az0 = plate.origin
        force = np.stack([ch[:, 0] + ch[:, 1], ch[:, 2] + ch[:, 3],
                          ch[:, 4] + ch[:, 5] + ch[:, 6] + ch[:, 7]], axis=1)
        moment = np.stack([b * (ch[:, 4] + ch[:, 5] - ch[:, 6] - ch[:, 7]),
                           a * (ch[:, 5] + ch[:, 6] - ch[:, 4] - ch[:, 7]),
                           b * (ch[:, 1] - ch[:, 0]) + a * (ch[:, 2] - ch[:, 3])], axis=1)
        moment = moment + np.cross(force, [0.0, 0.0, az0])
        return force, moment
    if plate.type == 4:
        data = data @ plate.cal_matrix.T
    force = data[:, :3]
    moment = data[:, 3:6] * _moment_factor(trial, plate)
    return force, moment + np.cross(force, plate.origin)


def _baseline(trial, plate: ForcePlate, data: np.ndarray, threshold: float) -> np.ndarray:
    """Channel offsets of an unloaded plate (see the module docstring)."""
    group = trial.parameters.get("FORCE_PLATFORM", {})
    zero = _param(group, "ZERO")
    per_frame = max(int(round((trial.analog_rate or trial.rate) / trial.rate)), 1)
    if zero is not None and zero.size >= 2:
        first, last = int(zero.reshape(-1)[0]), int(zero.reshape(-1)[1])
        if 1 <= first <= last:
            window = data[(first - 1) * per_frame:last * per_frame]
            if len(window):
                return window.mean(axis=0)
    force, _ = _plate_wrench(trial, plate, data)
    width = max(int(0.1 * (trial.analog_rate or trial.rate)), 1)
    if data.shape[0] < width:
        return np.zeros(data.shape[1])
    kernel = np.ones(width) / width
    level = np.convolve(np.abs(force[:, 2]), kernel, mode="valid")
    start = int(np.argmin(level))
    if level[start] >= threshold:
        return np.zeros(data.shape[1])          # never unloaded: keep as stored
    return data[start:start + width].mean(axis=0)


def _lab(plate: ForcePlate, force: np.ndarray, moment: np.ndarray, rate: float,
         threshold: float) -> PlateForces:
    """Lab-frame force, moment about the lab origin, COP and free moment of one plate."""
    axes, centre = plate.axes, plate.centre
    fz = force[:, 2]
    loaded = (np.abs(fz) >= threshold) & (fz != 0)       # no COP without a force
    safe = np.where(loaded, fz, 1.0)
    cop_p = np.stack([-moment[:, 1] / safe, moment[:, 0] / safe, np.zeros_like(fz)], axis=1)
    if plate.type == 3 and plate.cop_poly is not None:
        # Kistler's COP correction polynomial, in the file's length unit.
        k, unit = plate.cop_poly, plate.unit
        x, y = cop_p[:, 0] / unit, cop_p[:, 1] / unit
        cop_p[:, 0] -= unit * ((k[0] * y ** 4 + k[1] * y ** 2 + k[2]) * x ** 3
                               + (k[3] * y ** 4 + k[4] * y ** 2 + k[5]) * x)
        cop_p[:, 1] -= unit * ((k[6] * x ** 4 + k[7] * x ** 2 + k[8]) * y ** 3
                               + (k[9] * x ** 4 + k[10] * x ** 2 + k[11]) * y)
    free_p = moment - np.cross(cop_p, force)
    free_p[~loaded] = 0.0
    cop_p[~loaded] = np.nan
    force_w = force @ axes.T
    moment_c = moment @ axes.T
    moment_w = moment_c + np.cross(centre, force_w)           # about the lab origin
    return PlateForces(rate, force_w, moment_w, cop_p @ axes.T + centre, free_p @ axes.T, plate)


def plate_forces(trial, rate: str = "analog", baseline: bool = False,
                 threshold: float = THRESHOLD) -> list[PlateForces]:
    """Ground reaction of every plate of a trial.

    Parameters
    ----------
    trial : Trial
        Read from a C3D file (its ``parameters`` and analogs).
    rate : {"analog", "marker"}
        Keep the analog samples, or resample to the marker frames (a centred moving average
        over one marker frame, then the sample at each frame's time; the COP and free moment
        are computed from the resampled force and moment).
    baseline : bool
        Take off the unloaded offset of each channel (module docstring).
    threshold : float, N
        Vertical force under which the COP is undefined (NaN) and the free moment 0.

    Returns
    -------
    list of PlateForces
        One per plate, in FORCE_PLATFORM order (empty without plates).

    Raises
    ------
    MocapError
        See :func:`force_plates`; also a trial without analog data.
    """
    if rate not in ("analog", "marker"):
        raise ValueError(f"rate must be 'analog' or 'marker', got {rate!r}")
    plates = force_plates(trial)
    if not plates:
        return []
    analogs = np.asarray(trial.analogs, dtype=float)
    analog_rate = float(trial.analog_rate or trial.rate)
    per_frame = max(int(round(analog_rate / trial.rate)), 1)
    results = []
    for plate in plates:
        data = analogs[:, plate.channels]
        if baseline:
            data = data - _baseline(trial, plate, data, threshold)
        force, moment = _plate_wrench(trial, plate, data)
        out_rate = analog_rate
        if rate == "marker" and per_frame > 1:
            force, moment = (_to_frames(x, per_frame, trial.frames) for x in (force, moment))
            out_rate = float(trial.rate)
        results.append(_lab(plate, force, moment, out_rate, threshold))
    return results


def _to_frames(values: np.ndarray, per_frame: int, frames: int) -> np.ndarray:
    """Analog samples (samples, k) to marker frames: centred mean over one frame, sampled at
    each frame's first analog sample (the sample simultaneous with the markers)."""
    half = per_frame // 2
    padded = np.concatenate([np.repeat(values[:1], half, axis=0), values,
                             np.repeat(values[-1:], per_frame, axis=0)])
    cumulative = np.concatenate([np.zeros((1, values.shape[1])), np.cumsum(padded, axis=0)])
    start = np.arange(frames) * per_frame
    return (cumulative[start + per_frame] - cumulative[start]) / per_frame


def total_forces(parts: list[PlateForces], threshold: float = THRESHOLD) -> PlateForces:
    """Sum of several plates' reactions: force, moment about the lab origin, the combined
    COP on the floor plane of the plates (their mean corner height) and free moment."""
    parts = [p for p in parts if p.plate is None or not p.plate.problem]
    if not parts:
        raise ValueError("no plates to add")
    force = sum(p.force for p in parts)
    moment = sum(p.moment for p in parts)
    # Up = the mean plate normal pointing the way the loaded force points.
    normals = np.stack([p.plate.axes[:, 2] for p in parts if p.plate is not None])
    up = normals.mean(axis=0)
    if np.nanmean(force @ up) < 0:
        up = -up
    up /= np.linalg.norm(up)
    height = float(np.mean([p.plate.centre @ up for p in parts if p.plate is not None]))
    fn = force @ up
    loaded = (np.abs(fn) >= threshold) & (fn != 0)       # no COP without a force
    safe = np.where(loaded, fn, 1.0)
    # The point c on the plane c·up = h where the moment is parallel to up:
    # M = c × F + T up  ⇒  c = h up + (up × M_perp-part) / (F·up) adjusted for the height.
    point = height * up
    m_at = moment - np.cross(point, force)                   # moment about a plane point
    lateral = np.cross(up, m_at) / safe[:, None]             # from that point, in the plane
    cop = point + lateral
    free = m_at - np.cross(lateral, force)
    cop[~loaded] = np.nan
    free[~loaded] = 0.0
    return PlateForces(parts[0].rate, force, moment, cop, free, None)


def describe_plates(trial) -> list[str]:
    """One line per plate for ``mocap info`` (no analog arithmetic)."""
    lines = []
    for plate in force_plates(trial):
        head = f"plate {plate.index + 1}: type {plate.type}, "
        channels = f"channels {', '.join(plate.labels)}"
        if plate.problem:
            lines.append(head + f"{channels} (ignored: {plate.problem})")
            continue
        width, length = plate.size
        centre = plate.centre
        lines.append(head + f"{width * 1000:.0f} × {length * 1000:.0f} mm, centre "
                     f"({centre[0]:.3f}, {centre[1]:.3f}, {centre[2]:.3f}) m, {channels}"
                     + (", calibrated" if plate.cal_matrix is not None else ""))
    return lines
