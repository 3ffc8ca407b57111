"""Plug-in Gait's outputs under Vicon Nexus's labels and units, for C3D and CSV.

Nexus writes each output as a C3D point listed in ``POINT:ANGLES``, ``FORCES``,
``MOMENTS`` or ``POWERS``:

* ``<Side><Joint>Angles`` (degrees; X, Y, Z = flexion, adduction, rotation), e.g.
  ``LHipAngles``, ``RFootProgressAngles``, ``LThoraxAngles``;
* ``<Side><Joint>Moment`` (N·mm per kg of body mass, written with unit ``Nmm``),
  ``<Side><Joint>Power`` (W/kg, total in Z, X and Y zero, unit ``W``),
  ``<Side><Joint>Force`` and ``<Side>GroundReactionForce`` (N/kg, unit ``N``);
* the model's joint centres as markers (``LHJC``, ``LKJC``, ``LAJC`` …, lengths).

:func:`model_outputs` gives the (label, kind, values) list that
:func:`mocap.io.c3d.write.write_c3d` writes; :func:`analysis_group` the ``ANALYSIS``
group of the gait-cycle parameters; :func:`outputs_table` the same outputs as a tidy
table (one row per frame, label and component).
"""
from __future__ import annotations

import numpy as np

from mocap.plugingait.parameters import VICON_NAMES, GaitParameters

#: Unit of each output kind as Vicon Nexus labels it, and what the values are.
UNITS = {"ANGLES": ("deg", "degrees"), "MOMENTS": ("Nmm", "N·mm/kg"),
         "POWERS": ("W", "W/kg"), "FORCES": ("N", "N/kg")}


def kinetic_label(segment: str, suffix: str) -> str:
    """``l_hip`` + ``Moment`` -> ``LHipMoment`` (the angles' labels are
    :func:`mocap.plugingait.clinical.vicon_label`).

    >>> kinetic_label("r_ankle", "Power")
    'RAnklePower'
    """
    side, _, joint = segment.partition("_")
    return side.upper() + "".join(part.capitalize() for part in joint.split("_")) + suffix


def model_outputs(angles, kinetics=None) -> list[tuple[str, str, np.ndarray]]:
    """(label, kind, values (frames, 3)) of every output, Vicon's labels and units.

    Parameters
    ----------
    angles : JointAngles
        :func:`mocap.plugingait.clinical.plugingait_angles` (degrees).
    kinetics : JointKinetics, optional
        :func:`mocap.plugingait.kinetics.plugingait_kinetics`.
    """
    from mocap.plugingait.clinical import vicon_label

    out = [(vicon_label(name), "ANGLES", np.asarray(angles.segment(name), float))
           for name in angles.segments]
    if kinetics is None:
        return out
    frames = len(kinetics.times)
    for k, side in enumerate(("l", "r")):
        out.append((f"{side.upper()}GroundReactionForce", "FORCES", kinetics.ground[:, k]))
    for k, name in enumerate(kinetics.segments):
        out.append((kinetic_label(name, "Force"), "FORCES", kinetics.forces[:, k]))
    for k, name in enumerate(kinetics.segments):
        out.append((kinetic_label(name, "Moment"), "MOMENTS", kinetics.moments[:, k]))
    for k, name in enumerate(kinetics.segments):
        power = np.zeros((frames, 3))
        power[:, 2] = kinetics.powers[:, k]
        power[~np.isfinite(kinetics.powers[:, k])] = np.nan
        out.append((kinetic_label(name, "Power"), "POWERS", power))
    return out


def analysis_group(parameters: list[GaitParameters], subject: str = "") -> dict:
    """Vicon's ``ANALYSIS`` group (NAMES, CONTEXTS, UNITS, VALUES …) of the gait parameters.

    One entry per parameter and side with cycles (``Left``/``Right``), Vicon's names and
    units (:data:`mocap.plugingait.parameters.VICON_NAMES`); NaN values are left out.
    """
    names, contexts, units, values = [], [], [], []
    for p in parameters:
        if not p.cycles:
            continue
        for key, (name, unit) in VICON_NAMES.items():
            value = float(getattr(p, key))
            if np.isfinite(value):
                names.append(name)
                contexts.append({"l": "Left", "r": "Right"}[p.side])
                units.append(unit)
                values.append(value)
    return {"ANALYSIS": {"USED": np.array([len(names)]), "NAMES": names,
                         "DESCRIPTIONS": [""] * len(names) if names else [],
                         "SUBJECTS": [subject] * len(names) if names else [],
                         "CONTEXTS": contexts, "UNITS": units,
                         "VALUES": np.array(values, dtype=float)}} if names else {}


def outputs_table(times: np.ndarray, outputs: list[tuple[str, str, np.ndarray]]):
    """The outputs as a tidy pandas DataFrame.

    Columns ``frame`` (0-based), ``time`` (s), ``label`` (Vicon's), ``kind`` (ANGLES …),
    ``component`` (X, Y, Z), ``value`` and ``unit`` (degrees, N·mm/kg, W/kg, N/kg);
    rows where the value is missing are left out; a power's X and Y (always 0) too.
    """
    from mocap.errors import import_pandas

    pandas = import_pandas()
    frames = np.arange(len(times))
    parts = []
    for label, kind, values in outputs:
        components = ("Z",) if kind == "POWERS" else ("X", "Y", "Z")
        for component in components:
            column = values[:, "XYZ".index(component)]
            keep = np.isfinite(column)
            parts.append(pandas.DataFrame({
                "frame": frames[keep], "time": np.asarray(times)[keep], "label": label,
                "kind": kind, "component": component, "value": column[keep],
                "unit": UNITS[kind][1]}))
    columns = ["frame", "time", "label", "kind", "component", "value", "unit"]
    if not parts:
        return pandas.DataFrame(columns=columns)
    return pandas.concat(parts, ignore_index=True)[columns]


def write_outputs_csv(path, times: np.ndarray, outputs: list[tuple[str, str, np.ndarray]]
                      ) -> None:
    """:func:`outputs_table` written as CSV (all-or-nothing), without pandas."""
    import csv
    from itertools import repeat

    from mocap.atomic import atomic_path

    times = np.asarray(times, dtype=float)
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["frame", "time", "label", "kind", "component", "value", "unit"])
        for label, kind, values in outputs:
            unit = UNITS[kind][1]
            for component in (("Z",) if kind == "POWERS" else ("X", "Y", "Z")):
                column = values[:, "XYZ".index(component)]
                frames = np.flatnonzero(np.isfinite(column))
                # rows built in C (zip, map): no per-frame Python loop
                writer.writerows(zip(frames.tolist(), map(repr, times[frames].tolist()),
                                     repeat(label), repeat(kind), repeat(component),
                                     map(repr, column[frames].tolist()), repeat(unit)))


__all__ = ["UNITS", "analysis_group", "model_outputs", "outputs_table", "kinetic_label",
           "write_outputs_csv"]
