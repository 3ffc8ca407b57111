"""Plug-in Gait's angle conventions: Cardan angles of one segment frame in another.

The clinical joint angles (Cardan ``YXZ`` with Plug-in Gait's signs and order,
:func:`clinical_angles`), the general remap that Vicon's other outputs use
(:func:`cardan_outputs`: the foot progression, :data:`FOOT_PROGRESSION`, and the upper
body, :data:`mocap.plugingait.upper.ANGLES`) and the progression frame they are taken
in (:func:`progression_frame`).  Frames are rotation matrices (frames, 3, 3) whose
columns are the segment's x, y, z axes in lab coordinates; angles are in degrees.
:mod:`mocap.plugingait.model` re-exports every name here.
"""
from __future__ import annotations

import numpy as np

from mocap.rotations.angles import unwrap_columns
from mocap.rotations.euler import euler_from_components

def frame_from_axes(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Rotation matrices with columns x, y, z, shape (frames, 3, 3)."""
    return np.stack([x, y, z], axis=-1)


def yxz_angles(proximal: np.ndarray, distal: np.ndarray) -> np.ndarray:
    """Cardan YXZ angles (degrees) of ``proximalᵀ distal``, shape (frames, 3).

    ``R = Ry(a1) Rx(a2) Rz(a3)``: a1 in (-180, 180], a2 in [-90, 90], a3 in
    (-180, 180]; NaN where either rotation is NaN.
    """
    r = np.einsum("...ji,...jk->...ik", proximal, distal)
    # the one Euler/Cardan decomposition: intrinsic YXZ
    return euler_from_components(np.moveaxis(r, (-2, -1), (0, 1)), "YXZ")


#: Clinical sign of (a1, a2, a3) per joint and side, and an offset of a1 (degrees):
#: flexion, adduction / varus / obliquity-up / inversion, internal rotation /
#: forward positive (see the module docstring and docs/plugingait.md).
_CLINICAL = {
    ("pelvis", "l"): ((1, 1, -1), (0, 1, 2)),
    ("pelvis", "r"): ((1, -1, 1), (0, 1, 2)),
    ("hip", "l"): ((-1, -1, -1), (0, 1, 2)),
    ("hip", "r"): ((-1, 1, 1), (0, 1, 2)),
    ("knee", "l"): ((1, -1, -1), (0, 1, 2)),
    ("knee", "r"): ((1, 1, 1), (0, 1, 2)),
    # the foot's z runs backwards along it: a1 is -90 at neutral; a3 is about
    # the foot's long axis (inversion), a2 about its vertical x (rotation)
    ("ankle", "l"): ((-1, -1, -1), (0, 2, 1)),
    ("ankle", "r"): ((-1, 1, 1), (0, 2, 1)),
}


def clinical_angles(proximal: np.ndarray, distal: np.ndarray, joint: str, side: str
                    ) -> np.ndarray:
    """Plug-in Gait's <Side><Joint>Angles (flexion, adduction, rotation), degrees."""
    raw = yxz_angles(proximal, distal)
    if joint == "ankle":
        raw[..., 0] += 90.0
        raw[..., 0] = (raw[..., 0] + 180.0) % 360.0 - 180.0
    signs, order = _CLINICAL[(joint, side)]
    return raw[..., list(order)] * np.asarray(signs, dtype=float)


def cardan_outputs(proximal: np.ndarray, distal: np.ndarray, sequence: str,
                   order: tuple, signs: tuple, offsets: tuple) -> np.ndarray:
    """Vicon's X, Y, Z of a Cardan sequence of ``proximalᵀ distal``, degrees (frames, 3).

    Component k is ``signs[k] * a[order[k]] + offsets[k]``, wrapped to (-180, 180], of
    the ``sequence`` angles ``a`` (:func:`mocap.rotations.euler.euler_from_components`);
    ``proximal`` and ``distal`` are rotations (frames, 3, 3); NaN where either is NaN.
    The foot progression's convention (:data:`FOOT_PROGRESSION`) and the upper body's
    (:data:`mocap.plugingait.upper.ANGLES`) are written this way.
    """
    r = np.einsum("...ji,...jk->...ik", proximal, distal)
    raw = euler_from_components(np.moveaxis(r, (-2, -1), (0, 1)), sequence)
    out = raw[..., list(order)] * np.asarray(signs, dtype=float) + np.asarray(offsets, float)
    return 180.0 - (180.0 - out) % 360.0


#: Vicon's ``<Side>FootProgressAngles`` per side: (order, signs, offsets) of the ``YXZ``
#: angles of ``progressionᵀ foot`` (:func:`cardan_outputs`): X is -90 with the foot level
#: (the foot's z runs backwards), lower with the toes up; Y inversion; Z internal (the
#: toes towards the midline).  Found on the angles Vicon stored beside its own segment
#: outputs (tests/mocap/plugingait/test_upper.py, < 0.001°).
FOOT_PROGRESSION = {"l": ((0, 2, 1), (1, 1, -1), (0, 0, 0)),
                    "r": ((0, 2, 1), (1, -1, 1), (0, 0, 0))}


def foot_progression_angles(progression: np.ndarray, foot: np.ndarray, side: str
                            ) -> np.ndarray:
    """Vicon's ``<Side>FootProgressAngles`` (X, Y, Z), degrees (frames, 3).

    Parameters
    ----------
    progression : ndarray, shape (3, 3) or (frames, 3, 3)
        The progression frame (:func:`progression_frame`).
    foot : ndarray, shape (frames, 3, 3)
        The anatomical foot (``kinematics(...).frames["l_foot"]``).
    side : str
        ``"l"`` or ``"r"``.

    Returns
    -------
    ndarray, shape (frames, 3)
        :data:`FOOT_PROGRESSION`'s components, each continuous over the frames as Vicon
        writes it: whole turns removed (:func:`mocap.rotations.angles.unwrap_columns`;
        the first valid frame keeps its value in (-180, 180]); NaN where the foot is.
    """
    progression = np.broadcast_to(progression, foot.shape)
    return unwrap_columns(cardan_outputs(progression, foot, "YXZ", *FOOT_PROGRESSION[side]))


def progression_frame(origin: np.ndarray, pelvis: np.ndarray, min_travel: float = 0.2
                      ) -> np.ndarray:
    """The walking direction's frame (3, 3): x along the progression, z up.

    The progression is the lab's horizontal axis (±X or ±Y) along which the
    pelvis origin travels most from the first to the last valid frame, as
    Plug-in Gait takes it; when it travels less than ``min_travel`` metres (a
    static trial), the axis nearest the pelvis's mean forward direction.
    ``origin`` is (frames, 3), metres; ``pelvis`` (frames, 3, 3).
    """
    valid = np.isfinite(origin).all(axis=1)
    if valid.sum() >= 2:
        idx = np.flatnonzero(valid)
        travel = origin[idx[-1], :2] - origin[idx[0], :2]
    else:
        travel = np.zeros(2)
    if np.hypot(*travel) < min_travel:
        forward = np.nanmean(pelvis[..., 0], axis=0)
        travel = forward[:2] if np.isfinite(forward).all() else np.array([1.0, 0.0])
    axis = int(np.argmax(np.abs(travel)))
    x = np.zeros(3)
    x[axis] = np.sign(travel[axis]) or 1.0
    z = np.array([0.0, 0.0, 1.0])
    return frame_from_axes(x, np.cross(z, x), z)
