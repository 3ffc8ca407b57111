"""Plug-in Gait upper body: frames, joint centres and angles.

The upper-body half of Vicon's Plug-in Gait (the Plug-in Gait reference guide; the
same construction as pyCGM's ``thoraxJC``, ``headJC``, ``findshoulderJC``,
``elbowJointCenter``, ``wristJointCenter``, ``handJointCenter``), vectorised over
frames, in metres.  It shares the lower body's helpers: the chord
(:func:`mocap.markersets.chord.chord`), frames as rotation matrices with columns x, y,
z (:func:`mocap.plugingait.model.frame_from_axes`) and the one Cardan decomposition
(:func:`mocap.rotations.euler.euler_from_components`).

Segments, in Vicon's orientation (the frames its ``TRXO/TRXA/TRXL/TRXP``, ``HEDO``…,
``LHUO``…, ``LRAO``…, ``LHNO``… outputs draw):

* thorax: ``z`` from the midpoint of C7 and CLAV to the midpoint of T10 and STRN
  (down), ``x`` the part of (CLAV + STRN)/2 − (C7 + T10)/2 orthogonal to it
  (anterior), ``y = z × x`` (right); origin CLAV moved back along ``x`` by the
  marker radius;
* head: ``x`` from the back to the front head markers' midpoints, ``y`` the
  part of the left minus the right midpoints orthogonal to it, ``z = x × y`` (up),
  turned about ``y`` by the subject's head offset; origin the front midpoint;
* shoulder joint centre: the chord of (wand, thorax origin, SHO) at the shoulder
  offset plus the marker radius from SHO, the wand a point off the thorax origin
  along ``x × (SHO − origin)`` (left; the mirror on the right);
* elbow joint centre: the chord of (a point on the normal of the plane of the
  shoulder centre, ELB and the wrist markers' midpoint WRI; the shoulder centre;
  ELB) at half the elbow width plus the marker radius;
* wrist joint centre: WRI moved along the forearm's ``y`` (normal to the wrist
  bar WRA − WRB and the forearm axis) by half the wrist width plus the marker
  radius;
* humerus: ``z`` from the elbow to the shoulder centre, ``y = (WJC − EJC) × z``
  (the elbow flexion axis), ``x = y × z``; radius: ``z`` from the wrist to the
  elbow centre, ``y`` the humerus's ``y`` made orthogonal to it, ``x = y × z``;
* hand: origin the chord of (WRI, WJC, FIN) at half the hand thickness plus the
  marker radius, ``z`` from it to the wrist centre, ``y`` along the wrist bar
  (WRA → WRI on the left, WRI → WRA on the right) made orthogonal, ``x = y × z``.

Angles: for each output, a Cardan sequence of the distal frame relative to the
proximal one, its components reordered, signed and shifted (:data:`ANGLES`), as
Vicon writes ``<Side><Joint>Angles`` (:func:`mocap.plugingait.model.cardan_outputs`);
the thorax and head are relative to the progression frame
(:func:`mocap.plugingait.model.progression_frame`), like the pelvis.  (The foot
progression needs only the lower body: it is one of its clinical angles,
:func:`mocap.plugingait.model.foot_progression_angles`.)  Checked against the angles Vicon
computed from its own segment outputs in the real files (tests/mocap/plugingait/
test_upper.py), and against Vicon's stored angles on held-out subjects (docs/
plugingait-upper.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mocap.markersets.chord import _unit, chord, processing_number
from mocap.plugingait.model import (PROCESSING_LENGTH_M, SIDES, Kinematics, cardan_outputs,
                                    frame_from_axes, rotate_about)
from mocap.rotations.angles import unwrap_columns
from mocap.trial import Trial

#: Markers the upper-body model reads.
UPPER_MARKERS = ("C7", "T10", "CLAV", "STRN", "LFHD", "RFHD", "LBHD", "RBHD",
                 "LSHO", "RSHO", "LELB", "RELB", "LWRA", "LWRB", "RWRA", "RWRB",
                 "LFIN", "RFIN")

#: Joints of the upper-body output in column order, each ``<side>_<joint>`` being
#: Vicon's ``<Side><Joint>Angles``.
UPPER_JOINTS = ("thorax", "spine", "neck", "head", "shoulder", "elbow", "wrist")

#: Vicon's name of each joint's output (after the side letter).
VICON_NAMES = {"thorax": "ThoraxAngles", "spine": "SpineAngles", "neck": "NeckAngles",
               "head": "HeadAngles", "shoulder": "ShoulderAngles",
               "elbow": "ElbowAngles", "wrist": "WristAngles"}

#: Marker radius of the upper-body joint centres, metres: Vicon's upper body puts
#: its centres as for a 14 mm marker whatever the subject's MarkerDiameter (chosen
#: on the design half of the real files, docs/plugingait-upper.md).
UPPER_MARKER_RADIUS_M = 0.007

#: Distance of the construction points (shoulder wand, elbow plane point) from
#: their origin, metres: any length gives the same plane.
_WAND_M = 0.5


class UpperBodyWarning(UserWarning):
    """Part of the upper body cannot be computed (markers or measurements missing)."""


@dataclass
class UpperSubject:
    """Subject measurements of the Plug-in Gait upper body, per side.

    Lengths in metres (Vicon's PROCESSING group stores millimetres:
    :func:`upper_subject_from_trial` converts them), the head offset in radians.
    ``None`` means not measured: the segments that need it are left out.

    Attributes
    ----------
    shoulder_offset, elbow_width, wrist_width, hand_thickness : dict side -> float or None
        Metres (Vicon's ``LShoulderOffset`` …).
    head_offset : float
        Radians, the head frame's turn about its y (Vicon's ``HeadOffset``).
    """

    shoulder_offset: dict = field(default_factory=lambda: {"l": None, "r": None})
    elbow_width: dict = field(default_factory=lambda: {"l": None, "r": None})
    wrist_width: dict = field(default_factory=lambda: {"l": None, "r": None})
    hand_thickness: dict = field(default_factory=lambda: {"l": None, "r": None})
    head_offset: float = 0.0

    def missing(self, side: str) -> list[str]:
        """Names of the measurements of ``side`` that are unknown."""
        return [key for key in ("shoulder_offset", "elbow_width", "wrist_width",
                                "hand_thickness") if getattr(self, key)[side] is None]


#: UpperSubject field -> PROCESSING name pattern ({S} = L or R), millimetres.
_PROCESSING = {"shoulder_offset": "{S}ShoulderOffset", "elbow_width": "{S}ElbowWidth",
               "wrist_width": "{S}WristWidth", "hand_thickness": "{S}HandThickness"}


def upper_subject_from_trial(*trials: Trial | None) -> UpperSubject:
    """Upper-body measurements from the PROCESSING group of the first trial that has each.

    Parameters
    ----------
    *trials : Trial or None
        Searched in order (the static, then its walk, as the lower body's
        measurements); None entries are skipped.

    Returns
    -------
    UpperSubject
        Lengths in metres; a value of 0 (Vicon's "not measured") is None.
    """
    sub = UpperSubject()
    sources = [t for t in trials if t is not None]
    for key, pattern in _PROCESSING.items():
        values = getattr(sub, key)
        for side in SIDES:
            for trial in sources:
                value = processing_number(trial, pattern.format(S=side.upper()))
                if value is not None:
                    values[side] = value * PROCESSING_LENGTH_M
                    break
    for trial in sources:
        value = processing_number(trial, "HeadOffset")
        if value is not None:
            sub.head_offset = value
            break
    return sub


# ------------------------------------------------------------------ frames

def _orthogonal(v: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """The unit part of ``v`` orthogonal to unit ``axis`` (frames, 3)."""
    return _unit(v - np.sum(v * axis, axis=-1, keepdims=True) * axis)


def thorax_frame(clav: np.ndarray, c7: np.ndarray, strn: np.ndarray, t10: np.ndarray,
                 radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Thorax rotation (frames, 3, 3) and origin (frames, 3), metres.

    ``z`` down the trunk, ``x`` anterior, ``y`` right (Vicon's TRX segment); the
    origin is CLAV moved ``radius`` metres back along ``x``.
    """
    z = _unit((strn + t10) / 2.0 - (clav + c7) / 2.0)
    x = _orthogonal((clav + strn) / 2.0 - (c7 + t10) / 2.0, z)
    return frame_from_axes(x, np.cross(z, x), z), clav - radius * x


def head_frame(lfhd: np.ndarray, rfhd: np.ndarray, lbhd: np.ndarray, rbhd: np.ndarray,
               offset: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Head rotation (frames, 3, 3) and origin (frames, 3), metres.

    ``x`` from the back to the front midpoint (anterior), ``y`` to the left,
    ``z`` up; turned about ``y`` by ``offset`` radians (Vicon's HeadOffset, the
    head level correction of the static); origin the front midpoint.
    """
    front, back = (lfhd + rfhd) / 2.0, (lbhd + rbhd) / 2.0
    x = _unit(front - back)
    y = _orthogonal((lfhd + lbhd) / 2.0 - (rfhd + rbhd) / 2.0, x)
    z = np.cross(x, y)
    if offset:
        x, z = rotate_about(x, y, offset), rotate_about(z, y, offset)
    return frame_from_axes(x, y, z), front


def shoulder_joint_centre(thorax: np.ndarray, origin: np.ndarray, shoulder: np.ndarray,
                          delta: float, side: str) -> np.ndarray:
    """Shoulder joint centre (frames, 3), metres: Plug-in Gait's chord from a wand.

    The wand is the point at :data:`_WAND_M` from the thorax origin along
    ``x × (SHO − origin)`` (left; ``(SHO − origin) × x`` right): the centre lies
    in the plane of the thorax's x and the shoulder marker, ``delta`` (the
    shoulder offset plus the marker radius) from SHO, at a right angle to the
    thorax origin.
    """
    x = thorax[..., 0]
    out = _unit(shoulder - origin)
    wand = np.cross(x, out) if side == "l" else np.cross(out, x)
    return chord(origin + _WAND_M * _unit(wand), origin, shoulder, delta)


def elbow_joint_centre(sjc: np.ndarray, elbow: np.ndarray, wri: np.ndarray, delta: float,
                       side: str) -> np.ndarray:
    """Elbow joint centre (frames, 3), metres.

    The chord of (a point on the normal of the plane (SJC, ELB, WRI) through ELB,
    SJC, ELB) at ``delta`` (half the elbow width plus the marker radius) from ELB;
    the right side's centre is the mirror construction.
    """
    normal = _unit(np.cross(_unit(sjc - elbow), _unit(wri - elbow)))
    return chord(elbow + _WAND_M * normal, sjc, elbow, delta if side == "l" else -delta)


def wrist_joint_centre(ejc: np.ndarray, wra: np.ndarray, wrb: np.ndarray, delta: float,
                       side: str) -> np.ndarray:
    """Wrist joint centre (frames, 3), metres.

    WRI (the wrist markers' midpoint) moved by ``delta`` (half the wrist width
    plus the marker radius) along ``y = z × x`` of the frame with ``z`` from WRI
    to the elbow centre and ``x`` along WRA − WRB (negative ``y`` on the left).
    """
    wri = (wra + wrb) / 2.0
    z = _unit(ejc - wri)
    y = _unit(np.cross(z, _orthogonal(wra - wrb, z)))
    return wri + (delta if side == "r" else -delta) * y


def humerus_frame(sjc: np.ndarray, ejc: np.ndarray, wjc: np.ndarray) -> np.ndarray:
    """Humerus rotation (frames, 3, 3): ``z`` EJC → SJC, ``y = (WJC − EJC) × z``."""
    z = _unit(sjc - ejc)
    y = _unit(np.cross(wjc - ejc, z))
    return frame_from_axes(np.cross(y, z), y, z)


def radius_frame(ejc: np.ndarray, wjc: np.ndarray, humerus: np.ndarray) -> np.ndarray:
    """Radius (forearm) rotation (frames, 3, 3): ``z`` WJC → EJC, ``y`` the humerus's
    ``y`` (the elbow flexion axis) made orthogonal to it."""
    z = _unit(ejc - wjc)
    y = _orthogonal(humerus[..., 1], z)
    return frame_from_axes(np.cross(y, z), y, z)


def hand_frame(wjc: np.ndarray, wra: np.ndarray, wrb: np.ndarray, fin: np.ndarray,
               delta: float, side: str) -> tuple[np.ndarray, np.ndarray]:
    """Hand rotation (frames, 3, 3) and origin (frames, 3), metres.

    The origin is the chord of (WRI, WJC, FIN) at ``delta`` (half the hand
    thickness plus the marker radius) from FIN; ``z`` from it to the wrist
    centre, ``y`` along the wrist bar (WRA → WRI left, WRI → WRA right) made
    orthogonal, ``x = y × z``.
    """
    wri = (wra + wrb) / 2.0
    origin = chord(wri, wjc, fin, delta)
    z = _unit(wjc - origin)
    y = _orthogonal(wri - wra if side == "l" else wra - wri, z)
    return frame_from_axes(np.cross(y, z), y, z), origin


# ------------------------------------------------------------------ the model

def upper_kinematics(markers: dict, subject: UpperSubject,
                     radius: float = UPPER_MARKER_RADIUS_M) -> Kinematics:
    """Upper-body joint centres (metres) and segment rotations from marker arrays.

    Parameters
    ----------
    markers : dict of str to ndarray (frames, 3), metres
        Bare Plug-in Gait names (:func:`mocap.plugingait.model.markers_from_trial`
        with :data:`UPPER_MARKERS`); a segment whose markers or measurements are
        absent is left out, with a note saying what it needs.
    subject : UpperSubject
    radius : float
        Marker radius of the joint centres and the thorax origin, metres.

    Returns
    -------
    Kinematics
        ``centres`` (frames, 3), metres: ``"thorax"`` (the thorax origin, Vicon's
        TRXO), ``"head"`` (the front head markers' midpoint), ``"l_shoulder"``,
        ``"l_elbow"``, ``"l_wrist"`` (the joint centres: Vicon's LCLO, LHUO,
        LRAO), ``"l_hand"`` (the chord point of the hand) and ``"l_hand_end"``
        (as far again beyond it from the wrist: Vicon's LHNO) …; ``frames``
        (frames, 3, 3): ``"thorax"``, ``"head"``, ``"l_humerus"``,
        ``"l_radius"``, ``"l_hand"`` …
    """
    centres: dict = {}
    frames: dict = {}
    notes: list[str] = []

    def have(*names: str) -> bool:
        return all(n in markers for n in names)

    if have("C7", "T10", "CLAV", "STRN"):
        frames["thorax"], centres["thorax"] = thorax_frame(
            markers["CLAV"], markers["C7"], markers["STRN"], markers["T10"], radius)
    else:
        notes.append("no thorax (C7, T10, CLAV and STRN are needed)")
    if have("LFHD", "RFHD", "LBHD", "RBHD"):
        frames["head"], centres["head"] = head_frame(
            markers["LFHD"], markers["RFHD"], markers["LBHD"], markers["RBHD"],
            subject.head_offset)
    else:
        notes.append("no head (LFHD, RFHD, LBHD and RBHD are needed)")
    for side in SIDES:
        S = side.upper()
        missing = [m for m in subject.missing(side) if m != "hand_thickness"]
        if "thorax" not in frames or not have(f"{S}SHO", f"{S}ELB", f"{S}WRA", f"{S}WRB") \
                or missing:
            needs = f"{S}SHO, {S}ELB, {S}WRA, {S}WRB, the thorax"
            if missing:
                needs += " and the " + ", ".join(m.replace("_", " ") for m in missing)
            notes.append(f"{S}: no arm ({needs} are needed)")
            continue
        sjc = shoulder_joint_centre(frames["thorax"], centres["thorax"], markers[f"{S}SHO"],
                                    subject.shoulder_offset[side] + radius, side)
        wra, wrb = markers[f"{S}WRA"], markers[f"{S}WRB"]
        ejc = elbow_joint_centre(sjc, markers[f"{S}ELB"], (wra + wrb) / 2.0,
                                 subject.elbow_width[side] / 2.0 + radius, side)
        wjc = wrist_joint_centre(ejc, wra, wrb, subject.wrist_width[side] / 2.0 + radius,
                                 side)
        centres.update({f"{side}_shoulder": sjc, f"{side}_elbow": ejc, f"{side}_wrist": wjc})
        humerus = humerus_frame(sjc, ejc, wjc)
        frames[f"{side}_humerus"] = humerus
        frames[f"{side}_radius"] = radius_frame(ejc, wjc, humerus)
        if not have(f"{S}FIN") or subject.hand_thickness[side] is None:
            notes.append(f"{S}: no hand ({S}FIN and the hand thickness are needed)")
            continue
        hand, centre = hand_frame(wjc, wra, wrb, markers[f"{S}FIN"],
                                  subject.hand_thickness[side] / 2.0 + radius, side)
        frames[f"{side}_hand"] = hand
        centres[f"{side}_hand"] = centre
        centres[f"{side}_hand_end"] = 2.0 * centre - wjc
    return Kinematics(centres, frames, notes)


#: Each output: (proximal frame, distal frame, Cardan sequence, per side (order,
#: signs, offsets in degrees)): Vicon's component k is ``signs[k] * a[order[k]] +
#: offsets[k]`` (wrapped to (-180, 180]) of the sequence's angles ``a`` of
#: ``proximalᵀ distal`` (:func:`mocap.plugingait.model.cardan_outputs`).
#: "progression" is the walk's progression frame, "pelvis" the lower body's frame;
#: the others are this module's.  Found on the
#: angles Vicon stored beside its own segment outputs (every real file, < 0.001°).
ANGLES = {
    "thorax": ("progression", "thorax", "YXZ",
               {"l": ((0, 1, 2), (1, -1, 1), (180, 0, 180)),
                "r": ((0, 1, 2), (1, 1, -1), (180, 0, 180))}),
    "spine": ("pelvis", "thorax", "ZXY",
              {"l": ((2, 1, 0), (-1, 1, 1), (180, 0, 180)),
               "r": ((2, 1, 0), (-1, -1, -1), (180, 0, 180))}),
    "neck": ("thorax", "head", "ZXY",
             {"l": ((2, 1, 0), (1, 1, -1), (180, 0, 180)),
              "r": ((2, 1, 0), (1, -1, 1), (180, 0, 180))}),
    "head": ("progression", "head", "YXZ",
             {"l": ((0, 1, 2), (-1, 1, -1), (0, 0, 0)),
              "r": ((0, 1, 2), (-1, -1, 1), (0, 0, 0))}),
    "shoulder": ("thorax", "humerus", "XYZ",
                 {"l": ((1, 0, 2), (-1, 1, -1), (0, 180, 180)),
                  "r": ((1, 0, 2), (-1, -1, 1), (0, 180, 180))}),
    "elbow": ("humerus", "radius", "YXZ",
              {"l": ((0, 1, 2), (1, 1, 1), (0, 0, 0)),
               "r": ((0, 1, 2), (1, 1, 1), (0, 0, 0))}),
    "wrist": ("radius", "hand", "YXZ",
              {"l": ((0, 1, 2), (1, -1, -1), (0, 0, 0)),
               "r": ((0, 1, 2), (1, 1, 1), (0, 0, 0))}),
}


def vicon_angles(proximal: np.ndarray, distal: np.ndarray, joint: str, side: str
                 ) -> np.ndarray:
    """Vicon's ``<Side><Joint>Angles`` (X, Y, Z) of two frames, degrees (frames, 3).

    ``proximal`` and ``distal`` are rotations (frames, 3, 3) as :data:`ANGLES`
    names them; NaN where either is NaN.
    """
    _, _, sequence, per_side = ANGLES[joint]
    return cardan_outputs(proximal, distal, sequence, *per_side[side])


def upper_columns() -> list[str]:
    """Segment names of the upper-body output: l_thorax … r_wrist."""
    return [f"{side}_{joint}" for side in SIDES for joint in UPPER_JOINTS]


def upper_angles(lower: Kinematics, upper: Kinematics, progression: np.ndarray
                 ) -> np.ndarray:
    """The upper-body angles, degrees (frames, 14, 3).

    Parameters
    ----------
    lower : Kinematics
        The lower body's (:func:`mocap.plugingait.model.kinematics`): its
        ``"pelvis"`` frame.
    upper : Kinematics
        :func:`upper_kinematics`.
    progression : ndarray, shape (3, 3) or (frames, 3, 3)
        The progression frame.

    Returns
    -------
    ndarray, shape (frames, 14, 3)
        Columns in :func:`upper_columns` order, components Vicon's X, Y, Z; a
        column whose frames are absent is NaN.  Each component is continuous
        over the frames, as Vicon writes it: whole turns are removed
        (:func:`mocap.rotations.angles.unwrap_columns`; the first valid frame
        keeps its value in (-180, 180]).
    """
    pelvis = lower.frames["pelvis"]
    n = pelvis.shape[0]
    values = np.full((n, len(SIDES) * len(UPPER_JOINTS), 3), np.nan)
    shared = {"progression": np.broadcast_to(progression, pelvis.shape), "pelvis": pelvis,
              "thorax": upper.frames.get("thorax"), "head": upper.frames.get("head")}
    for i, side in enumerate(SIDES):
        own = {name: upper.frames.get(f"{side}_{name}")
               for name in ("humerus", "radius", "hand")}
        for j, joint in enumerate(UPPER_JOINTS):
            proximal, distal = (shared.get(k, own.get(k)) for k in ANGLES[joint][:2])
            if proximal is None or distal is None:
                continue
            values[:, i * len(UPPER_JOINTS) + j] = vicon_angles(proximal, distal, joint, side)
    return unwrap_columns(values)
