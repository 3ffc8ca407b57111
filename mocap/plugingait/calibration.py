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
  joint centre, see :mod:`mocap.plugingait.model`) to the foot along heel → toe,
  as Plug-in Gait's StaticPlantFlex and StaticRotOff (the mean over the
  static's frames of the first two YXZ angles of that rotation).  With
  ``flat_foot`` the heel is taken at the toe's height (the sole on the floor);
* a knee alignment device (KAD: markers {S}KAX, {S}KD1, {S}KD2 with data):
  the virtual knee marker at the device's corner replaces {S}KNE, the knee
  joint centre lies in the plane of KAX, the hip centre and that marker
  (:func:`kad_virtual_knee`, :func:`kad_thigh_rotation`), and the angle about
  the thigh from the THI wand's plane to it becomes the thigh rotation offset
  the walks use (Plug-in Gait's ThighRotation);
* the shank rotation offset (Plug-in Gait's ShankRotation) with a KAD, or when
  a tibial torsion is known and the subject gives no shank rotation: the ankle
  centre is put where the static's ankle axis (ankle centre → ANK) lies at the
  tibial torsion from the knee flexion axis, as Plug-in Gait does
  (:func:`shank_rotation_for_torsion`; in Vicon's static outputs the
  torsioned tibia's y is parallel to the knee axis, to 0.01° on 5 subjects
  and 0.6° on the other 3).

Everything is computed from the static's complete frames only; nothing a gap
fill does in a walk can change it.  The result is a :class:`~mocap.plugingait.model.Subject`
with ``calibrated = True``.
"""
from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from mocap.errors import MocapError
from mocap.markersets.model import MissingMarkerWarning
from mocap.plugingait.model import (MARKERS, SIDES, Subject, _side_sign,
                              anatomical_foot_frame, chord, hip_joint_centres, kinematics,
                              markers_from_trial, pelvis_frame, rotate_about,
                              subject_from_trial, yxz_angles, _unit)
from mocap.trial import Trial

#: Medial marker names accepted for knee width and tibial torsion, per side letter.
MEDIAL_KNEE = ("{S}KNM", "{S}MKN", "{S}MFC", "{S}KNEM")
MEDIAL_ANKLE = ("{S}MED", "{S}MMA", "{S}MMAL", "{S}ANKM")
#: Knee alignment device markers: the arm along the knee flexion axis, then the two across it.
KAD = ("{S}KAX", "{S}KD1", "{S}KD2")


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


def _about(a: np.ndarray, b: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Signed angle (radians, (frames,)) about unit ``axis`` from ``a`` to ``b``,
    both taken perpendicular to the axis."""
    a = a - np.sum(a * axis, axis=-1, keepdims=True) * axis
    b = b - np.sum(b * axis, axis=-1, keepdims=True) * axis
    return np.arctan2(np.sum(np.cross(a, b) * axis, axis=-1), np.sum(a * b, axis=-1))


def _median_angle(angle: np.ndarray) -> float | None:
    angle = angle[np.isfinite(angle)]
    return float(np.median(angle)) if angle.size else None


def kad_virtual_knee(kax: np.ndarray, kd1: np.ndarray, kd2: np.ndarray,
                     hjc: np.ndarray, ankle: np.ndarray) -> np.ndarray:
    """The corner of a knee alignment device, its virtual knee marker (frames, 3).

    The device's three arms are equally long and mutually perpendicular: KAX
    along the knee flexion axis (laterally), KD1 and KD2 across it.  The
    corner is the apex of the tetrahedron over the markers' triangle, at
    ``s / sqrt(6)`` from the triangle's centroid along its normal (``s`` the
    mean side; pyCGM2's KAD uses the same apex), on the side of
    the leg: the one nearer the line from the hip joint centre to ANK (the
    other lies ``2 s / sqrt(6)`` further out from the knee).

    Parameters
    ----------
    kax, kd1, kd2 : ndarray, shape (frames, 3), metres
    hjc, ankle : ndarray, shape (frames, 3), metres
        The hip joint centre and the lateral malleolus marker (ANK).

    Examples
    --------
    >>> arms = 0.1 * np.eye(3)[None] + [0.0, 0.05, 0.4]   # corner at (0, 0.05, 0.4) m
    >>> leg = np.array([[0.0, 0.0, 0.8]]), np.array([[0.0, 0.04, 0.0]])
    >>> kad_virtual_knee(arms[:, 0], arms[:, 1], arms[:, 2], *leg).round(12) + 0.0
    array([[0.  , 0.05, 0.4 ]])
    """
    centroid = (kax + kd1 + kd2) / 3.0
    side = (np.linalg.norm(kax - kd1, axis=-1) + np.linalg.norm(kax - kd2, axis=-1)
            + np.linalg.norm(kd1 - kd2, axis=-1)) / 3.0
    normal = _unit(np.cross(kd1 - kax, kd2 - kax)) * (side / np.sqrt(6.0))[..., None]
    a, b = centroid + normal, centroid - normal
    leg = _unit(ankle - hjc)

    def off_leg(p: np.ndarray) -> np.ndarray:
        return np.linalg.norm(np.cross(p - hjc, leg), axis=-1)

    return np.where((off_leg(a) <= off_leg(b))[..., None], a, b)


def kad_thigh_rotation(thigh: np.ndarray, hjc: np.ndarray, knee: np.ndarray,
                       kax: np.ndarray, delta: float, side: str) -> tuple[np.ndarray, float]:
    """Knee joint centre and thigh rotation offset from a knee alignment device.

    The centre is Plug-in Gait's chord of (KAX, HJC, virtual knee) at
    ``delta`` (half the knee width plus the marker radius) from the virtual
    knee: the device's wand takes the thigh wand's place.  The offset is the
    angle about the thigh axis (KJC → HJC) from the THI wand's plane to the
    plane of the knee flexion axis (KJC → virtual knee), with Plug-in Gait's
    sign (the ``ThighRotation`` of the PROCESSING group; the chord of a walk
    turns the THI plane by it, :func:`mocap.plugingait.model.kinematics`).

    Parameters
    ----------
    thigh, hjc, knee, kax : ndarray, shape (frames, 3), metres
        THI, the hip joint centre, the virtual knee marker, KAX.
    delta : float
        Millimetres.
    side : {"l", "r"}

    Returns
    -------
    kjc : ndarray, shape (frames, 3), metres
    rotation : float
        Radians, the median over the frames; NaN when no frame gives it.
    """
    kjc = chord(kax, hjc, knee, delta)
    angle = _about(thigh - kjc, knee - kjc, _unit(hjc - kjc))
    value = _median_angle(angle)
    return kjc, np.nan if value is None else _side_sign(side) * value


def shank_rotation_for_torsion(kjc: np.ndarray, tibia: np.ndarray, ankle: np.ndarray,
                               knee_axis: np.ndarray, delta: float, torsion: float,
                               side: str, iterations: int = 8) -> float:
    """Plug-in Gait's shank rotation offset: the static's ankle axis at the tibial
    torsion from the knee flexion axis.

    The ankle joint centre ``J`` lies on the circle of points at ``delta``
    from ANK that see KJC and ANK at a right angle (the chord's locus); it is
    put where the shank's y (``J`` → ANK, towards the left) is the knee
    flexion axis (the thigh's y) turned about the shank axis by the torsion,
    so that the torsioned tibia's y is parallel to the knee axis (a few
    whole-trial fixed-point passes: the shank axis moves with ``J``).  The
    offset is the angle about the shank axis from the TIB wand's plane to
    (KJC, J, ANK), with Plug-in Gait's sign (``ShankRotation``).

    Parameters
    ----------
    kjc, tibia, ankle : ndarray, shape (frames, 3), metres
        The knee joint centre, TIB, ANK.
    knee_axis : ndarray, shape (frames, 3)
        The thigh's y axis (unit, towards the left).
    delta : float
        Millimetres (half the ankle width plus the marker radius).
    torsion : float
        Radians, Plug-in Gait's TibialTorsion.
    side : {"l", "r"}

    Returns
    -------
    float
        Radians, the median over the frames; NaN when no frame gives it.
    """
    sign = _side_sign(side)
    length = np.linalg.norm(kjc - ankle, axis=-1, keepdims=True)
    u = (kjc - ankle) / length
    with np.errstate(invalid="ignore"):
        centre = ankle + u * delta ** 2 / length
        radius = delta * np.sqrt(1.0 - (delta / length) ** 2)
    ajc = chord(tibia, kjc, ankle, delta)
    for _ in range(iterations):     # whole-trial passes, not a frame loop
        z = _unit(kjc - ajc)
        y = knee_axis - np.sum(knee_axis * z, axis=-1, keepdims=True) * z
        lateral = rotate_about(_unit(y), z, sign * torsion) * (-sign)   # J -> ANK
        w = lateral - np.sum(lateral * u, axis=-1, keepdims=True) * u
        ajc = centre - radius * _unit(w)     # so that J -> ANK runs along lateral
    angle = _about(tibia - ajc, ankle - ajc, _unit(kjc - ajc))
    value = _median_angle(angle)
    return np.nan if value is None else sign * value


def kad_markers(static: Trial) -> tuple[dict, list[str]]:
    """The knee alignment device markers of each side that has all three with data.

    Returns ``{side: (KAX, KD1, KD2)}`` (metres, (frames, 3)) and the
    KAD labels of sides whose device is incomplete (a KD1 or KD2 label with
    some of the three absent or empty).  A KAX alone is not a device (Vicon
    writes a virtual LKAX/RKAX of its own in some statics).
    """
    names = tuple(p.format(S=S) for S in "LR" for p in KAD)
    found, empty = markers_from_trial(static, names)
    devices, unusable = {}, []
    for side in SIDES:
        mine = [p.format(S=side.upper()) for p in KAD]
        if not any(n in found or n in empty for n in mine[1:]):
            continue
        if all(n in found for n in mine):
            arrays = tuple(found[n] for n in mine)
            if np.isfinite(np.stack(arrays)).all(axis=(0, 2)).any():
                devices[side] = arrays
                continue
        unusable += [n for n in mine if n not in found] or mine
    return devices, unusable


def static_markers(static: Trial) -> dict:
    """Marker arrays (metres) of the static, with medial markers if present."""
    names = MARKERS + tuple(p.format(S=S) for p in MEDIAL_KNEE + MEDIAL_ANKLE
                            for S in "LR")
    markers, _ = markers_from_trial(static, names)
    return markers


def calibrate(static: Trial, subject: Subject | None = None, *, flat_foot: bool = False,
              sole_delta: float = 0.0, warn: bool = True) -> Subject:
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
        Metres of sole under the heel with ``flat_foot`` (shoes).
    warn : bool
        Say (a :class:`MissingMarkerWarning`) when the static has knee
        alignment device labels that cannot be used (absent or empty markers):
        it is then calibrated without the device.

    Returns
    -------
    Subject
        With ``static_plantar_flexion``, ``static_rotation_offset`` (radians,
        Plug-in Gait's signs) and the estimated measurements filled in; with a
        knee alignment device, ``thigh_rotation`` and ``shank_rotation`` from
        it (the given ones are replaced, as Plug-in Gait does).

    Raises
    ------
    MocapError
        The static lacks the pelvis, knee (or KAD), ankle or toe markers, or
        the knee / ankle widths are neither given nor measurable.  A foot
        without its heel marker keeps offsets of 0 (with a warning).
    """
    path = static.path
    base = subject_from_trial(static, source="static PROCESSING") if subject is None \
        else subject
    sub = replace(base, sources=dict(base.sources), leg_length=dict(base.leg_length),
                  knee_width=dict(base.knee_width), ankle_width=dict(base.ankle_width),
                  tibial_torsion=dict(base.tibial_torsion),
                  thigh_rotation=dict(base.thigh_rotation),
                  shank_rotation=dict(base.shank_rotation),
                  static_plantar_flexion={"l": None, "r": None},
                  static_rotation_offset={"l": None, "r": None})
    m = static_markers(static)
    devices, unusable = kad_markers(static)
    if unusable and warn:
        warnings.warn(f"{path or 'static trial'}: knee alignment device marker(s) "
                      f"{', '.join(unusable)} absent or without data: that side is "
                      f"calibrated without the KAD (thigh rotation as given)",
                      MissingMarkerWarning, stacklevel=2)
    needed = [n for n in ("LASI", "RASI", "LKNE", "RKNE", "LTHI", "RTHI", "LTIB", "RTIB",
                          "LANK", "RANK", "LTOE", "RTOE")
              if n not in m and not (n[1:] == "KNE" and n[0].lower() in devices)]
    if needed:
        raise MocapError(f"static trial lacks marker(s) with data: {', '.join(needed)} "
                         f"(a Plug-in Gait static needs the pelvis, both legs and feet)",
                         path)
    heelless = [f"{S}HEE" for S in "LR" if f"{S}HEE" not in m]
    if heelless and warn:
        warnings.warn(f"{path or 'static trial'}: no {' or '.join(heelless)} with data: "
                      f"that foot's plantar-flexion and rotation offsets are not calibrated "
                      f"(taken as 0)", MissingMarkerWarning, stacklevel=2)
    if "SACR" not in m and not ("LPSI" in m and "RPSI" in m):
        raise MocapError("static trial has neither SACR nor LPSI and RPSI with data", path)
    if sub.inter_asis is None:
        sub.inter_asis = _median_distance(m["LASI"], m["RASI"])
        sub.sources[("inter_asis", None)] = "static markers"
    for side in SIDES:
        S = side.upper()
        if sub.leg_length[side] is None:
            leg = _median_distance(m[f"{S}ASI"], m[f"{S}ANK"])
            sub.leg_length[side] = None if leg is None else leg + sub.radius
            sub.sources[("leg_length", side)] = "static markers"
    if devices:
        pelvis, origin, _ = pelvis_frame(m, path)
        hips = hip_joint_centres(pelvis, origin, sub)
        for side, (kax, kd1, kd2) in devices.items():
            m[f"{side.upper()}KNE"] = kad_virtual_knee(kax, kd1, kd2, hips[side],
                                                       m[f"{side.upper()}ANK"])
    for side in SIDES:
        S = side.upper()
        for key, patterns, lateral in (("knee_width", MEDIAL_KNEE, "KNE"),
                                       ("ankle_width", MEDIAL_ANKLE, "ANK")):
            if getattr(sub, key)[side] is None:
                medial = _first_present(m, patterns, side)
                if medial is None:
                    raise MocapError(
                        f"{S} {key.replace('_', ' ')} unknown: give it (Subject.{key}, "
                        f"metres) or record medial markers in the static", path)
                # marker centre to centre, less one diameter = skin to skin
                getattr(sub, key)[side] = _median_distance(
                    m[f"{S}{lateral}"], medial) - 2.0 * sub.radius
                sub.sources[(key, side)] = "static medial markers"
    for side, (kax, _, _) in devices.items():
        S = side.upper()
        _, rotation = kad_thigh_rotation(m[f"{S}THI"], hips[side], m[f"{S}KNE"], kax,
                                         sub.knee_width[side] / 2.0 + sub.radius, side)
        if not np.isfinite(rotation):
            raise MocapError(f"static trial: no frame with {S}THI, {S}KAX, {S}KD1 and "
                             f"{S}KD2 together", path)
        sub.thigh_rotation[side] = rotation
        sub.sources[("thigh_rotation", side)] = "static KAD"
    sub.static_plantar_flexion = {"l": 0.0, "r": 0.0}
    sub.static_rotation_offset = {"l": 0.0, "r": 0.0}
    sub.calibrated = False
    kin = kinematics(m, sub, path)
    for side in SIDES:
        S = side.upper()
        medial = _first_present(m, MEDIAL_ANKLE, side)
        if medial is not None and not base.tibial_torsion[side]:
            sub.tibial_torsion[side] = _tibial_torsion(kin, m, medial, side)
            sub.sources[("tibial_torsion", side)] = "static medial markers"
    for side in SIDES:
        S = side.upper()
        if side in devices or (sub.tibial_torsion[side] and not base.shank_rotation[side]):
            rotation = shank_rotation_for_torsion(
                kin.centres[f"{side}_knee"], m[f"{S}TIB"], m[f"{S}ANK"],
                kin.frames[f"{side}_thigh"][..., 1],
                sub.ankle_width[side] / 2.0 + sub.radius, sub.tibial_torsion[side], side)
            if np.isfinite(rotation):
                sub.shank_rotation[side] = rotation
                sub.sources[("shank_rotation", side)] = "static calibration"
    if any(getattr(sub, key)[s] != getattr(base, key)[s] for s in SIDES
           for key in ("tibial_torsion", "thigh_rotation", "shank_rotation")):
        kin = kinematics(m, sub, path)
    for side in SIDES:
        S = side.upper()
        if f"{S}HEE" in heelless:
            continue
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
    value = _median_angle(_about(thigh[..., 1], malleolar, z))  # knee axis -> malleolar axis
    if value is None:
        warnings.warn(f"{S}: no static frame gives the tibial torsion; using 0",
                      MissingMarkerWarning, stacklevel=3)
        return 0.0
    # With the right malleolar axis reversed above (both axes then point left),
    # Plug-in Gait's sign is the opposite of this angle on the left and this angle
    # on the right: checked against the LTibialTorsion / RTibialTorsion Vicon
    # stored for 7 real statics with medial malleoli (tests/mocap/plugingait/test_clinical.py)
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
        sub = calibrate(static, subject, flat_foot=option, warn=False)
        error[option] = sum(abs(sub.static_plantar_flexion[s] - stored[s]) for s in SIDES)
    return error[True] < error[False]
