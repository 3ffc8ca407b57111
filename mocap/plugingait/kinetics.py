"""Plug-in Gait kinetics: joint forces, moments and powers of the legs from force plates.

Bottom-up Newton–Euler inverse dynamics on Plug-in Gait's segments (foot, shank, thigh
of each side, the model's joint centres and frames, :mod:`mocap.plugingait.model`) with
its Dempster inertial parameters (:func:`mocap.body.anthropometry.plugingait_segments`):

* foot: ankle joint centre (AJC) → toe marker; shank: knee (KJC) → AJC; thigh: hip
  (HJC) → KJC; mass ``m = fraction × body mass``, centre of mass ``c`` at its fraction
  of the segment from the proximal end, inertia ``m (k L)²`` about the two axes across
  the segment and none about its long axis (``k`` the radius of gyration).
* for each segment, distal to proximal: ``F_p = m (a_c − g) − F_d`` and
  ``M_p = İ α + ω × (I ω) − (p − c) × F_p − (d − c) × F_d − M_d``, where ``F_d, M_d``
  act at the distal end ``d`` (the ground reaction at the centre of pressure with the
  plate's free moment for the foot; the opposite of the next segment's proximal load
  otherwise), ``p`` the proximal joint centre.  ``F_p, M_p`` are the loads the proximal
  segment applies to this one at the joint: the joint's internal force and moment.
* power: ``M_p · (ω_distal − ω_proximal)`` (W), the joint's total power (Vicon's Z
  component of ``<Side><Joint>Power``).
* outputs as Plug-in Gait writes them (:mod:`mocap.plugingait.outputs`): moments and
  forces in the distal segment's axes (the thigh, the torsioned tibia, the
  static-corrected foot: :data:`DISTAL_FRAME`) with Vicon's order and signs
  (:data:`MOMENT_AXES`, :data:`FORCE_AXES`); moments in N·mm per kg of body mass, forces
  in N/kg, powers in W/kg.
* the inertias scale with the static's segment lengths (:func:`segment_lengths`), and
  the radii of gyration are Dempster's about the proximal end applied about the centre of
  mass (``data/bodies/plugingait-dempster.toml``): what reproduces Vicon's stored values
  (``benchmarks/plugingait_choices.py``, design subjects only).

Velocities and accelerations are central differences of the positions and rotations
(the markers are used as they are: filter them first as Vicon's pipeline does).
Frames where a foot is on the ground and no plate measures its reaction (a stance off
the plates, on a plate shared with the other foot, or partly off its plate:
:func:`mocap.io.c3d.stances.assign_plates`) have no kinetics for that side (NaN);
Vicon leaves some such off-plate stances computed as if the foot were in the air.

Units inside: metres, seconds, newtons, N·m (like ``Trial.points``).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from mocap.body.anthropometry import plugingait_segments
from mocap.errors import MocapError, MocapWarning
from mocap.plugingait.model import (MARKERS, SIDES, Kinematics, Subject, kinematics,
                                    markers_from_trial)
from mocap.trial import Trial

#: Standard gravity, m/s², along the lab's −Z (Plug-in Gait's labs are Z up).
GRAVITY = 9.80665
#: Joints of the kinetic output, in column order per side.
KINETIC_JOINTS = ("hip", "knee", "ankle")


class KineticsWarning(MocapWarning):
    """Kinetics skipped or left out on some frames (no plates, a foot off its plate)."""


@dataclass
class JointKinetics:
    """Joint kinetics of one trial, Plug-in Gait's outputs per side and joint.

    Attributes
    ----------
    times : ndarray (frames,), seconds
    segments : list of str
        ``l_hip, l_knee, l_ankle, r_hip, r_knee, r_ankle``.
    moments : ndarray (frames, 6, 3), N·mm/kg
        Vicon's X, Y, Z of ``<Side><Joint>Moment``: internal moments in the distal
        segment's axes (sagittal, frontal, transverse) with Plug-in Gait's signs.
    powers : ndarray (frames, 6), W/kg
        Total joint power (Vicon's Z of ``<Side><Joint>Power``).
    forces : ndarray (frames, 6, 3), N/kg
        Joint reaction force in the distal segment's axes (``<Side><Joint>Force``).
    ground : ndarray (frames, 2, 3), N/kg
        Ground reaction force on each foot, lab axes (``<Side>GroundReactionForce``).
    body_mass : float, kg
    notes : list of str
        Stances left out and why.
    """

    times: np.ndarray
    segments: list
    moments: np.ndarray
    powers: np.ndarray
    forces: np.ndarray
    ground: np.ndarray
    body_mass: float
    notes: list = field(default_factory=list)

    def segment(self, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(moment (frames, 3), power (frames,), force (frames, 3)) of ``l_hip`` …"""
        k = self.segments.index(name)
        return self.moments[:, k], self.powers[:, k], self.forces[:, k]


def _derivative(values: np.ndarray, rate: float) -> np.ndarray:
    """Central differences along frames (one-sided at the ends), per second."""
    if values.shape[0] < 2:
        return np.full_like(values, np.nan)
    return np.gradient(values, 1.0 / rate, axis=0)


def angular_velocity(rotation: np.ndarray, rate: float) -> np.ndarray:
    """Angular velocity (frames, 3), rad/s, lab axes, of rotations (frames, 3, 3).

    The axial vector of ``Ṙ Rᵀ``, ``Ṙ`` by central differences.
    """
    spin = np.einsum("fij,fkj->fik", _derivative(rotation, rate), rotation)
    skew = 0.5 * (spin - np.swapaxes(spin, 1, 2))
    return np.stack([skew[:, 2, 1], skew[:, 0, 2], skew[:, 1, 0]], axis=1)


@dataclass
class GroundReaction:
    """One foot's measured ground reaction at marker frames (NaN where none).

    Attributes
    ----------
    force : ndarray (frames, 3), N, lab axes
    cop : ndarray (frames, 3), m
    free_moment : ndarray (frames, 3), N·m
    unknown : ndarray (frames,), bool
        Frames where the foot is loaded and no plate measures it (no kinetics).
    """

    force: np.ndarray
    cop: np.ndarray
    free_moment: np.ndarray
    unknown: np.ndarray


def _segment_loads(start: np.ndarray, com: np.ndarray, length: np.ndarray,
                   rotation: np.ndarray, mass: float, radius: float, rate: float,
                   distal_point: np.ndarray, distal_force: np.ndarray,
                   distal_moment: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Force and moment (lab axes, N, N·m) the proximal segment applies at ``start``.

    ``start``, ``end`` the proximal and distal ends (frames, 3); ``rotation`` the
    segment's frame (frames, 3, 3) with z along it; ``distal_*`` the load applied to it
    at ``distal_point``.  Returns (force, moment about ``start``, angular velocity).
    """
    acceleration = _derivative(_derivative(com, rate), rate)
    gravity = np.array([0.0, 0.0, -GRAVITY])
    force = mass * (acceleration - gravity) - distal_force
    omega = angular_velocity(rotation, rate)
    alpha = _derivative(omega, rate)
    transverse = mass * (radius * length) ** 2                      # (frames,)
    local = np.zeros(rotation.shape)
    local[:, 0, 0] = local[:, 1, 1] = transverse
    inertia = rotation @ local @ np.swapaxes(rotation, 1, 2)         # lab axes
    spin = np.einsum("fij,fj->fi", inertia, alpha) + np.cross(
        omega, np.einsum("fij,fj->fi", inertia, omega))
    moment = (spin - np.cross(start - com, force) - np.cross(distal_point - com, distal_force)
              - distal_moment)
    return force, moment, omega


def lab_kinetics(kin: Kinematics, ground: dict, body_mass: float, rate: float,
                 lengths: dict | None = None, table: dict | None = None) -> dict:
    """Internal joint loads and powers of both legs, lab axes.

    Parameters
    ----------
    kin : Kinematics
        Joint centres and frames (:func:`mocap.plugingait.model.kinematics`).
    ground : dict side -> GroundReaction
        NaN force while the foot is in the air counts as no load.
    body_mass : float, kg
    rate : float, Hz
    lengths : dict, optional
        ``"l_thigh"``, ``"l_shank"``, ``"l_foot"`` … -> metres: the segment lengths the
        inertias scale with (:func:`segment_lengths`); default each frame's joint-centre
        distance.
    table : dict, optional
        ``thigh``, ``shank``, ``foot`` -> DempsterSegment; default
        :func:`mocap.body.anthropometry.plugingait_segments`.

    Returns
    -------
    dict ``"l_hip"`` … -> (force (frames, 3) N, moment (frames, 3) N·m, power (frames,) W),
    NaN on frames the side's reaction is unknown; a side whose segments are missing is
    left out.
    """
    table = plugingait_segments() if table is None else table
    lengths = lengths or {}
    out = {}
    pelvis_omega = angular_velocity(kin.frames["pelvis"], rate)
    for side in SIDES:
        need = [f"{side}_{n}" for n in ("hip", "knee", "ankle", "toe")]
        if not all(n in kin.centres for n in need) or f"{side}_foot" not in kin.frames:
            continue
        hip, knee, ankle, toe = (kin.centres[n] for n in need)
        reaction = ground[side]
        loaded = np.isfinite(reaction.force).all(axis=1)
        force = np.where(loaded[:, None], reaction.force, 0.0)
        point = np.where(loaded[:, None], reaction.cop, ankle)
        moment = np.where(loaded[:, None], np.nan_to_num(reaction.free_moment), 0.0)
        chain = (("ankle", ankle, toe, kin.frames[f"{side}_foot"], "foot"),
                 ("knee", knee, ankle, kin.frames[f"{side}_shank"], "shank"),
                 ("hip", hip, knee, kin.frames[f"{side}_thigh"], "thigh"))
        omegas, loads = [], []
        for joint, start, end, rotation, kind in chain:
            part = table[kind]
            length = lengths.get(f"{side}_{kind}")
            length = np.linalg.norm(end - start, axis=1) if length is None else \
                np.full(len(start), float(length))
            com = start + part.com_fraction * (end - start)
            f, m, w = _segment_loads(start, com, length, rotation,
                                     part.mass_fraction * body_mass,
                                     part.radius_of_gyration, rate, point, force, moment)
            loads.append((joint, f, m))
            omegas.append(w)
            point, force, moment = start, -f, -m
        omegas.append(pelvis_omega)
        bad = reaction.unknown
        for k, (joint, f, m) in enumerate(loads):
            power = np.sum(m * (omegas[k] - omegas[k + 1]), axis=1)
            out[f"{side}_{joint}"] = (np.where(bad[:, None], np.nan, f),
                                      np.where(bad[:, None], np.nan, m),
                                      np.where(bad, np.nan, power))
    return out


#: Vicon's components of each output from the distal frame's axes: (axis, sign) for X, Y, Z
#: per (joint, side).  Moments and forces in the distal segment's axes (the torsioned
#: tibia for the knee, the static-corrected foot for the ankle), as Plug-in Gait writes
#: them; chosen on the design files (benchmarks/plugingait_choices.py).
MOMENT_AXES = {
    ("hip", "l"): ((1, 1), (0, 1), (2, 1)), ("hip", "r"): ((1, 1), (0, -1), (2, -1)),
    ("knee", "l"): ((1, -1), (0, 1), (2, 1)), ("knee", "r"): ((1, -1), (0, -1), (2, -1)),
    ("ankle", "l"): ((1, 1), (2, -1), (0, 1)), ("ankle", "r"): ((1, 1), (2, 1), (0, -1)),
}
FORCE_AXES = {
    "hip": ((0, 1), (1, 1), (2, 1)), "knee": ((0, 1), (1, 1), (2, 1)),
    "ankle": ((0, -1), (1, 1), (2, -1)),
}
#: The distal frame each joint's outputs are expressed in (Kinematics.frames names).
DISTAL_FRAME = {"hip": "thigh", "knee": "tibia", "ankle": "foot"}


def _components(rotation: np.ndarray, vector: np.ndarray, axes) -> np.ndarray:
    """``vector`` (frames, 3) in ``rotation``'s axes, reordered and signed, (frames, 3)."""
    local = np.einsum("fji,fj->fi", rotation, vector)
    return np.stack([sign * local[:, axis] for axis, sign in axes], axis=1)


def segment_lengths(kin: Kinematics, subject_trial: Trial | None = None,
                    static_kin: Kinematics | None = None, static_markers: dict | None = None,
                    radius: float = 0.007) -> dict:
    """Lengths (metres) the segments' inertias scale with, as Plug-in Gait takes them.

    Femur |HJC − KJC|, tibia |KJC − AJC| and foot |HEE − TOE| minus the marker radius,
    averaged over the static trial (Vicon's PROCESSING FemurLength, TibiaLength,
    FootLength equal these); without a static, the PROCESSING values of
    ``subject_trial``; else the walk's median joint-centre distances (the foot's
    |AJC − TOE|).
    """
    out: dict[str, float] = {}
    group = {} if subject_trial is None else {
        str(k).upper(): v for k, v in (subject_trial.parameters.get("PROCESSING") or {}).items()}
    for side in SIDES:
        S = side.upper()
        pairs = {"thigh": ("hip", "knee", "FEMURLENGTH"), "shank": ("knee", "ankle", "TIBIALENGTH"),
                 "foot": ("ankle", "toe", "FOOTLENGTH")}
        for kind, (a, b, key) in pairs.items():
            value = None
            if static_kin is not None:
                if kind == "foot":
                    m = static_markers or {}
                    if f"{S}HEE" in m and f"{S}TOE" in m:
                        d = np.linalg.norm(m[f"{S}HEE"] - m[f"{S}TOE"], axis=1)
                        value = float(np.nanmean(d)) - radius
                elif f"{side}_{a}" in static_kin.centres and f"{side}_{b}" in static_kin.centres:
                    value = float(np.nanmean(np.linalg.norm(
                        static_kin.centres[f"{side}_{a}"] - static_kin.centres[f"{side}_{b}"],
                        axis=1)))
            if (value is None or not np.isfinite(value)) and S + key in group:
                try:
                    stored = float(np.ravel(group[S + key])[0])
                except (TypeError, ValueError, IndexError):
                    stored = None
                value = stored * 1e-3 if stored else None
            if (value is None or not np.isfinite(value)) and f"{side}_{a}" in kin.centres \
                    and f"{side}_{b}" in kin.centres:
                value = float(np.nanmedian(np.linalg.norm(
                    kin.centres[f"{side}_{a}"] - kin.centres[f"{side}_{b}"], axis=1)))
            if value is not None and np.isfinite(value):
                out[f"{side}_{kind}"] = value
    return out


#: Frames at each end where the second differences are one-sided: no kinetics there.
EDGE_FRAMES = 2


def body_mass_of(trial: Trial, static: Trial | None = None) -> float | None:
    """Body mass (kg) from the static's, else the walk's PROCESSING Bodymass (as the other
    subject measurements, :func:`~mocap.plugingait.clinical.prepare_subject`); None if
    absent."""
    for source in (static, trial):
        if source is None:
            continue
        group = {str(k).upper(): v for k, v in (source.parameters.get("PROCESSING") or {}).items()}
        try:
            value = float(np.ravel(group["BODYMASS"])[0])
        except (KeyError, TypeError, ValueError, IndexError):
            continue
        if np.isfinite(value) and value > 0:
            return value
    return None


def _contacts(trial: Trial, side: str, events: list) -> list[tuple[int, int]]:
    """The side's stances (first frame, stop frame) from gait events (GaitEvent list)."""
    from mocap.plugingait.events import FOOT_OFF, FOOT_STRIKE

    events = sorted({(int(round(e.frame)), e.label) for e in events if e.side == side})
    out, start = [], None
    for k, (frame, label) in enumerate(events):
        if label == FOOT_STRIKE:
            start = frame if start is None else start
        elif label == FOOT_OFF:
            first = 0 if start is None and k == 0 else start
            if first is not None:
                out.append((first, frame + 1))
            start = None
    if start is not None:
        out.append((start, trial.frames))
    return out


def ground_reactions(trial: Trial, kin: Kinematics) -> tuple[dict, list[str]]:
    """Each foot's measured ground reaction and the frames it is unknown, with notes.

    Plates go to feet by :func:`mocap.io.c3d.stances.assign_plates`; a foot's stance
    (from the events, the file's and detected) that no clean plate stretch measures has
    no kinetics; so has an unclean stretch.
    """
    from mocap.io.c3d.forceplates import plate_forces
    from mocap.io.c3d.stances import assign_plates
    from mocap.plugingait.events import detect_events, events_from_file

    frames = trial.frames
    events = events_from_file(trial) + detect_events(trial)
    plates = [p for p in plate_forces(trial, rate="marker") if not p.plate.problem]
    markers, _ = markers_from_trial(trial, ("LHEE", "LTOE", "RHEE", "RTOE"))
    feet = {side: (markers[f"{side.upper()}HEE"], markers[f"{side.upper()}TOE"])
            for side in SIDES if f"{side.upper()}HEE" in markers
            and f"{side.upper()}TOE" in markers}
    stances = assign_plates(plates, feet) if feet else []
    by_index = {p.plate.index: p for p in plates}
    notes: list[str] = []
    out = {}
    for side in SIDES:
        force = np.full((frames, 3), np.nan)
        cop, free = force.copy(), force.copy()
        unknown = np.zeros(frames, dtype=bool)
        measured = np.zeros(frames, dtype=bool)
        for stance in (s for s in stances if s.side == side):
            span = slice(stance.start, stance.stop)
            if stance.clean:
                plate = by_index[stance.plate]
                force[span], cop[span] = plate.force[span], plate.cop[span]
                free[span] = plate.free_moment[span]
                measured[span] = True
            else:
                unknown[span] = True
                notes.append(f"{side.upper()} foot {stance.reason} (plate {stance.plate + 1}, "
                             f"frames {stance.start + 1}-{stance.stop}): no "
                             f"{'left' if side == 'l' else 'right'} kinetics on that stance")
        for start, stop in _contacts(trial, side, events):
            if not measured[start:stop].any():
                unknown[start:stop] = True
        unknown &= ~measured
        out[side] = GroundReaction(force, cop, free, unknown)
    return out, notes


def plugingait_kinetics(trial: Trial, subject: Subject | None = None, *,
                        static: Trial | None = None, body_mass: float | None = None,
                        flat_foot: bool | str = "auto",
                        walk_kinematics: Kinematics | None = None) -> JointKinetics:
    """Plug-in Gait joint moments, powers and forces of a walk on force plates.

    Parameters
    ----------
    trial : Trial
        The walk (a C3D with FORCE_PLATFORM and analogs); points in metres.
    subject : Subject, optional
        As :func:`mocap.plugingait.clinical.prepare_subject` gives it; default from the
        walk, the static and estimates (with their warnings).
    static : Trial, optional
        Calibrates the feet and gives the segment lengths (:func:`segment_lengths`).
    body_mass : float, optional
        kg; default PROCESSING Bodymass of the static, then the walk.
    flat_foot : bool or "auto"
        As :func:`mocap.plugingait.clinical.plugingait_angles`.
    walk_kinematics : Kinematics, optional
        The walk's :func:`~mocap.plugingait.model.kinematics` with ``subject``, when the
        caller has it already; default computed here.

    Returns
    -------
    JointKinetics

    Raises
    ------
    MocapError
        No force plates, no body mass, or markers the model needs are missing.
    """
    from mocap.io.c3d.forceplates import force_plates
    from mocap.plugingait.clinical import prepare_subject

    path = trial.path
    if not [p for p in force_plates(trial) if not p.problem]:
        raise MocapError("no force plates: kinetics skipped", path)
    mass = body_mass if body_mass is not None else body_mass_of(trial, static)
    if mass is None:
        raise MocapError("no body mass (PROCESSING Bodymass; give --body-mass): kinetics "
                         "skipped", path)
    if not (np.isfinite(mass) and 0 < mass < 500):
        raise MocapError(f"body mass {mass:g} kg is not a body's (0-500 kg)", path)
    if subject is None:
        subject = prepare_subject(trial, static=static, flat_foot=flat_foot)
    kin = walk_kinematics
    if kin is None:
        kin = kinematics(markers_from_trial(trial, MARKERS)[0], subject, path)
    static_kin = static_markers = None
    if static is not None:
        static_markers, _ = markers_from_trial(static, MARKERS)
        try:
            static_kin = kinematics(static_markers, subject, static.path)
        except MocapError:
            static_kin = None
    lengths = segment_lengths(kin, trial if static is None else static, static_kin,
                              static_markers, subject.radius)
    ground, notes = ground_reactions(trial, kin)
    loads = lab_kinetics(kin, ground, mass, trial.rate, lengths)
    frames = trial.frames
    segments = [f"{side}_{joint}" for side in SIDES for joint in KINETIC_JOINTS]
    moments = np.full((frames, len(segments), 3), np.nan)
    forces = np.full_like(moments, np.nan)
    powers = np.full((frames, len(segments)), np.nan)
    for k, name in enumerate(segments):
        side, joint = name.split("_")
        if name not in loads:
            notes.append(f"{side.upper()}: no {joint} kinetics (markers missing)")
            continue
        f, m, p = loads[name]
        rotation = kin.frames[f"{side}_{DISTAL_FRAME[joint]}"]
        moments[:, k] = _components(rotation, m, MOMENT_AXES[(joint, side)]) * 1000.0 / mass
        forces[:, k] = _components(rotation, f, FORCE_AXES[joint]) / mass
        powers[:, k] = p / mass
    edge = min(EDGE_FRAMES, frames)
    for array in (moments, forces, powers):
        array[:edge] = np.nan
        array[frames - edge:] = np.nan
    ground_out = np.stack([ground[s].force for s in SIDES], axis=1) / mass
    for note in notes:
        warnings.warn(f"{path or 'trial'}: {note}", KineticsWarning, stacklevel=2)
    return JointKinetics(trial.times, segments, moments, powers, forces, ground_out, mass,
                         notes)


__all__ = ["GRAVITY", "GroundReaction", "JointKinetics", "KINETIC_JOINTS", "KineticsWarning",
           "angular_velocity", "body_mass_of", "ground_reactions", "lab_kinetics",
           "plugingait_kinetics", "segment_lengths"]
