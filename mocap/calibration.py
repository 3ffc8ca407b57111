"""Static calibration of the Plug-in Gait lower body, vectorised over frames.

A static trial (the subject standing still, the same markers as the walks)
fixes what a walk cannot tell:

* subject measurements Plug-in Gait estimates when they were not measured:
  the inter-ASIS distance (the median ``|LASI - RASI|``), the leg lengths
  (the median distance from each ASIS to the lateral malleolus marker plus
  the marker radius, standing: the clinical measure runs ASIS → medial
  malleolus, whose height matches the lateral one's), knee and ankle widths
  from medial knee / malleolus markers when the static has them;
* the tibial torsion from medial malleolus markers (LMED/RMED or LMMA/RMMA):
  the angle about the shank's long axis between the knee flexion axis and the
  malleolar axis, when the subject file gives none;
* the foot's offsets: the rotation from the uncorrected foot (toe → ankle
  joint centre, see :mod:`mocap.plugingait`) to the foot along heel → toe,
  as Plug-in Gait's StaticPlantFlex and StaticRotOff (the mean over the
  static's frames of the first two YXZ angles of that rotation).  With
  ``flat_foot`` the heel is taken at the toe's height (the sole on the floor).

Everything is computed from the static's complete frames only; nothing a gap
fill does in a walk can change it.  The result is a :class:`~mocap.plugingait.Subject`
with ``calibrated = True``.
"""
from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from mocap.errors import MocapError
from mocap.markersets.model import MissingMarkerWarning
from mocap.plugingait import (MARKERS, SIDES, Subject,
                              anatomical_foot_frame, kinematics, markers_from_trial,
                              subject_from_trial, yxz_angles, _unit)
from mocap.trial import Trial

#: Medial marker names accepted for knee width and tibial torsion, per side letter.
MEDIAL_KNEE = ("{S}KNM", "{S}MKN", "{S}MFC", "{S}KNEM")
MEDIAL_ANKLE = ("{S}MED", "{S}MMA", "{S}MMAL", "{S}ANKM")


def _first_present(markers: dict, patterns: tuple[str, ...], side: str) -> np.ndarray | None:
    for pattern in patterns:
        value = markers.get(pattern.format(S=side.upper()))
        if value is not None:
            return value
    return None


def _median_distance(a: np.ndarray, b: np.ndarray) -> float | None:
    d = np.linalg.norm(a - b, axis=1)
    d = d[np.isfinite(d)]
    return float(np.median(d)) if d.size else None


def static_markers(static: Trial) -> dict:
    """Marker arrays (millimetres) of the static, with medial markers if present."""
    names = MARKERS + tuple(p.format(S=S) for p in MEDIAL_KNEE + MEDIAL_ANKLE
                            for S in "LR")
    markers, _ = markers_from_trial(static, names)
    return markers


