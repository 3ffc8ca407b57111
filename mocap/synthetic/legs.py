"""The legs: two-link inverse kinematics from the pelvis to the ankle and the foot."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.synthetic.people import SEGMENT_NAMES, Person
from mocap.synthetic.templates import _CLINICAL_SIGNS

def _leg_length(person: Person, knee: np.ndarray | float) -> np.ndarray:
    """Hip-to-ankle distance with the knee flexed by ``knee`` degrees, metres."""
    t, s = person.lengths["thigh"], person.lengths["shank"]
    return np.sqrt(t * t + s * s + 2 * t * s * np.cos(np.radians(knee)))


def _leg_rotations(person: Person, side: str, pelvis: np.ndarray, hip: np.ndarray,
                   ankle: np.ndarray, foot: np.ndarray, clinical: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hip, knee and ankle joint rotations that put the ankle and the foot where asked.

    The knee is a hinge, so the hip-to-ankle distance gives its flexion (two-link inverse
    kinematics); the hip's flexion and abduction point the leg at the ankle; the hip's
    axial rotation is chosen so that the ankle's axial rotation is the template's
    (``clinical``, which carries the knee's axial rotation too); the ankle takes the rest
    of the foot's orientation.

    Parameters
    ----------
    pelvis : (frames, 3, 3) pelvis frame in the lab
    hip, ankle : (frames, 3) joint centres in the lab, metres
    foot : (frames, 3, 3) foot frame in the lab
    clinical : (frames, segments, 3) template angles, degrees

    Returns
    -------
    thigh, shank, foot joint rotations, each (frames, 3, 3).
    """
    shank_i, foot_i = (SEGMENT_NAMES.index(f"{side}_{name}") for name in ("shank", "foot"))
    t, s = person.lengths["thigh"], person.lengths["shank"]
    target = np.einsum("fji,fj->fi", pelvis, ankle - hip)             # in the pelvis frame
    distance = np.linalg.norm(target, axis=1)
    reach = np.minimum(distance, _leg_length(person, 0.5))           # never quite straight
    knee = np.arccos(np.clip((reach**2 - t * t - s * s) / (2 * t * s), -1.0, 1.0))
    target = target * (reach / distance)[:, None]
    leg = np.stack([-s * np.sin(knee), np.zeros_like(knee), -t - s * np.cos(knee)], axis=1)
    knee_joint = Rotation.from_euler(
        "YZ", np.stack([np.degrees(knee), clinical[:, shank_i, 2] * _CLINICAL_SIGNS[shank_i, 2]],
                       axis=1), degrees=True).as_matrix()
    wanted = np.radians(clinical[:, foot_i, 2] * _CLINICAL_SIGNS[foot_i, 2])

    def pose(twist):
        """Hip and ankle joints, and the ankle's axial rotation, for a hip axial rotation."""
        turned = np.stack([leg[:, 0] * np.cos(twist), leg[:, 0] * np.sin(twist), leg[:, 2]],
                          axis=1)
        radius = np.hypot(turned[:, 1], turned[:, 2])
        about_x = -np.arccos(np.clip(target[:, 1] / radius, -1.0, 1.0)) - np.arctan2(
            turned[:, 2], turned[:, 1])
        about_x = (about_x + np.pi) % (2 * np.pi) - np.pi
        rolled_z = turned[:, 1] * np.sin(about_x) + turned[:, 2] * np.cos(about_x)
        about_y = np.arctan2(target[:, 0], target[:, 2]) - np.arctan2(turned[:, 0], rolled_z)
        hip_joint = Rotation.from_euler("YXZ", np.stack([about_y, about_x, twist], axis=1)
                                        ).as_matrix()
        ankle_joint = np.swapaxes(pelvis @ hip_joint @ knee_joint, 1, 2) @ foot
        axial = Rotation.from_matrix(ankle_joint).as_euler("YXZ")[:, 2]
        return hip_joint, ankle_joint, (axial - wanted + np.pi) % (2 * np.pi) - np.pi

    # Secant method on the hip's axial rotation, starting from slope −1 (turning the
    # thigh turns the shank over the foot); the slope stays away from 0 while the knee is
    # not bent past a right angle.
    twist, slope = np.zeros_like(knee), -np.ones_like(knee)
    hip_joint, ankle_joint, error = pose(twist)
    for _ in range(8):
        if np.abs(error).max() < 1e-12:
            break
        step = -np.clip(error / slope, -0.5, 0.5)
        twist = twist + step
        hip_joint, ankle_joint, new_error = pose(twist)
        moved = np.abs(step) > 1e-12
        slope = np.where(moved, (new_error - error) / np.where(moved, step, 1.0), slope)
        slope = np.where(np.abs(slope) > 0.2, slope, -1.0)
        error = new_error
    return hip_joint, knee_joint, ankle_joint
