"""Gait-cycle (spatio-temporal) parameters per side, as Vicon Nexus defines them.

A side's cycle runs from one of its foot strikes to the next (times ``s0``, ``s1``,
stride time ``T = s1 - s0``). Within it, with percentages of ``T`` from ``s0``:

- Foot Off: the side's foot off; Opposite Foot Off / Opposite Foot Contact: the
  other foot's first off and first strike;
- Step Time: ``s1`` minus the opposite foot contact (s);
- Cadence: ``120 / T`` (steps/min, two steps a stride);
- Single Support: Opposite Foot Contact − Opposite Foot Off (%);
- Double Support: Opposite Foot Off + (Foot Off − Opposite Foot Contact) (%);
- Stride Length: horizontal distance of the side's heel marker (HEE, else the
  ankle marker ANK) from ``s0`` to ``s1``;
  Step Length: the side's heel at ``s1`` minus the other heel at the opposite foot
  contact, along the stride (m); Step Width: the same step across the stride, i.e. the
  horizontal distance of the other heel from the line of this side's two strikes (m);
- Walking Speed: Stride Length / ``T`` (m/s).

The identities for cadence, step time, speed and support are those Vicon's stored
``ANALYSIS`` values satisfy (``c3dorg sample_04/sub_labels.c3d`` to 1e-5). Values are
means over the side's complete cycles.
"""
from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass

import numpy as np

from mocap.plugingait.events import FOOT_OFF, FOOT_STRIKE, GaitEvent, _marker, gait_events
from mocap.trial import Trial

#: Vicon's ANALYSIS names and units for the fields of :class:`GaitParameters`.
VICON_NAMES = {
    "cadence": ("Cadence", "steps/min"),
    "walking_speed": ("Walking Speed", "m/s"),
    "stride_time": ("Stride Time", "s"),
    "step_time": ("Step Time", "s"),
    "stride_length": ("Stride Length", "m"),
    "step_length": ("Step Length", "m"),
    "step_width": ("Step Width", "m"),
    "foot_off": ("Foot Off", "%"),
    "opposite_foot_off": ("Opposite Foot Off", "%"),
    "opposite_foot_contact": ("Opposite Foot Contact", "%"),
    "single_support": ("Single Support", "%"),
    "double_support": ("Double Support", "%"),
}


@dataclass(frozen=True)
class GaitParameters:
    """One side's gait-cycle parameters (means over ``cycles`` complete cycles).

    Units: cadence steps/min; walking_speed m/s; stride_time, step_time s;
    stride_length, step_length, step_width m; foot_off … double_support % of the stride.
    NaN where the events or heel markers needed are missing.
    """

    side: str
    cycles: int
    cadence: float
    walking_speed: float
    stride_time: float
    step_time: float
    stride_length: float
    step_length: float
    step_width: float
    foot_off: float
    opposite_foot_off: float
    opposite_foot_contact: float
    single_support: float
    double_support: float


def _first_in(times: np.ndarray, start: float, stop: float) -> float:
    inside = times[(times > start) & (times < stop)]
    return float(inside[0]) if inside.size else np.nan


def cycle_timing(strikes, offs, opposite_strikes, opposite_offs) -> np.ndarray:
    """Temporal parameters of each complete cycle of one side.

    Parameters
    ----------
    strikes, offs : array-like of float, seconds
        The side's foot strikes and foot offs.
    opposite_strikes, opposite_offs : array-like of float, seconds
        The other side's.

    Returns
    -------
    ndarray, shape (cycles, 5), float: stride time (s), step time (s), foot off,
    opposite foot off, opposite foot contact (% of the stride); NaN where an event
    is missing inside the cycle.

    Examples
    --------
    >>> cycle_timing([0.0, 1.0], [0.6], [0.5], [0.1]).round(6).tolist()
    [[1.0, 0.5, 60.0, 10.0, 50.0]]
    """
    strikes = np.sort(np.asarray(strikes, float))
    offs, o_strikes, o_offs = (np.sort(np.asarray(a, float))
                               for a in (offs, opposite_strikes, opposite_offs))
    rows = []
    for s0, s1 in zip(strikes[:-1], strikes[1:]):  # a handful of cycles per trial
        stride = s1 - s0
        fo, ofo, ofc = (_first_in(a, s0, s1) for a in (offs, o_offs, o_strikes))
        rows.append([stride, s1 - ofc, *(100.0 * (np.array([fo, ofo, ofc]) - s0) / stride)])
    return np.array(rows, float).reshape(-1, 5)


