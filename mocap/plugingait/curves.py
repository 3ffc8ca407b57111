"""Plug-in Gait outputs per gait cycle, under Vicon's names: what scores and reports read.

A walk's outputs (the clinical angles this toolkit computes, or those Vicon stored in the
file, joint moments and powers when there are any) are cut into each side's cycles (foot
strike to foot strike) and resampled to 0–100 % (:func:`mocap.plugingait.events.normalise_cycles`),
each variable under Vicon's name without the side (``HipAngles``, ``KneeMoment`` …).

Units: angles degrees, moments N·m/kg, powers W/kg (a file's N·mm/kg moments, Vicon's
``POINT:MOMENT_UNITS`` ``Nmm``, are divided by 1000).
"""
from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from mocap.plugingait.events import CYCLE_SAMPLES, GaitEvent, normalise_cycles
from mocap.trial import Trial


@dataclass
class CycleCurves:
    """The normalised cycles of one walk.

    Attributes
    ----------
    source : str
        The walk (its path).
    side : list of str
        Per cycle, ``"l"`` or ``"r"``.
    foot_off : list of float
        Per cycle, % of the cycle at the side's foot off (NaN when none).
    values : dict of str to ndarray, shape (cycles, samples, 3)
        Per variable (``HipAngles`` …), components X, Y, Z of the cycle's own side; NaN
        where the walk has no value.
    samples : int
    """

    source: str
    side: list
    foot_off: list
    values: dict
    samples: int = CYCLE_SAMPLES

    def of_side(self, side: str) -> dict:
        """``values`` restricted to one side's cycles: variable -> (cycles, samples, 3)."""
        chosen = np.array([s == side for s in self.side], dtype=bool)
        return {name: v[chosen] for name, v in self.values.items()}


def angle_series(angles) -> dict:
    """The clinical angles of :func:`~mocap.plugingait.clinical.plugingait_angles` as
    series: ``(side, Vicon name)`` -> (frames, 3) degrees (the name without its side,
    :func:`~mocap.plugingait.clinical.vicon_label`)."""
    from mocap.plugingait.clinical import vicon_label

    return {(segment[0], vicon_label(segment)[1:]): angles.values[:, k, :]
            for k, segment in enumerate(angles.segments)}


#: Scale of a file's POINT unit of each kind to the curves' units.
_MOMENT_SCALE = {"nmm": 1e-3, "n.mm": 1e-3, "nmm/kg": 1e-3, "nm": 1.0, "n.m": 1.0,
                 "nm/kg": 1.0}


def stored_series(trial: Trial, names=None) -> dict:
    """Plug-in Gait outputs a previous (Vicon) run stored in the file.

    Parameters
    ----------
    trial : Trial
        Read from a C3D; the outputs are in ``trial.modelled``.
    names : iterable of str, optional
        Vicon names to keep (default: those of
        :data:`mocap.plugingait.normative.VARIABLES`).

    Returns
    -------
    dict
        ``(side, name)`` -> (frames, 3): angles degrees, moments N·m/kg, powers W/kg. Labels
        with a subject prefix (``Matt:LKneeAngles``) count; an empty output is left out.
    """
    from mocap.plugingait.normative import VARIABLES

    wanted = set(names) if names is not None else {v.name for v in VARIABLES}
    modelled = trial.modelled
    if not modelled:
        return {}
    unit = str(trial.parameters.get("POINT", {}).get("MOMENT_UNITS", "Nmm")).strip().lower()
    moment_scale = _MOMENT_SCALE.get(unit.replace(" ", ""), 1e-3)
    values = np.asarray(modelled["values"], dtype=float)
    out = {}
    for k, label in enumerate(modelled["labels"]):
        found = re.fullmatch(r"(?:.*:)?([LR])(\w+)", str(label).strip())
        if not found or found[2] not in wanted:
            continue
        series = values[:, k, :]
        if not np.isfinite(series).any():
            continue
        if found[2].endswith("Moment"):
            series = series * moment_scale
        out[(found[1].lower(), found[2])] = series
    return out


def cycle_curves(series: dict, events: list[GaitEvent], frames: int, source: str = "",
                 samples: int = CYCLE_SAMPLES) -> CycleCurves:
    """Each side's cycles of every series, resampled to ``samples`` points.

    Parameters
    ----------
    series : dict
        ``(side, name)`` -> (frames, 3), as :func:`angle_series` and
        :func:`stored_series` give them (merge the dicts to combine sources).
    events : list of GaitEvent
    frames : int
        Frames of the walk (every series has as many rows).
    source : str
    samples : int

    Returns
    -------
    CycleCurves
        A variable that one side lacks is NaN on that side's cycles.
    """
    from mocap.rotations.angles import JointAngles

    names = list(dict.fromkeys(name for _, name in series))
    segments, columns = [], []
    for side in ("l", "r"):
        for name in names:
            segments.append(f"{side}_{name}")
            columns.append(series.get((side, name), np.full((frames, 3), np.nan)))
    values = (np.stack(columns, axis=1) if columns else np.zeros((frames, 0, 3)))
    table = JointAngles(times=np.arange(frames, dtype=float), values=values,
                        segments=segments, sequence="XYZ", parents=[-1] * len(segments),
                        axes=["X", "Y", "Z"])
    cycles = normalise_cycles(table, events, samples)
    return CycleCurves(source, list(cycles.side), list(cycles.foot_off),
                       {name: cycles.values[:, :, j] for j, name in enumerate(cycles.joints)},
                       samples)


__all__ = ["CycleCurves", "angle_series", "cycle_curves", "stored_series"]
