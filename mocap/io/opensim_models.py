"""Joint angles as the coordinates of OpenSim's gait2392 and Rajagopal models.

OpenSim matches a ``.mot`` file's columns to the model's coordinates by name and
takes rotations in the model's joint axes, so a column must carry the model's name,
sign and unit. Both models (gait2392_simbody.osim and Rajagopal2015.osim of
opensim-models) use a Y-up ground with X anterior and Z to the right, and CustomJoints
whose three rotations are applied in the order Z, X, Y of the parent's axes (body
fixed), with the left side's X and Y axes negated. The mapping, documented in
docs/opensim.md:

============================  =========================  =====================
coordinate                    body joint (child/parent)  our angle
============================  =========================  =====================
pelvis_tilt / list / rotation pelvis / lab               −Y, X, Z
pelvis_tx / ty / tz           pelvis origin, metres      x, z, −y (Y up)
hip_flexion/adduction/        r_thigh / pelvis           −Y, X, Z
rotation_r                    (left: −Y, −X, −Z)
knee_angle_r (flexion < 0)    r_shank / r_thigh          −Y
ankle_angle_r (dorsiflexion   r_foot / r_shank           −Y
> 0)
lumbar_extension / bending /  thorax / pelvis            −Y, X, Z
rotation
arm_flex / add / rot_r        r_upperarm / thorax        −Y, X, Z (Rajagopal;
                              (left: −Y, −X, −Z)         left mirrored)
elbow_flex_r                  r_forearm / r_upperarm     −Y (Rajagopal)
============================  =========================  =====================

"our angle" is the project's joint angle in the Z-up lab (X anterior, Y left, Z up)
with the intrinsic sequence YXZ, computed by the one motion → angles code
(:func:`mocap.body.angles.motion_joint_angles`): OpenSim's Z (right) is our −Y, its X our
X and its Y (up) our Z, so OpenSim's Z-X-Y rotation of angles (a, b, c) is our Y-X-Z
rotation of (−a, b, c). Single-axis joints (knee, ankle, elbow) take the flexion
angle; subtalar, mtp, pronation and wrist coordinates are not written (OpenSim
keeps their defaults). Angles are degrees (``inDegrees=yes``), translations metres.
"""
from __future__ import annotations

import os

import numpy as np

from mocap.errors import MocapError

#: (coordinate, segment, parent segment or None for the lab, angle index in YXZ, sign)
_LEGS = [
    ("hip_flexion_{s}", "{s}_thigh", "pelvis", 0, -1),
    ("hip_adduction_{s}", "{s}_thigh", "pelvis", 1, +1),
    ("hip_rotation_{s}", "{s}_thigh", "pelvis", 2, +1),
    ("knee_angle_{s}", "{s}_shank", "{s}_thigh", 0, -1),
    ("ankle_angle_{s}", "{s}_foot", "{s}_shank", 0, -1),
]
_ARMS = [
    ("arm_flex_{s}", "{s}_upperarm", "thorax", 0, -1),
    ("arm_add_{s}", "{s}_upperarm", "thorax", 1, +1),
    ("arm_rot_{s}", "{s}_upperarm", "thorax", 2, +1),
    ("elbow_flex_{s}", "{s}_forearm", "{s}_upperarm", 0, -1),
]
_PELVIS = [
    ("pelvis_tilt", "pelvis", None, 0, -1),
    ("pelvis_list", "pelvis", None, 1, +1),
    ("pelvis_rotation", "pelvis", None, 2, +1),
]
_LUMBAR = [
    ("lumbar_extension", "thorax", "pelvis", 0, -1),
    ("lumbar_bending", "thorax", "pelvis", 1, +1),
    ("lumbar_rotation", "thorax", "pelvis", 2, +1),
]

def _sided(entries, side: str):
    """Coordinates of one side; on the left the X and Y axes are negated (−X, −Y)."""
    out = []
    for name, segment, parent, index, sign in entries:
        name = name.format(s=side)
        if side == "l" and index in (1, 2):
            sign = -sign
        out.append((name, segment.format(s=side), parent.format(s=side) if parent else None,
                    index, sign))
    return out


def _model(arms: bool):
    joints = list(_PELVIS)
    for side in ("r", "l"):
        joints += _sided(_LEGS, side)
    joints += _LUMBAR
    if arms:
        for side in ("r", "l"):
            joints += _sided(_ARMS, side)
    return joints


#: Model name → coordinate table.
MODELS = {"gait2392": _model(arms=False), "rajagopal": _model(arms=True)}
#: The translations of the pelvis (ground_pelvis joint), metres, Y up.
TRANSLATIONS = ("pelvis_tx", "pelvis_ty", "pelvis_tz")