def _heel(trial: Trial, side: str, time: float) -> np.ndarray:
    heel = _marker(trial, side.upper() + "HEE")
    heel = _marker(trial, side.upper() + "ANK") if heel is None else heel
    if heel is None or not np.isfinite(time):
        return np.full(3, np.nan)
    return heel[int(round(time * trial.rate))]


def gait_parameters(trial: Trial, events: list[GaitEvent] | None = None
                    ) -> list[GaitParameters]:
    """Vicon's gait-cycle parameters for the left and the right side.

    Parameters
    ----------
    trial : Trial
        Points in metres; L/RHEE (else L/RANK) for the lengths.
    events : list of GaitEvent, optional
        Default :func:`mocap.plugingait.events.gait_events` (the file's events,
        else detected).

    Returns
    -------
    list of GaitParameters, left then right; a side without a complete cycle has
    ``cycles == 0`` and NaN values.
    """
    events = gait_events(trial) if events is None else events
    times = {(e.side, e.label): [] for e in events}
    for e in events:
        times[(e.side, e.label)].append(e.frame / trial.rate)
    out = []
    for side, other in (("l", "r"), ("r", "l")):
        get = lambda s, k: times.get((s, k), [])  # noqa: E731
        strikes = sorted(get(side, FOOT_STRIKE))
        timing = cycle_timing(strikes, get(side, FOOT_OFF), get(other, FOOT_STRIKE),
                              get(other, FOOT_OFF))
        lengths = []
        for (s0, s1), row in zip(zip(strikes[:-1], strikes[1:]), timing):
            stride = (_heel(trial, side, s1) - _heel(trial, side, s0))[:2]
            ofc = s0 + row[4] * (s1 - s0) / 100.0
            step = (_heel(trial, side, s1) - _heel(trial, other, ofc))[:2]
            length = float(np.hypot(*stride))
            along = float(step @ stride) / length if length else np.nan
            across = abs(float(stride[0] * step[1] - stride[1] * step[0])) / length \
                if length else np.nan
            lengths.append([length, along, across])
        lengths = np.array(lengths, float).reshape(-1, 3)
        with warnings.catch_warnings():  # an all-NaN column is a NaN mean, not news
            warnings.simplefilter("ignore", RuntimeWarning)
            t = np.nanmean(timing, axis=0) if len(timing) else np.full(5, np.nan)
            L = np.nanmean(lengths, axis=0) if len(lengths) else np.full(3, np.nan)
        stride_t, step_t, fo, ofo, ofc = t
        out.append(GaitParameters(
            side=side, cycles=len(timing), cadence=120.0 / stride_t,
            walking_speed=L[0] / stride_t, stride_time=stride_t, step_time=step_t,
            stride_length=L[0], step_length=L[1], step_width=L[2], foot_off=fo, opposite_foot_off=ofo,
            opposite_foot_contact=ofc, single_support=ofc - ofo,
            double_support=ofo + (fo - ofc)))
    return out


def to_dataframe(parameters: list[GaitParameters]):
    """One row per side (``Left``/``Right``), columns Vicon's ``Name (unit)``."""
    from mocap.errors import import_pandas

    pandas = import_pandas()
    rows = []
    for p in parameters:
        values = asdict(p)
        row = {"Context": {"l": "Left", "r": "Right"}[p.side], "Cycles": p.cycles}
        row.update({f"{name} ({unit})": values[key]
                    for key, (name, unit) in VICON_NAMES.items()})
        rows.append(row)
    return pandas.DataFrame(rows)


def write_parameters(parameters: list[GaitParameters], path) -> None:
    """One row per side: CSV, or JSON (a list of objects) when ``path`` ends .json."""
    from mocap.atomic import atomic_path

    frame = to_dataframe(parameters)
    with atomic_path(path) as tmp:
        if str(path).lower().endswith(".json"):
            frame.to_json(tmp, orient="records", indent=1)
        else:
            frame.to_csv(tmp, index=False)


__all__ = ["GaitParameters", "VICON_NAMES", "cycle_timing", "gait_parameters",
           "to_dataframe", "write_parameters"]
