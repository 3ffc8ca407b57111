"""C3D marker files: read (structure check, then a vectorised decoder) and write (ezc3d).

Reading goes in two steps:

1. :func:`mocap.io.c3d.layout.inspect_c3d` checks the header, walks the parameter
   section with bounds checks and matches the data size against the file size,
   in pure Python. Damaged files stop here with a :class:`MocapError`.
2. :func:`mocap.io.c3d.decode.decode_c3d_data` decodes the data section of the
   checked layout with numpy (Intel, DEC and SGI/MIPS; integer and float).

Why our own decoder rather than ezc3d or the ``c3d`` package (the design's first
plan was ezc3d, with the ``c3d`` package as fallback), measured on this project's
real files and on seeded damage of them:

- ezc3d misreads valid files silently: the three BTS files of c3d.org sample 28
  (no ANALOG:RATE, so it skips the 6 analog words per frame and scrambles the
  points: median change per axis between frames 575 mm instead of 1.6 mm) and
  the KINARM sample (it opens it only with ``ignore_bad_formatting``, then with
  blank labels and constant values);
- ezc3d refuses SGI/MIPS files and stalls 30-55 s on the KINARM sample before
  raising; one flipped bit in a description length stalled it 20-35 s, and
  one flipped bit in a group id crashed the process (segmentation fault),
  both in files our structure check had accepted;
- ezc3d is 5-11× slower in process (benchmarks/io.py) and a child-process guard
  against its crashes would cost 7-58× (Python and ezc3d start-up per file);
- the ``c3d`` package refuses 13 of the 100 valid real C3D files with assertion
  errors (scale-factor and analog-count consistency checks, parameter types).

Our decoder gives the same points and validity as ezc3d on the files ezc3d
reads correctly, and the same as the ``c3d`` package on the files ezc3d cannot
read (tests/mocap/io/test_realdata.py checks both). ezc3d writes C3D files here, and
``read_c3d(path, engine="ezc3d")`` still reads with it, for files
:func:`ezc3d_refusal` finds safe for it.

Every reading ends in the same :class:`~mocap.trial.Trial`: points in metres,
NaN where the residual is negative, the coordinates are not finite, or the
point sits exactly at (0, 0, 0) (how some Qualisys files mark gaps). Points that
a modelling package computed (POINT:ANGLES, FORCES, MOMENTS, POWERS, SCALARS,
REACTIONS, such as Plug-in Gait's ``LKneeAngles``) are not markers: they are
kept in ``trial.modelled`` instead (``labels``, ``kinds`` and
``values`` of shape (frames, n, 3) in the file's units for each kind, e.g.
degrees for angles, NaN where invalid). ``trial.parameters`` holds every
C3D parameter (``{group: {name: value}}``, e.g. FORCE_PLATFORM for the analogs),
``trial.events`` the EVENT group (label, context, time, frame), and
``trial.poses`` the segment poses of a markerless file's ROTATION group
(:class:`mocap.io.c3d.rotations.SegmentPoses`).

Units: POINT:UNITS ``mm``/``cm``/``m`` (and their long spellings) are honoured.
When the file has no usable unit, the unit is inferred from the magnitude of
the valid coordinates: a 99th percentile above 20 means millimetres (no capture
volume is 20 m wide, while a marker 20 mm from the origin for 99 % of a trial is
implausible), otherwise metres; the inference is recorded in
``metadata["warnings"]``.
"""
from __future__ import annotations

import os

import numpy as np

from mocap.errors import MocapError
from mocap.io.c3d.decode import decode_c3d_data
from mocap.io.c3d.layout import C3DLayout, count_parameter, inspect_c3d
from mocap.io.c3d.outputs import MODELLED_KINDS, listed_outputs
from mocap.trial import Trial


_UNIT_FACTORS = {
    "mm": 1e-3, "millimeter": 1e-3, "millimeters": 1e-3, "millimetre": 1e-3,
    "millimetres": 1e-3, "cm": 1e-2, "centimeter": 1e-2, "centimeters": 1e-2,
    "centimetre": 1e-2, "centimetres": 1e-2, "m": 1.0, "meter": 1.0, "meters": 1.0,
    "metre": 1.0, "metres": 1.0, "dm": 0.1, "in": 0.0254, "inch": 0.0254,
    "inches": 0.0254,
}
#: 99th-percentile |coordinate| above which a file without units is taken as millimetres.
INFER_MM_ABOVE = 20.0