#: Plug-in Gait clinical angle (joint, plane index) -> sign of the model coordinate: the
#: hips as Vicon gives them (flexion, adduction, internal rotation positive on both sides,
#: as gait2392's), knee flexion negated, ankle dorsiflexion as it is.
CLINICAL = {"hip_flexion_{s}": ("hip", 0, 1.0), "hip_adduction_{s}": ("hip", 1, 1.0),
            "hip_rotation_{s}": ("hip", 2, 1.0), "knee_angle_{s}": ("knee", 0, -1.0),
            "ankle_angle_{s}": ("ankle", 0, 1.0)}


def clinical_coordinates(angles) -> dict[str, np.ndarray]:
    """Hip, knee and ankle coordinates from Plug-in Gait's calibrated clinical angles.

    Parameters
    ----------
    angles : JointAngles
        :func:`mocap.pipeline.clinical_angles`' ``angles``: segments ``l_pelvis`` …
        ``r_foot_progress`` (the hips, knees and ankles are read, by name), axes flexion,
        adduction, rotation, values (frames, segments, 3) degrees.

    Returns
    -------
    dict of str to ndarray, shape (frames,)
        ``hip_flexion_r`` … ``ankle_angle_l`` in degrees (:data:`CLINICAL`).
    """
    result = {}
    for side in ("r", "l"):
        for name, (joint, plane, sign) in CLINICAL.items():
            column = angles.values[:, angles.segments.index(f"{side}_{joint}"), plane]
            result[name.format(s=side)] = sign * column
    return result


def model_coordinates(motion, model: str, clinical=None
                      ) -> tuple[np.ndarray, list[str], np.ndarray]:
    """The coordinates of an OpenSim model that a motion defines.

    Parameters
    ----------
    motion : Motion
        Any motion (BVH, ASF/AMC, marker trial with a marker set); mapped onto the
        15-segment body first.
    model : {"gait2392", "rajagopal"}
    clinical : JointAngles, optional
        Plug-in Gait's calibrated clinical angles of the same frames
        (:func:`mocap.pipeline.clinical_angles` with the static): the hip, knee and ankle
        coordinates are taken from them (:func:`clinical_coordinates`) instead of the
        marker set's segment angles; the pelvis and lumbar stay the motion's.

    Returns
    -------
    times : ndarray, shape (frames,), seconds
        The motion's own clock (``motion.start_time`` onwards: a C3D's frame 1 at 0 s), as
        in the TRC of the same trial, so OpenSim's tools line the files up.
    labels : list of str
        Model coordinate names, pelvis translations first; coordinates of segments the
        motion lacks are left out.
    values : ndarray, shape (frames, len(labels))
        Degrees for rotations, metres for translations (OpenSim's Y-up ground).
    """
    from mocap.io.lab import Z_TO_Y_UP
    from mocap.body.angles import motion_joint_angles
    from mocap.body.retarget import motion_to_lab, reduce_to_segments

    if model not in MODELS:
        raise MocapError(f"unknown OpenSim model {model!r}: use one of {', '.join(MODELS)}")
    body = reduce_to_segments(motion, partial=True)
    angles = motion_joint_angles(body, "YXZ", body=False)
    parents = dict(zip(angles.segments, [angles.segments[p] if p >= 0 else None
                                         for p in angles.parents]))
    _, root = motion_to_lab(body)                    # pelvis origin in the Z-up lab
    labels = list(TRANSLATIONS)
    columns = [root @ Z_TO_Y_UP.T]
    for name, segment, parent, index, sign in MODELS[model]:
        if segment not in parents or parents[segment] != parent:
            continue
        labels.append(name)
        columns.append(sign * angles.values[:, angles.segments.index(segment), index:index + 1])
    values = np.column_stack(columns)
    if clinical is not None:
        if clinical.values.shape[0] != values.shape[0]:
            raise MocapError(f"{clinical.values.shape[0]} frames of clinical angles for a "
                             f"motion of {values.shape[0]}")
        for name, column in clinical_coordinates(clinical).items():
            if name not in labels:
                labels.append(name)
                values = np.column_stack([values, column])
            else:
                values[:, labels.index(name)] = column
    return motion.start_time + angles.times, labels, values


def write_model_mot(motion, path, model: str, precision: int = 6, clinical=None) -> None:
    """Write a motion as a ``.mot`` of the model's coordinates (all-or-nothing); see
    :func:`model_coordinates` for ``clinical``."""
    from mocap.io.mot import write_mot

    times, labels, values = model_coordinates(motion, model, clinical)
    write_mot(path, times, labels, values,
              name=os.path.splitext(os.path.basename(os.fspath(path)))[0],
              precision=precision)
