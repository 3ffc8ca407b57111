"""Ground reactions for OpenSim's inverse dynamics: a ``.mot`` of forces and the
ExternalLoads XML that applies them.

OpenSim's external-loads storage has, per applied force, nine columns: the force
``<p>ground_force_vx, vy, vz`` (N), its point of application ``<p>ground_force_px, py, pz``
(m) and a torque ``<p>ground_torque_x, y, z`` (N·m), all in the ground frame (Y up, X
anterior, Z right: the lab turned as ``mocap convert --up y`` turns the markers). The
ExternalLoads XML names, per force, the body it acts on and these column prefixes.

Here the point is the centre of pressure and the torque the free moment about it
(:mod:`mocap.io.c3d.forceplates`). Each plate's reaction goes to the foot that stands on it
(:func:`assign_feet`: the foot whose heel–toe midpoint is nearest the centre of pressure
while the plate is loaded); the plates of one foot are added (:func:`total_forces`), and the
prefixes are ``r_`` and ``l_`` (bodies ``calcn_r``, ``calcn_l`` of gait2392 and Rajagopal).
Without foot markers the plates are written one by one (``plate1_`` …). Below the loading
threshold a plate's force, point and torque are written 0 (its noise would otherwise act at
an undefined point). Times are the trial's own clock (:meth:`mocap.trial.Trial.time_base`),
as in its TRC and coordinates ``.mot``.
"""
from __future__ import annotations

import os
from pathlib import Path
from xml.sax.saxutils import escape

import numpy as np

from mocap.atomic import atomic_path
from mocap.errors import MocapError
from mocap.io.c3d.forceplates import PlateForces, total_forces
from mocap.io.lab import Z_TO_Y_UP
from mocap.io.mot import write_mot

#: Foot prefix -> (OpenSim body, Plug-in Gait heel and toe markers).
FEET = {"r": ("calcn_r", "RHEE", "RTOE"), "l": ("calcn_l", "LHEE", "LTOE")}


def assign_feet(trial, plates: list[PlateForces]) -> dict[str, list[PlateForces]] | None:
    """Which foot stands on each plate: foot prefix ("r", "l") -> its plates.

    A plate goes to the foot whose heel–toe midpoint is nearest (median over the loaded
    marker frames) its centre of pressure; a plate never loaded, or loaded only while
    neither foot is seen, goes to no foot.

    Parameters
    ----------
    trial : Trial
        The walk the plates belong to; markers ``RHEE``, ``RTOE``, ``LHEE``, ``LTOE``
        (metres, the plates' lab frame).
    plates : list of PlateForces
        At the analog or the marker rate.

    Returns
    -------
    dict or None
        None when the trial lacks a foot's markers.
    """
    try:
        feet = {side: 0.5 * (trial.marker(heel) + trial.marker(toe))   # (frames, 3), m
                for side, (_, heel, toe) in FEET.items()}
    except (KeyError, ValueError, MocapError):
        return None
    result: dict[str, list[PlateForces]] = {side: [] for side in FEET}
    for part in plates:
        # the plate's sample at each marker frame (the analog sample simultaneous with it)
        index = np.minimum((np.arange(trial.frames) * part.rate / trial.rate).round()
                           .astype(int), part.samples - 1)
        cop = part.cop[index]                                            # (frames, 3)
        distance = {side: np.linalg.norm((cop - foot)[:, :2], axis=1)
                    for side, foot in feet.items()}
        seen = np.isfinite(distance["r"]) & np.isfinite(distance["l"])
        if not seen.any():
            continue
        nearest = min(distance, key=lambda side: np.median(distance[side][seen]))
        result[nearest].append(part)
    return result


def ground_reaction_columns(parts: dict[str, PlateForces]
                            ) -> tuple[list[str], np.ndarray]:
    """OpenSim's nine columns per applied force, Y-up ground frame.

    Parameters
    ----------
    parts : dict of str to PlateForces
        Column prefix (``"r_"``, ``"plate1_"`` …) -> reaction in the Z-up lab, all at one
        rate.

    Returns
    -------
    labels : list of str
        ``<p>ground_force_vx`` … ``<p>ground_force_pz``, ``<p>ground_torque_x`` … per
        prefix, in that order.
    values : ndarray, shape (samples, 9 * len(parts))
        N, m, N·m; 0 where a force is below the loading threshold (no centre of pressure).
    """
    labels, columns = [], []
    for prefix, part in parts.items():
        loaded = np.isfinite(part.cop).all(axis=1)[:, None]
        for name, quantity in (("ground_force_v", part.force), ("ground_force_p", part.cop),
                               ("ground_torque_", part.free_moment)):
            labels += [f"{prefix}{name}{axis}" for axis in "xyz"]
            columns.append(np.where(loaded, quantity @ Z_TO_Y_UP.T, 0.0))
    return labels, np.concatenate(columns, axis=1)


