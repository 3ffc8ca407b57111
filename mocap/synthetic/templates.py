"""Template joint-angle curves of each action and the clinical (flexion, abduction,
rotation) ↔ joint-rotation convention of the generator."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.synthetic.people import _DOFS, ACTIONS, SEGMENT_NAMES, Person, _style_effects

# --------------------------------------------------------------------------- templates

def _bump(u: np.ndarray, centre: float, width: float) -> np.ndarray:
    """Periodic bump on the unit cycle: 1 at ``centre``, about Gaussian with std ``width``."""
    return np.exp((np.cos(2 * np.pi * (u - centre)) - 1.0) / (2 * np.pi * width) ** 2)


def _cos(u: np.ndarray, shift: float = 0.0, harmonic: int = 1) -> np.ndarray:
    return np.cos(2 * np.pi * harmonic * (u - shift))


def _sin(u: np.ndarray, shift: float = 0.0, harmonic: int = 1) -> np.ndarray:
    return np.sin(2 * np.pi * harmonic * (u - shift))


def _stance_knee(action: str, u: np.ndarray) -> np.ndarray:
    """Knee flexion (degrees) the supporting leg aims for over its phase ``u`` (0 = its
    landing); it sets the pelvis height while that leg leads the support."""
    if action == "walk":      # loading response peak, nearly straight in mid-stance
        return 4 + 14 * _bump(u, 0.14, 0.06) + 56 * _bump(u, 0.71, 0.09)
    if action == "run":
        return 18 + 24 * _bump(u, 0.17, 0.06)
    if action == "ascend":    # lands bent on the higher step, then straightens
        return 12 + 48 * _bump(u, 0.0, 0.08) + 80 * _bump(u, 0.73, 0.09)
    return 8 + 78 * _bump(u, 0.55, 0.13) + 22 * _bump(u, 0.86, 0.06)    # descend: lowers


def _action_angles(action: str, u: np.ndarray) -> np.ndarray:
    """Template joint angles of an action: (frames, segments, 3) = (flex, abd, rot) degrees.

    Flexion is about the segment's left axis (e2), abduction about its anterior
    axis (e1), axial rotation about its up axis (e3), in clinical sign
    (flexion, abduction and internal rotation positive on both sides).  Hip, knee
    and ankle flexion and abduction are zero here: they follow from the feet by
    inverse kinematics (:func:`_leg_rotations`); the knee and ankle axial rotations
    are targets for it.  Phase 0 is the right foot's landing: the pelvis is turned
    with the right hip forward and the right arm back.
    """
    intensity = {"walk": 1.0, "run": 1.8, "ascend": 1.2, "descend": 1.0}[action]
    lean = {"walk": 3.0, "run": 10.0, "ascend": 9.0, "descend": 2.0}[action]
    elbow = {"walk": 20.0, "run": 85.0, "ascend": 25.0, "descend": 18.0}[action]
    angles = np.zeros(u.shape + _DOFS)
    index = {name: i for i, name in enumerate(SEGMENT_NAMES)}

    def put(segment: str, flex=0.0, abd=0.0, rot=0.0) -> None:
        angles[:, index[segment]] = np.stack(np.broadcast_arrays(flex, abd, rot, u)[:3], axis=-1)

    # root: pelvis tilt (flex), obliquity (abd: the swing side drops), rotation (yaw)
    put("pelvis", flex=2 + 2 * intensity * _cos(u, 0.1, 2), abd=-4 * intensity * _sin(u, 0.05),
        rot=5 * intensity * _cos(u))
    put("thorax", flex=lean + 1.5 * _cos(u, 0.1, 2), abd=2 * intensity * _sin(u, 0.05),
        rot=-8 * intensity * _cos(u))          # counter-rotates the pelvis
    put("head", flex=-lean + 2 * _cos(u, 0.2, 2), abd=1.5 * _sin(u, 0.1),
        rot=3 * intensity * _cos(u))           # keeps the gaze forward
    for side, phase in (("r", 0.0), ("l", 0.5)):
        v = (u + phase) % 1.0
        put(f"{side}_shank", 0.0, 0.0, 2 * _sin(v, 0.1))
        put(f"{side}_foot", 0.0, 0.0, 2 * _sin(v, 0.3))
        swing = 16 * intensity * _cos(v, 0.55)   # arm swings with the other leg
        put(f"{side}_upperarm", swing, 8 + 2 * _sin(v, 0.25), 3 * _sin(v))
        put(f"{side}_forearm", elbow + 0.5 * swing + 4 * _cos(v, 0.6, 2), 0.0, 4 * _sin(v, 0.2))
        put(f"{side}_hand", 5 + 4 * _sin(v, 0.6), 2 * _sin(v), 0.0)
    return angles


#: Sign of (about +Y, about +X, about +Z) per segment for clinical (flex, abd, rot): limb
#: flexion swings the distal end forward (negative about +Y), trunk and head flexion lean
#: forward (positive about +Y), right abduction moves the limb to −Y, left internal
#: rotation turns it to −Y.
_CLINICAL_SIGNS = np.array([
    (1.0, 1.0, 1.0) if name in ("pelvis", "thorax", "head") else
    (-1.0, -1.0, 1.0) if name.startswith("r_") else (-1.0, 1.0, -1.0)
    for name in SEGMENT_NAMES])


def _to_rotations(clinical: np.ndarray) -> np.ndarray:
    """Clinical (flex, abd, rot) degrees → joint rotation matrices, (frames, segments, 3, 3).

    Applied as intrinsic Y-X-Z (flexion first), signs per ``_CLINICAL_SIGNS``: the knee's
    negative flexion swings the shank back, ankle dorsiflexion lifts the toes.
    """
    euler = (clinical * _CLINICAL_SIGNS).reshape(-1, 3)
    matrices = Rotation.from_euler("YXZ", euler, degrees=True).as_matrix()
    return matrices.reshape(clinical.shape[:-1] + (3, 3))


def _to_clinical(rotations: np.ndarray, segment: int) -> np.ndarray:
    """Inverse of :func:`_to_rotations` for one segment: (frames, 3, 3) → (frames, 3) degrees."""
    euler = Rotation.from_matrix(rotations).as_euler("YXZ", degrees=True)
    return euler * _CLINICAL_SIGNS[segment]


def _template(person: Person, action: str, phase: np.ndarray, seed: int) -> np.ndarray:
    """Template angles with the person's style (gains, offsets, asymmetry),
    (frames, segments, 3) degrees."""
    gains, offsets, action_weights = _style_effects(seed)
    weights = person.style * action_weights[ACTIONS.index(action)]        # (styles,)
    gain = 1.0 + np.tensordot(weights, gains, axes=1)                      # (segments, 3)
    offset = np.tensordot(weights, offsets, axes=1)
    left = np.array([name.startswith("l_") for name in SEGMENT_NAMES])
    gain = gain * np.where(left, 1.0 + person.asymmetry, 1.0)[:, None]
    return offset + gain * _action_angles(action, phase % 1.0)