def calibrate(static: Trial, subject: Subject | None = None, *, flat_foot: bool = False,
              sole_delta: float = 0.0) -> Subject:
    """A calibrated :class:`Subject` from a static trial.

    Parameters
    ----------
    static : Trial
        The standing trial (points in metres).  Its C3D PROCESSING group,
        when present, supplies the measured values (leg length, knee and
        ankle widths, marker diameter, tibial torsion, wand rotations).
    subject : Subject, optional
        Measurements to use instead (values not None win over the file's).
    flat_foot : bool
        Plug-in Gait's "foot flat" option: the static foot's long axis is
        horizontal.
    sole_delta : float
        Millimetres of sole under the heel with ``flat_foot`` (shoes).

    Returns
    -------
    Subject
        With ``static_plantar_flexion``, ``static_rotation_offset`` (radians,
        Plug-in Gait's signs) and the estimated measurements filled in.

    Raises
    ------
    MocapError
        The static lacks the pelvis, knee, ankle or foot markers, or the knee
        / ankle widths are neither given nor measurable.
    """
    path = static.path
    base = subject_from_trial(static) if subject is None else subject
    sub = replace(base, leg_length=dict(base.leg_length),
                  knee_width=dict(base.knee_width), ankle_width=dict(base.ankle_width),
                  tibial_torsion=dict(base.tibial_torsion),
                  static_plantar_flexion={"l": None, "r": None},
                  static_rotation_offset={"l": None, "r": None})
    m = static_markers(static)
    needed = [n for n in ("LASI", "RASI", "LKNE", "RKNE", "LTHI", "RTHI", "LTIB", "RTIB",
                          "LANK", "RANK", "LTOE", "RTOE", "LHEE", "RHEE") if n not in m]
    if needed:
        raise MocapError(f"static trial lacks marker(s) with data: {', '.join(needed)} "
                         f"(a Plug-in Gait static needs the pelvis, both legs and feet)",
                         path)
    if "SACR" not in m and not ("LPSI" in m and "RPSI" in m):
        raise MocapError("static trial has neither SACR nor LPSI and RPSI with data", path)
    if sub.inter_asis is None:
        sub.inter_asis = _median_distance(m["LASI"], m["RASI"])
    for side in SIDES:
        S = side.upper()
        if sub.leg_length[side] is None:
            leg = _median_distance(m[f"{S}ASI"], m[f"{S}ANK"])
            sub.leg_length[side] = None if leg is None else leg + sub.radius
        for key, patterns, lateral in (("knee_width", MEDIAL_KNEE, "KNE"),
                                       ("ankle_width", MEDIAL_ANKLE, "ANK")):
            if getattr(sub, key)[side] is None:
                medial = _first_present(m, patterns, side)
                if medial is None:
                    raise MocapError(
                        f"{S} {key.replace('_', ' ')} unknown: give it (millimetres) or "
                        f"record medial markers in the static", path)
                # marker centre to centre, less one diameter = skin to skin
                getattr(sub, key)[side] = _median_distance(
                    m[f"{S}{lateral}"], medial) - sub.marker_diameter
    sub.static_plantar_flexion = {"l": 0.0, "r": 0.0}
    sub.static_rotation_offset = {"l": 0.0, "r": 0.0}
    sub.calibrated = False
    kin = kinematics(m, sub, path)
    for side in SIDES:
        S = side.upper()
        medial = _first_present(m, MEDIAL_ANKLE, side)
        if medial is not None and not base.tibial_torsion[side]:
            sub.tibial_torsion[side] = _tibial_torsion(kin, m, medial, side)
    if any(sub.tibial_torsion[s] != base.tibial_torsion[s] for s in SIDES):
        kin = kinematics(m, sub, path)
    for side in SIDES:
        S = side.upper()
        tibia = kin.frames[f"{side}_tibia"]
        uncorrected = kin.frames[f"{side}_foot_uncorrected"]
        anatomical = anatomical_foot_frame(m[f"{S}TOE"], m[f"{S}HEE"], tibia[..., 1],
                                           kin.centres[f"{side}_ankle"], flat_foot,
                                           sole_delta)
        angles = np.radians(yxz_angles(uncorrected, anatomical))     # (frames, 3)
        angles = angles[np.isfinite(angles).all(axis=1)]
        if not len(angles):
            raise MocapError(f"static trial: no frame with every {S} leg and foot marker",
                             path)
        b, a = angles[:, 0].mean(), angles[:, 1].mean()
        sub.static_plantar_flexion[side] = float(-b)
        sub.static_rotation_offset[side] = float(a if side == "r" else -a)
    sub.calibrated = True
    return sub


def _tibial_torsion(kin, markers: dict, medial: np.ndarray, side: str) -> float:
    """Angle (radians) about the shank axis from the knee flexion axis to the
    malleolar axis (lateral → medial malleolus), Plug-in Gait's sign."""
    S = side.upper()
    shank = kin.frames[f"{side}_shank"]
    thigh = kin.frames[f"{side}_thigh"]
    z = shank[..., 2]
    malleolar = markers[f"{S}ANK"] - medial          # medial → lateral
    if side == "r":
        malleolar = -malleolar                        # towards the left, like y
    knee_axis = thigh[..., 1]
    def flat(v):
        return _unit(v - np.sum(v * z, axis=-1, keepdims=True) * z)
    u, w = flat(knee_axis), flat(malleolar)
    angle = np.arctan2(np.sum(np.cross(u, w) * z, axis=-1), np.sum(u * w, axis=-1))
    angle = angle[np.isfinite(angle)]
    if not angle.size:
        warnings.warn(f"{S}: no static frame gives the tibial torsion; using 0",
                      MissingMarkerWarning, stacklevel=3)
        return 0.0
    # Plug-in Gait's sign is the opposite of this angle's, for both sides: checked
    # against the LTibialTorsion / RTibialTorsion Vicon stored for 7 real statics
    # with medial malleoli (tests/mocap/test_plugingait_vicon.py)
    value = float(np.median(angle))
    return -value if side == "l" else value


def resolve_flat_foot(static: Trial, subject: Subject, flat_foot: bool | str,
                      walk: Trial | None = None) -> bool:
    """The foot-flat option to use; ``"auto"`` recovers a previous run's choice.

    When the walk's (else the static's) PROCESSING group stores Plug-in Gait's
    StaticPlantFlex of both feet (a previous calibration applied to it),
    ``"auto"`` picks the option whose plantar-flexion offsets are nearer those
    stored; without them it is off (Plug-in Gait's default).
    """
    if flat_foot in (True, False):
        return bool(flat_foot)
    if flat_foot != "auto":
        raise ValueError(f"flat_foot must be True, False or 'auto', not {flat_foot!r}")
    stored = {"l": None}
    for source in ((walk,) if walk is not None else ()) + (static,):
        stored = subject_from_trial(source, offsets=True).static_plantar_flexion
        if all(stored[s] is not None for s in SIDES):
            break
    if any(stored.get(s) is None for s in SIDES):
        return False
    error = {}
    for option in (False, True):
        sub = calibrate(static, subject, flat_foot=option)
        error[option] = sum(abs(sub.static_plantar_flexion[s] - stored[s]) for s in SIDES)
    return error[True] < error[False]