def unit_factor(units: str) -> float | None:
    """Metres per file unit for a unit string (``"mm"`` → 0.001), None if unknown."""
    return _UNIT_FACTORS.get(units.strip().lower().rstrip("."))


def infer_unit_factor(values: np.ndarray) -> tuple[str, float]:
    """Guess the unit of coordinates with no stated unit, from their magnitude.

    Parameters
    ----------
    values : ndarray
        Coordinates in the unknown unit, NaN where missing.

    Returns
    -------
    (unit, metres per unit) : ``("mm", 0.001)`` or ``("m", 1.0)``.
    """
    finite = np.abs(values[np.isfinite(values)])
    if finite.size and np.percentile(finite, 99) > INFER_MM_ABOVE:
        return "mm", 1e-3
    return "m", 1.0


#: Beyond this distance from the origin (m) no capture volume reaches: a stated unit that
#: puts the markers there is a unit the file got wrong (mm values labelled m).
UNIT_FAR_M = 100.0
#: Below this (m) a whole marker cloud is no body: metre values labelled mm.
UNIT_NEAR_M = 0.005


def unit_disagreement(values: np.ndarray, factor: float, units: str) -> str | None:
    """A warning when the stated unit puts the coordinates where no capture is, else None.

    Parameters
    ----------
    values : ndarray, shape (frames, markers, 3)
        Coordinates in the file's unit, NaN where missing.
    factor : float
        Metres per file unit of the stated ``units``.
    units : str
        The unit as stated (for the message).
    """
    flat = values.reshape(-1)
    flat = flat[:: max(1, flat.size // 200_000)]          # a sample is enough for a scale
    finite = np.abs(flat[np.isfinite(flat) & (flat != 0)]) * factor
    if finite.size < 10:
        return None
    reach = float(np.percentile(finite, 99))
    if reach > UNIT_FAR_M:
        shown = f"{reach:,.0f}" if reach < 1e7 else f"{reach:.3g}"     # no 300-digit numbers
        return (f"the stated unit {units!r} puts the markers {shown} m from the origin; "
                "the coordinates look like millimetres (the file's unit may be wrong)")
    if reach < UNIT_NEAR_M and values.shape[1] >= 3:     # one or two markers may sit anywhere
        return (f"the stated unit {units!r} puts every marker within {reach * 1000:.2g} mm of "
                "the origin; the coordinates look like metres (the file's unit may be wrong)")
    return None


def _string_list(value) -> list[str]:
    if value is None:
        return []
    if isinstance(value, str):
        return [value] if value else []
    if isinstance(value, list):
        return [str(v) for v in value]
    return []


def _group_labels(group: dict, count: int) -> list[str]:
    """A group's LABELS, LABELS2 … joined, stripped, padded with "" or cut to ``count``."""
    labels = _string_list(group.get("LABELS"))
    index = 2
    while f"LABELS{index}" in group:
        labels += _string_list(group[f"LABELS{index}"])
        index += 1
    labels = [label.strip() for label in labels[:count]]
    return labels + [""] * (count - len(labels))


def _point_labels(layout: C3DLayout) -> list[str]:
    """POINT:LABELS, LABELS2 … joined, padded or cut to the point count."""
    return _group_labels(layout.parameters.get("POINT", {}), layout.point_count)


def _analog_labels(layout: C3DLayout) -> list[str]:
    labels = _group_labels(layout.parameters.get("ANALOG", {}), layout.analog_channels)
    return unique_labels(labels, prefix="A")[0]      # blank → A001…, repeats → _2


def unique_labels(labels: list[str], prefix: str = "M") -> tuple[list[str], list[str]]:
    """Make labels non-empty and unique, saying what was changed.

    Blank labels become ``M001``… (1-based column); the second and later
    copies of a repeated label get ``_2``, ``_3``… appended (``RKNE``,
    ``RKNE_2``), so every marker stays addressable by name.

    Returns
    -------
    (labels, notes) : the new labels and at most one note per kind of change.
    """
    result = []
    seen: dict[str, int] = {}
    renamed = []
    blank = 0
    taken = set(labels)
    for i, label in enumerate(labels):
        if not label:
            label = f"{prefix}{i + 1:03d}"
            blank += 1
        if label in seen:
            count = seen[label] + 1
            while f"{label}_{count}" in taken or f"{label}_{count}" in seen:
                count += 1
            seen[label] = count
            candidate = f"{label}_{count}"
            renamed.append(candidate)
            label = candidate
        seen.setdefault(label, 1)
        result.append(label)
    notes = []
    if blank:
        notes.append(f"{blank} blank label(s) named after their column ({prefix}001…)")
    if renamed:
        shown = ", ".join(renamed[:6]) + (", …" if len(renamed) > 6 else "")
        notes.append(f"{len(renamed)} repeated label(s) renamed with a numbered suffix: "
                     f"{shown}")
    return result, notes


def ezc3d_refusal(layout: C3DLayout) -> str:
    """Why ezc3d must not read this checked file ('' when it may).

    ezc3d trusts POINT:FRAMES, POINT:USED and ANALOG:RATE / POINT:RATE over the
    header; where those disagree with the layout the file size confirms, it
    misreads the data. It refuses SGI/MIPS files, and a parameter section with
    oddities (a group defined twice, a parameter of an undefined group, a
    description overrunning its entry, unprintable names) has crashed it or
    kept it busy for tens of seconds in the damage tests.
    """
    if layout.processor == "mips":
        return "ezc3d does not read SGI/MIPS files"
    if layout.warnings:
        return "; ".join(layout.warnings)
    if layout.anomalies:
        return "parameter section: " + "; ".join(layout.anomalies[:3])
    parameters = layout.parameters
    point = parameters.get("POINT", {})
    if "USED" not in point:
        return "no POINT:USED parameter"
    if count_parameter(parameters, "POINT", "FRAMES") != layout.frames:
        return "POINT:FRAMES does not give the frame count the file holds"
    if len(_string_list(point.get("LABELS"))) < min(layout.point_count, 255):
        return "fewer POINT:LABELS than points"
    analog = parameters.get("ANALOG", {})
    if layout.analog_channels:
        rate = analog.get("RATE")
        if not isinstance(rate, np.ndarray) or rate.size == 0 or layout.rate <= 0 \
                or not np.isfinite(rate.reshape(-1)[0]):
            return "no ANALOG:RATE: ezc3d would skip the analog words and shift the points"
        if int(float(rate.reshape(-1)[0]) / layout.rate) != layout.analog_samples_per_frame:
            return "ANALOG:RATE / POINT:RATE disagrees with the stored analog samples"
        for name in ("SCALE", "OFFSET", "LABELS"):
            value = analog.get(name)
            size = len(value) if isinstance(value, list) else getattr(value, "size", 0)
            if size < min(layout.analog_channels, 255):
                return f"fewer ANALOG:{name} entries than channels"
    return ""


def _read_ezc3d(layout: C3DLayout):
    import ezc3d   # deferred: only the engine="ezc3d" path needs it (0.2 s of start-up)

    c3d = ezc3d.c3d(layout.path, extract_forceplat_data=False)
    data = c3d["data"]
    points = np.asarray(data["points"])[:3].transpose(2, 1, 0)
    residuals = np.asarray(data["meta_points"]["residuals"])[0].T
    analogs = np.asarray(data["analogs"])[0].T
    return points, residuals, analogs


def _analog_transform(layout: C3DLayout, raw: np.ndarray) -> np.ndarray:
    """Apply ANALOG:OFFSET, SCALE and GEN_SCALE to raw stored analog values.

    With ANALOG:FORMAT "UNSIGNED" the stored words and OFFSET are unsigned 16-bit
    integers (C3D User Guide; :func:`mocap.io.c3d.parameters.analog_offsets`).
    """
    from mocap.io.c3d.parameters import analog_format_unsigned, analog_offsets

    channels = layout.analog_channels
    group = layout.parameters.get("ANALOG", {})

    def per_channel(name: str, default: float) -> np.ndarray:
        value = group.get(name)
        out = np.full(channels, default, dtype=float)
        if isinstance(value, np.ndarray):
            flat = value.reshape(-1)[:channels].astype(float)
            out[:flat.size] = flat
        return out

    offsets = analog_offsets(group, channels)
    scales = per_channel("SCALE", 1.0)
    gen_scale = group.get("GEN_SCALE")
    gen = float(gen_scale.reshape(-1)[0]) if isinstance(gen_scale, np.ndarray) \
        and gen_scale.size else 1.0
    values = raw
    if not layout.is_float and analog_format_unsigned(group):
        values = np.where(values < 0, values + 65536, values)
    return (values - offsets) * scales * gen


def _read_own(layout: C3DLayout):
    points, residuals, raw_analogs = decode_c3d_data(layout)
    analogs = _analog_transform(layout, raw_analogs) if layout.analog_channels else \
        np.zeros((0, 0))
    return points, residuals, analogs


def _shape_ok(layout: C3DLayout, points: np.ndarray, residuals: np.ndarray) -> bool:
    return (points.shape == (layout.frames, layout.point_count, 3)
            and residuals.shape == (layout.frames, layout.point_count))


def read_c3d(path: str | os.PathLike, engine: str = "mocap") -> Trial:
    """Read a C3D file into a :class:`Trial` (metres, NaN for missing samples).

    Parameters
    ----------
    path : str or PathLike
    engine : {"mocap", "ezc3d"}
        Who decodes the data section once the file has passed the structure
        check: our vectorised decoder (default), or ezc3d, which is refused
        (MocapError) for files it is known to misread or stall on. ezc3d is not
        otherwise guarded: it still stalls 30-55 s on the KINARM sample of
        c3d.org (sample 22) before raising, for a reason not found.

    Returns
    -------
    Trial
        ``points`` (frames, markers, 3) in metres; ``units`` as stored in the
        file (``""`` when absent); ``first_frame``, ``events``, ``parameters``,
        ``poses`` and ``modelled`` (computed points, see the module docstring);
        ``metadata`` holds ``reader`` (``"mocap"`` or ``"ezc3d"``), ``processor`` and
        ``warnings`` (list of str).

    Raises
    ------
    MocapError
        Missing, damaged or unreadable file.

    Examples
    --------
    >>> trial = read_c3d("walk.c3d")                   # doctest: +SKIP
    >>> trial.points.shape, trial.rate                 # doctest: +SKIP
    ((580, 51, 3), 100.0)
    """
    layout = inspect_c3d(path)
    notes = list(layout.warnings)
    if engine == "ezc3d":
        problem = ezc3d_refusal(layout)
        if problem:
            raise MocapError(f"not read with ezc3d: {problem}", layout.path)
        reader = _read_ezc3d
    elif engine == "mocap":
        reader = _read_own
    else:
        raise ValueError(f"unknown C3D engine {engine!r}")
    try:
        points, residuals, analogs = reader(layout)
    except MemoryError:
        raise MocapError("file too large to read into memory", layout.path) from None
    except (RuntimeError, OSError, ValueError, IndexError) as error:
        if engine != "ezc3d":
            raise           # our decoder failing on a checked layout is our bug
        raise MocapError(f"ezc3d could not decode the data: {error}", layout.path) \
            from None
    if not _shape_ok(layout, points, residuals):
        raise MocapError(f"{engine} read {points.shape[:2]} frames × points instead of "
                         f"{(layout.frames, layout.point_count)}", layout.path)
    return _to_trial(layout, engine, points, residuals, analogs, notes)


def _frame_blocks(frames: int, size: int = 4096):
    """Slices of ``size`` frames: the per-point masks and sums of a block stay small
    (a loop over blocks of frames, not over frames)."""
    return (slice(start, start + size) for start in range(0, frames, size))


def _to_trial(layout: C3DLayout, reader: str, points: np.ndarray, residuals: np.ndarray,
              analogs: np.ndarray, notes: list[str]) -> Trial:
    points = np.asarray(points, dtype=float)       # a fresh array of the reader's: no copy
    if not points.flags.writeable:
        points = points.copy()
    for block in _frame_blocks(points.shape[0]):
        chunk = points[block]
        # the sum of a point's coordinates is finite when all three are (no overflow: they
        # come from 16-bit integers or 32-bit floats); strided adds, not a reduction along
        # the last axis, which numpy runs several times slower
        invalid = ~(residuals[block] >= 0)
        invalid |= ~np.isfinite(chunk[..., 0] + chunk[..., 1] + chunk[..., 2])
        chunk[invalid] = np.nan

    raw_labels = _point_labels(layout)
    point_group = layout.parameters.get("POINT", {})
    modelled_names = listed_outputs(point_group)
    is_modelled = np.array([bool(label) and label in modelled_names for label in raw_labels],
                           dtype=bool)
    marker_columns = np.flatnonzero(~is_modelled)
    labels, label_notes = unique_labels([raw_labels[i] for i in marker_columns])
    notes += label_notes

    units = point_group.get("UNITS", "")
    units = units[0] if isinstance(units, list) and units else units
    units = units.strip() if isinstance(units, str) else ""
    factor = unit_factor(units) if units else None
    # without modelled outputs the markers are all the points (no copy: ``points`` is ours)
    markers = points[:, marker_columns, :] if is_modelled.any() else points
    for block in _frame_blocks(markers.shape[0]):
        chunk = markers[block]
        origin = chunk[..., 0] == 0                     # a gap coded as (0, 0, 0)
        origin &= chunk[..., 1] == 0
        origin &= chunk[..., 2] == 0
        chunk[origin] = np.nan
    if factor is None and not np.isfinite(markers).any():
        factor = 1.0            # nothing to convert: no valid coordinate
    elif factor is None:
        guess, factor = infer_unit_factor(markers)
        notes.append(f"POINT:UNITS is {units!r}; {guess} inferred from the coordinates' "
                     f"magnitude")
    else:
        disagreement = unit_disagreement(markers, factor, units)
        if disagreement:
            notes.append(f"POINT:UNITS: {disagreement}")
    if factor != 1.0:
        markers *= factor

    metadata = {
        "reader": reader,
        "processor": layout.processor,
        "c3d_frames": layout.frames,
        "warnings": notes,
    }
    modelled = None
    if is_modelled.any():
        columns = np.flatnonzero(is_modelled)
        modelled = {
            "labels": [raw_labels[i] for i in columns],
            "kinds": [modelled_names[raw_labels[i]] for i in columns],
            "values": points[:, columns, :],
        }
    from mocap.io.c3d.layout import decode_floats
    from mocap.io.c3d.rotations import read_rotations

    # poses are in POINT:UNITS; without one, the markers' inferred unit, else mm (Theia)
    pose_factor = (unit_factor(units) if units else None) or \
        (factor if np.isfinite(markers).any() else 1e-3)
    poses = read_rotations(layout, decode_floats, pose_factor)
    for group, key in (("MANUFACTURER", "COMPANY"), ("MANUFACTURER", "SOFTWARE"),
                       ("SUBJECTS", "NAMES")):
        value = layout.parameters.get(group, {}).get(key)
        if isinstance(value, (str, list)) and value:
            metadata[f"{group.lower()}_{key.lower()}"] = value
    analog_labels = _analog_labels(layout) if layout.analog_channels else []
    analog_rate = layout.rate * layout.analog_samples_per_frame \
        if layout.analog_channels and layout.rate > 0 else None
    if analogs.ndim != 2 or analogs.shape[1] != len(analog_labels):
        analogs = None
        analog_labels = []
        analog_rate = None
    return Trial(labels, markers, layout.rate, units, layout.path, "c3d",
                 analogs if analog_labels else None, analog_labels, analog_rate, metadata,
                 first_frame=layout.first_frame, events=_events(layout),
                 parameters=layout.parameters, poses=poses, modelled=modelled)


def _events(layout: C3DLayout) -> list[dict]:
    """EVENT group as a list of ``{"label", "context", "time", "frame"}``, by time.

    ``time`` is in seconds from the trial's first frame and ``frame`` the 0-based
    index into ``points``; the file stores times from the start of the capture
    (frame 1 at 0 s), as minutes and seconds. Events outside the trial are dropped.
    """
    group = layout.parameters.get("EVENT", {})
    times = group.get("TIMES")
    if not isinstance(times, np.ndarray) or times.ndim != 2 or times.shape[0] != 2 \
            or layout.rate <= 0:
        return []
    used = count_parameter(layout.parameters, "EVENT", "USED")
    count = min(times.shape[1], used if used is not None else times.shape[1])
    labels = _string_list(group.get("LABELS"))
    contexts = _string_list(group.get("CONTEXTS"))
    events = []
    for i in range(count):
        absolute = 60.0 * float(times[0, i]) + float(times[1, i])
        if not np.isfinite(absolute):
            continue
        frame = int(round(absolute * layout.rate)) + 1 - layout.first_frame
        if 0 <= frame < layout.frames:
            events.append({"label": labels[i] if i < len(labels) else "",
                           "context": contexts[i] if i < len(contexts) else "",
                           "time": frame / layout.rate, "frame": frame})
    return sorted(events, key=lambda event: event["frame"])


__all__ = ["read_c3d", "unit_factor", "infer_unit_factor", "unit_disagreement", "unique_labels", "MODELLED_KINDS"]
