"""Plug-in Gait lower body: joint centres, anatomical frames and clinical angles.

The Conventional Gait Model as Vicon's Plug-in Gait computes it (Davis, Ounpuu,
Tyburski & Gage 1991; Kadaba, Ramakrishnan & Wootten 1990; Baker 2013,
*Measuring Walking*, ch. 10; the Plug-in Gait reference guide), vectorised over
frames.  Every segment frame is a rotation matrix whose columns are its x, y, z
axes in lab coordinates; every length is in metres, as in ``Trial`` (Vicon's
PROCESSING group stores the subject's lengths in millimetres: they are converted
where they are read, :func:`subject_from_trial`).

Frames, for both sides (x anterior, y left, z up when standing):

* pelvis: origin the ASIS midpoint ``O``; ``y = unit(LASI - RASI)``; ``x`` the
  part of ``O - SACR`` orthogonal to ``y``; ``z = x × y``.
* hip joint centre (Davis): ``O + X x + Y y + Z z`` with
  ``C = 0.115 L - 0.0153`` (m), ``X = C cos θ sin β - (AT + r) cos β``,
  ``Y = ±(C sin θ - IAD / 2)`` (− left), ``Z = -C cos θ cos β - (AT + r) sin β``;
  θ = 0.5, β = 0.314 rad, ``L`` the mean leg length, ``AT`` the ASIS-trochanter
  distance (``0.1288 L - 0.04856`` m when not measured), ``r`` the marker radius.
* knee joint centre: :func:`chord` of (THI, HJC, KNE) at ``knee width / 2 + r``
  from KNE; thigh: ``z = unit(HJC - KJC)``, ``x`` normal to the plane
  (HJC, KJC, KNE), ``y = z × x``.
* ankle joint centre: :func:`chord` of (TIB, KJC, ANK) at ``ankle width / 2 + r``
  from ANK; shank: ``z = unit(KJC - AJC)``, ``x`` normal to (TIB, KJC, ANK), so
  that ``y`` points from the joint centre to the lateral malleolus (ANK);
  the torsioned shank (for the ankle) is turned about ``z`` by the tibial
  torsion.
* foot: origin TOE, ``z = unit(AJC - TOE)`` (backwards), ``x = y_ankle × z``
  (up), ``y = z × x``; then turned by the static plantar-flexion and rotation
  offsets (:mod:`mocap.plugingait.calibration`) so that it lies along heel → toe.

Angles: Cardan ``YXZ`` (flexion, then ab/adduction, then axial rotation) of the
distal frame relative to the proximal one (the pelvis relative to the
progression frame), with Plug-in Gait's signs: flexion, adduction (knee varus)
and internal rotation positive, ankle dorsiflexion and inversion positive,
pelvic tilt anterior, obliquity and rotation positive when that side is up /
forward.  The foot progression is the foot relative to the progression frame
(:func:`foot_progression_angles`): it needs no marker above the pelvis.  See
docs/plugingait.md for the column ↔ Vicon output table.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mocap.errors import MocapError
from mocap.markersets.chord import _unit, chord, rotate_about  # noqa: F401 (re-exported)
from mocap.markersets.model import _LabelIndex
from mocap.markersets.virtual import DAVIS_BETA, DAVIS_THETA  # noqa: F401 (re-exported)
from mocap.markersets.virtual import davis_asis_trochanter, hip_joint_centre_offset
from mocap.markersets.virtual import pelvis_frame as pelvis_axes
from mocap.plugingait.cardan import (  # noqa: F401 (re-exported)
    _CLINICAL, FOOT_PROGRESSION, cardan_outputs, clinical_angles, foot_progression_angles,
    frame_from_axes, progression_frame, yxz_angles)
from mocap.trial import Trial

#: Joints of the clinical output, in column order.
JOINTS = ("pelvis", "hip", "knee", "ankle")
#: Segments of the clinical output of a side, in column order: the joints, then the foot
#: progression (``<side>_foot_progress`` is Vicon's ``<Side>FootProgressAngles``).
CLINICAL_SEGMENTS = JOINTS + ("foot_progress",)
#: Planes of the clinical output (Vicon's X, Y, Z components of <Side><Joint>Angles).
PLANES = ("flexion", "adduction", "rotation")
SIDES = ("l", "r")


class MissingMeasurementError(MocapError):
    """Subject measurements Plug-in Gait needs (knee, ankle widths) are unknown.

    No longer raised by the model: missing widths are estimated from the walk
    (:mod:`mocap.plugingait.estimates`); kept for callers that catch it."""


class AnatomicalOffsetWarning(UserWarning):
    """Angles computed without a static calibration (offsets uncorrected)."""


@dataclass
class Subject:
    """Subject measurements and static offsets of Plug-in Gait, per side.

    Lengths in metres (like ``Trial.points``; :func:`subject_from_trial` converts
    the millimetres of Vicon's PROCESSING group), angles in radians.  ``None``
    means "not measured": estimated where Plug-in Gait estimates it.  A length
    too large to be metres (a knee 100 m wide: millimetres given by mistake) is
    a :class:`~mocap.errors.MocapError` at construction.

    Attributes
    ----------
    marker_diameter : float or None
        Metres; None when not recorded (:attr:`radius` then assumes
        :data:`DEFAULT_MARKER_DIAMETER_M`, and
        :func:`~mocap.plugingait.clinical.prepare_subject` says so).
    leg_length, asis_trochanter, knee_width, ankle_width : dict side -> float or None
        Metres.
    inter_asis : float or None
        Metres.
    tibial_torsion, thigh_rotation, shank_rotation : dict side -> float
        Radians; the last two turn the wand markers' planes (KAD calibration).
    static_plantar_flexion, static_rotation_offset : dict side -> float or None
        Radians, Plug-in Gait's signs; None when no static calibrated the foot.
    calibrated : bool
        True once a static trial set the offsets.
    sources : dict of (str, str or None) to str
        Where each value came from, keyed ``(field, side)`` (side None for
        ``inter_asis`` and ``marker_diameter``): ``"static PROCESSING"``, ``"walk
        PROCESSING"``, ``"static medial markers"``, ``"estimated from the walk"`` …
        (what the report's subject table shows); not compared by ``==``.
    """

    marker_diameter: float | None = None
    leg_length: dict = field(default_factory=lambda: {"l": None, "r": None})
    asis_trochanter: dict = field(default_factory=lambda: {"l": None, "r": None})
    knee_width: dict = field(default_factory=lambda: {"l": None, "r": None})
    ankle_width: dict = field(default_factory=lambda: {"l": None, "r": None})
    inter_asis: float | None = None
    tibial_torsion: dict = field(default_factory=lambda: {"l": 0.0, "r": 0.0})
    thigh_rotation: dict = field(default_factory=lambda: {"l": 0.0, "r": 0.0})
    shank_rotation: dict = field(default_factory=lambda: {"l": 0.0, "r": 0.0})
    static_plantar_flexion: dict = field(default_factory=lambda: {"l": None, "r": None})
    static_rotation_offset: dict = field(default_factory=lambda: {"l": None, "r": None})
    calibrated: bool = False
    sources: dict = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self) -> None:
        lengths = [("marker_diameter", None, self.marker_diameter),
                   ("inter_asis", None, self.inter_asis)]
        lengths += [(key, side, getattr(self, key).get(side)) for key in _LIMITS_M
                    if key not in ("marker_diameter", "inter_asis") for side in SIDES]
        for key, side, value in lengths:
            if value is not None and value > _LIMITS_M[key]:
                name = key if side is None else f"{key}[{side!r}]"
                raise MocapError(f"Subject.{name} = {value:g} is over {_LIMITS_M[key]:g} m: "
                                 f"millimetres? Subject lengths are metres")

    @property
    def radius(self) -> float:
        """Marker radius, metres (:data:`DEFAULT_MARKER_DIAMETER_M` / 2 when the
        diameter is not recorded)."""
        diameter = self.marker_diameter
        return (DEFAULT_MARKER_DIAMETER_M if diameter is None else diameter) / 2.0


#: Marker diameter assumed when no PROCESSING group records one, metres (Vicon's
#: 14 mm markers; biomechzoo's files record 10 mm).
DEFAULT_MARKER_DIAMETER_M = 0.014


#: Largest plausible value of each Subject length, metres: a marker of 10 cm, a leg
#: of 3 m, a pelvis 1 m wide; anything larger is a length given in millimetres.
_LIMITS_M = {"marker_diameter": 0.1, "inter_asis": 1.0, "leg_length": 3.0,
             "asis_trochanter": 0.5, "knee_width": 0.5, "ankle_width": 0.5}

#: Vicon's PROCESSING group stores lengths in millimetres.
PROCESSING_LENGTH_M = 1e-3


_PROCESSING = {  # Subject field -> PROCESSING name pattern ({S} = L or R), mm or rad
    "leg_length": "{S}LegLength", "asis_trochanter": "{S}AsisTrocanterDistance",
    "knee_width": "{S}KneeWidth", "ankle_width": "{S}AnkleWidth",
    "tibial_torsion": "{S}TibialTorsion", "thigh_rotation": "{S}ThighRotation",
    "shank_rotation": "{S}ShankRotation",
    "static_plantar_flexion": "{S}StaticPlantFlex",
    "static_rotation_offset": "{S}StaticRotOff",
}


def subject_from_trial(trial: Trial, *, offsets: bool = False,
                       source: str = "PROCESSING") -> Subject:
    """Subject measurements from a C3D's PROCESSING group (Vicon's subject values).

    Parameters
    ----------
    trial : Trial
        Read from a C3D (``parameters["PROCESSING"]``); other
        formats give the defaults.
    offsets : bool
        Also take the static offsets (plant-flexion, rotation) stored there by
        a previous Plug-in Gait run; off by default, as those are outputs of a
        static calibration, not measurements.
    source : str
        The provenance recorded in ``Subject.sources`` for every value found
        ("walk PROCESSING", "static PROCESSING" …).

    Returns
    -------
    Subject
        Lengths converted to metres (the group's are millimetres).  A
        measurement of 0 (Vicon's "not measured") becomes None.
    """
    parameters = trial.parameters
    group = {str(k).upper(): v for k, v in (parameters.get("PROCESSING") or {}).items()}

    def number(name: str) -> float | None:
        value = group.get(name.upper())
        try:
            value = float(np.ravel(value)[0])
        except (TypeError, ValueError, IndexError):
            return None
        return value if np.isfinite(value) else None

    subject = Subject()
    diameter = number("MarkerDiameter")
    if diameter and diameter > 0:
        subject.marker_diameter = diameter * PROCESSING_LENGTH_M
        subject.sources[("marker_diameter", None)] = source
    iad = number("InterAsisDistance")
    subject.inter_asis = iad * PROCESSING_LENGTH_M if iad else None
    if subject.inter_asis is not None:
        subject.sources[("inter_asis", None)] = source
    for key, pattern in _PROCESSING.items():
        if key.startswith("static_") and not offsets:
            continue
        values = getattr(subject, key)
        for side in SIDES:
            value = number(pattern.format(S=side.upper()))
            if key in ("tibial_torsion", "thigh_rotation", "shank_rotation"):
                values[side] = value or 0.0
            elif key.startswith("static_"):
                values[side] = value
            else:
                values[side] = value * PROCESSING_LENGTH_M if value else None
            if value:
                subject.sources[(key, side)] = source
    if offsets and all(subject.static_plantar_flexion[s] is not None for s in SIDES):
        subject.calibrated = True
    return subject


# ------------------------------------------------------------------ vector helpers

def rot_y(angle: float) -> np.ndarray:
    """Rotation matrix about y by ``angle`` radians."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_x(angle: float) -> np.ndarray:
    """Rotation matrix about x by ``angle`` radians."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_z(angle: float) -> np.ndarray:
    """Rotation matrix about z by ``angle`` radians."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


# ------------------------------------------------------------------ the model

@dataclass
class Markers:
    """The markers the model reads, metres, (frames, 3) each; None if absent."""

    points: dict

    def get(self, name: str) -> np.ndarray | None:
        return self.points.get(name)


def markers_from_trial(trial: Trial, names: tuple[str, ...]) -> tuple[dict, list[str]]:
    """Marker arrays (metres, (frames, 3)) by bare name; names with no valid frame are absent.

    Returns the arrays and the names found as labels but empty (no valid frame).
    """
    index = _LabelIndex(trial.labels)
    out: dict[str, np.ndarray] = {}
    empty: list[str] = []
    for name in names:
        column = index.find(name)
        if column is None:
            continue
        values = trial.points[:, column, :]
        if not np.isfinite(values).all(axis=1).any():
            empty.append(name)
            continue
        out[name] = values
    return out, empty


#: Every marker name the lower-body model may read.
MARKERS = ("LASI", "RASI", "SACR", "LPSI", "RPSI", "LTHI", "RTHI", "LKNE", "RKNE",
           "LTIB", "RTIB", "LANK", "RANK", "LHEE", "RHEE", "LTOE", "RTOE",
           "LKAX", "RKAX", "LKD1", "RKD1", "LKD2", "RKD2", "LMED", "RMED")


def pelvis_frame(m: dict, path: str | None = None, warn: bool = True
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pelvis rotation (frames, 3, 3), origin (frames, 3) and the sacrum used.

    SACR when it has data, else the PSIS midpoint (with a warning when a SACR
    label exists without data).
    """
    if "RASI" not in m or "LASI" not in m:
        raise MocapError("Plug-in Gait needs RASI and LASI markers with data", path)
    sacrum = m.get("SACR")
    if sacrum is None:
        if "LPSI" in m and "RPSI" in m:
            sacrum = (m["LPSI"] + m["RPSI"]) / 2.0
        else:
            raise MocapError("Plug-in Gait needs a SACR marker or both LPSI and RPSI "
                             "with data", path)
    rotation, origin = pelvis_axes(m["RASI"], m["LASI"], sacrum)
    return rotation, origin, sacrum


def hip_joint_centres(rotation: np.ndarray, origin: np.ndarray, subject: Subject
                      ) -> dict[str, np.ndarray]:
    """Davis hip joint centres (frames, 3) per side, metres.

    The one Davis regression (:func:`mocap.markersets.virtual.hip_joint_centre_offset`)
    with Plug-in Gait's inputs: the mean leg length of both sides, each side's
    ASIS-trochanter distance (measured, else regressed from that side's leg).
    """
    legs = [subject.leg_length[s] for s in SIDES]
    if any(v is None for v in legs):
        raise MocapError("leg lengths must be known (calibrate or give them)")
    mean_leg = float(np.mean(legs))
    out = {}
    for side, name in (("l", "left"), ("r", "right")):
        at = subject.asis_trochanter[side]
        if at is None:
            at = davis_asis_trochanter(subject.leg_length[side])
        local = hip_joint_centre_offset(
            "davis", name, subject.inter_asis, leg_length=mean_leg,
            marker_diameter=2.0 * subject.radius, asis_trochanter=at)
        out[side] = origin + rotation @ local
    return out


def thigh_frame(hjc: np.ndarray, kjc: np.ndarray, knee: np.ndarray, side: str
                ) -> np.ndarray:
    """Thigh rotation: z from KJC to HJC, x normal to (HJC, KJC, KNE), (frames, 3, 3)."""
    z = _unit(hjc - kjc)
    lateral = knee - hjc
    x = _unit(np.cross(z, lateral) if side == "r" else np.cross(lateral, z))
    return frame_from_axes(x, np.cross(z, x), z)


def shank_frame(kjc: np.ndarray, ajc: np.ndarray, ankle: np.ndarray, side: str
                ) -> np.ndarray:
    """Shank rotation from the joint centres and the lateral malleolus (frames, 3, 3).

    ``z = unit(KJC - AJC)``; ``y`` the part of AJC → ANK orthogonal to ``z``
    (towards the left: lateral on the left leg, medial on the right);
    ``x = y × z`` (anterior).  The wand marker only placed the ankle centre.
    """
    z = _unit(kjc - ajc)
    lateral = ankle - ajc
    y = _unit(lateral - np.sum(lateral * z, axis=-1, keepdims=True) * z)
    if side == "r":
        y = -y
    return frame_from_axes(np.cross(y, z), y, z)


def uncorrected_foot_frame(ajc: np.ndarray, toe: np.ndarray, ankle_y: np.ndarray
                           ) -> np.ndarray:
    """Foot before the static offsets: z from TOE to AJC, x = ankle y × z (up)."""
    z = _unit(ajc - toe)
    x = _unit(np.cross(ankle_y, z))
    return frame_from_axes(x, np.cross(z, x), z)


def torsioned(shank: np.ndarray, torsion: float) -> np.ndarray:
    """The shank turned about its z by the tibial torsion (radians)."""
    return shank @ rot_z(torsion) if torsion else shank


def anatomical_foot_frame(toe: np.ndarray, heel: np.ndarray, ankle_y: np.ndarray,
                          ajc: np.ndarray | None = None, flat: bool = False,
                          sole_delta: float = 0.0) -> np.ndarray:
    """The static's foot along heel → toe: z = unit(HEE - TOE), x = ankle y × z.

    With ``flat`` (Plug-in Gait's "foot flat" option) the heel is taken at the
    toe's height, so the foot's long axis is horizontal in the lab (the sole is
    on the floor): z is TOE → AJC projected onto the plane normal to the level
    heel → toe line's horizontal normal, as Plug-in Gait does.
    """
    if not flat:
        z = _unit(heel - toe)
    else:
        level = heel - toe
        level[..., 2] = 0.0
        level = _unit(level)
        to_ankle = ajc.copy()
        to_ankle[..., 2] += sole_delta
        to_ankle = _unit(to_ankle - toe)
        a = _unit(np.cross(level, to_ankle))
        b = _unit(np.cross(a, level))
        z = _unit(np.cross(b, a))
    x = _unit(np.cross(ankle_y, z))
    y = np.cross(z, x)
    return frame_from_axes(x, y, _unit(np.cross(x, y)))


@dataclass
class Kinematics:
    """Joint centres (metres) and segment rotations of one trial.

    ``centres`` maps ``"pelvis"``, ``"l_hip"``, ``"l_knee"``, ``"l_ankle"``,
    ``"l_toe"`` … to (frames, 3); ``frames`` maps ``"pelvis"``, ``"l_thigh"``,
    ``"l_shank"`` (untorsioned), ``"l_tibia"`` (torsioned, the ankle's
    proximal frame), ``"l_foot_uncorrected"``, ``"l_foot"`` … to
    (frames, 3, 3).  Segments whose markers are absent are left out.
    """

    centres: dict
    frames: dict
    notes: list = field(default_factory=list)


def _side_sign(side: str) -> float:
    # the wand-rotation offsets turn about a line pointing up the limb: mirrored
    return -1.0 if side == "l" else 1.0


def kinematics(markers: dict, subject: Subject, path: str | None = None,
               feet: bool = True) -> Kinematics:
    """Plug-in Gait joint centres and segment frames from marker arrays.

    Parameters
    ----------
    markers : dict of str to ndarray (frames, 3), metres
        Bare Plug-in Gait names (markers_from_trial); absent names are skipped
        (a leg without knee markers gives no thigh, a foot without HEE/TOE no
        foot).
    subject : Subject
        Leg lengths and the inter-ASIS distance must be known (calibrate).
    feet : bool
        Compute the feet (needs static offsets unless uncorrected is fine).
    """
    notes: list[str] = []
    pelvis, origin, sacrum = pelvis_frame(markers, path)
    centres = {"pelvis": origin, "sacrum": sacrum}
    frames = {"pelvis": pelvis}
    hips = hip_joint_centres(pelvis, origin, subject)
    for side in SIDES:
        S = side.upper()
        centres[f"{side}_hip"] = hips[side]
        if not all(f"{S}{n}" in markers for n in ("THI", "KNE")) \
                or subject.knee_width[side] is None:
            notes.append(f"{S}: no thigh ({S}THI, {S}KNE and the knee width are needed)")
            continue
        sign = _side_sign(side)
        kjc = chord(markers[f"{S}THI"], hips[side], markers[f"{S}KNE"],
                    subject.knee_width[side] / 2.0 + subject.radius,
                    sign * subject.thigh_rotation[side])
        centres[f"{side}_knee"] = kjc
        frames[f"{side}_thigh"] = thigh_frame(hips[side], kjc, markers[f"{S}KNE"], side)
        if not all(f"{S}{n}" in markers for n in ("TIB", "ANK")) \
                or subject.ankle_width[side] is None:
            notes.append(f"{S}: no shank ({S}TIB, {S}ANK and the ankle width are needed)")
            continue
        ajc = chord(markers[f"{S}TIB"], kjc, markers[f"{S}ANK"],
                    subject.ankle_width[side] / 2.0 + subject.radius,
                    sign * subject.shank_rotation[side])
        centres[f"{side}_ankle"] = ajc
        shank = shank_frame(kjc, ajc, markers[f"{S}ANK"], side)
        frames[f"{side}_shank"] = shank
        tibia = torsioned(shank, -sign * subject.tibial_torsion[side])
        frames[f"{side}_tibia"] = tibia
        if not feet or f"{S}TOE" not in markers:
            if feet:
                notes.append(f"{S}: no foot ({S}TOE is needed)")
            continue
        toe = markers[f"{S}TOE"]
        centres[f"{side}_toe"] = toe
        foot = uncorrected_foot_frame(ajc, toe, tibia[..., 1])
        frames[f"{side}_foot_uncorrected"] = foot
        flex, rot = (subject.static_plantar_flexion[side],
                     subject.static_rotation_offset[side])
        frames[f"{side}_foot"] = foot @ foot_offset_matrix(flex or 0.0, rot or 0.0, side)
    return Kinematics(centres, frames, notes)


def foot_offset_matrix(plantar_flexion: float, rotation_offset: float, side: str
                       ) -> np.ndarray:
    """Rotation taking the uncorrected foot to the anatomical one (3, 3).

    From Plug-in Gait's stored offsets (radians): ``Ry(b) Rx(a)`` with
    ``b = -StaticPlantFlex`` and ``a = StaticRotOff`` (right) or
    ``-StaticRotOff`` (left).
    """
    a = rotation_offset if side == "r" else -rotation_offset
    return rot_y(-plantar_flexion) @ rot_x(a)