def foot_reactions(trial, plates: list[PlateForces]) -> tuple[dict[str, PlateForces], dict]:
    """The reactions to write, by column prefix, and the body each acts on.

    Returns
    -------
    parts : dict of str to PlateForces
        ``{"r_": …, "l_": …}`` when the feet are known (:func:`assign_feet`; a foot on no
        plate gets zeros), else ``{"plate1_": …, …}``.
    bodies : dict of str to str
        Prefix -> OpenSim body (``calcn_r``, ``calcn_l``); empty for plates.
    """
    usable = [p for p in plates if p.plate is None or not p.plate.problem]
    feet = assign_feet(trial, usable)
    if feet is None:
        return {f"plate{p.plate.index + 1}_": p for p in usable}, {}
    parts, bodies = {}, {}
    for side, own in feet.items():
        if own:
            part = total_forces(own)
        else:
            zero = np.zeros_like(usable[0].force)
            part = PlateForces(usable[0].rate, zero, zero, np.full_like(zero, np.nan), zero)
        parts[f"{side}_"] = part
        bodies[f"{side}_"] = FEET[side][0]
    return parts, bodies


def write_grf_mot(path: str | os.PathLike, parts: dict[str, PlateForces],
                  start_time: float = 0.0) -> None:
    """Write ground reactions as OpenSim's external-loads ``.mot`` (all-or-nothing).

    Parameters
    ----------
    path : str or PathLike
    parts : dict of str to PlateForces
        Column prefix -> reaction (:func:`foot_reactions`), Z-up lab, one rate.
    start_time : float, seconds
        Time of the first sample: the trial's first frame
        (``trial.time_base()[1][0]``), so the file lines up with the trial's TRC.
    """
    labels, values = ground_reaction_columns(parts)
    times = start_time + next(iter(parts.values())).times
    write_mot(path, times, labels, values, in_degrees=False,
              name=Path(os.fspath(path)).stem)


def write_external_loads(path: str | os.PathLike, datafile: str | os.PathLike,
                         bodies: dict[str, str]) -> None:
    """Write the ExternalLoads XML that applies a :func:`write_grf_mot` file.

    Parameters
    ----------
    path : str or PathLike
        The ``.xml`` file.
    datafile : str or PathLike
        The ground-reaction ``.mot``; written relative to the XML's folder when it is
        inside it (OpenSim reads it from there), else absolute.
    bodies : dict of str to str
        Column prefix -> body the force acts on (``{"r_": "calcn_r", …}``).
    """
    if not bodies:
        raise MocapError("the ground reactions are not assigned to feet (the trial lacks "
                         "RHEE, RTOE, LHEE or LTOE), so no body can receive them", path)
    folder = Path(os.fspath(path)).resolve().parent
    data = Path(os.fspath(datafile)).resolve()
    reference = data.relative_to(folder) if data.is_relative_to(folder) else data
    forces = "".join(
        f'\n      <ExternalForce name="{escape(body)}_grf">'
        f"\n        <applied_to_body>{escape(body)}</applied_to_body>"
        "\n        <force_expressed_in_body>ground</force_expressed_in_body>"
        "\n        <point_expressed_in_body>ground</point_expressed_in_body>"
        f"\n        <force_identifier>{escape(prefix)}ground_force_v</force_identifier>"
        f"\n        <point_identifier>{escape(prefix)}ground_force_p</point_identifier>"
        f"\n        <torque_identifier>{escape(prefix)}ground_torque_</torque_identifier>"
        "\n      </ExternalForce>" for prefix, body in bodies.items())
    document = ('<?xml version="1.0" encoding="UTF-8" ?>\n<OpenSimDocument Version="40000">'
                '\n  <ExternalLoads name="externalloads">\n    <objects>' + forces
                + "\n    </objects>\n    <groups />"
                f"\n    <datafile>{escape(reference.as_posix())}</datafile>"
                "\n  </ExternalLoads>\n</OpenSimDocument>\n")
    with atomic_path(path) as tmp:
        tmp.write_text(document, encoding="utf-8")
