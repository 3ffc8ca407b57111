"""The lab's up axis of written files: Z up (C3D, Vicon) or Y up (OpenSim, BVH).

Marker files from capture systems are Z up (X anterior, Y left, Z up: the Vicon and
C3D convention). OpenSim's ground frame is Y up with X anterior and Z to the right.
``--up y`` turns the lab by −90° about X, the rotation OpenSim's own examples apply
to C3D data: (x, y, z) → (x, z, −y). It is a proper rotation (no mirror), so
distances, angles and handedness are kept.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from mocap.errors import MocapError

#: Rotation of a Z-up lab (X anterior, Y left, Z up) into OpenSim's Y-up ground
#: (X anterior, Y up, Z right): ``y_up = Z_TO_Y_UP @ z_up``.
Z_TO_Y_UP = np.array([[1.0, 0.0, 0.0],
                      [0.0, 0.0, 1.0],
                      [0.0, -1.0, 0.0]])

UP_CHOICES = ("z", "y")


def up_rotation(up: str) -> np.ndarray:
    """Rotation (3, 3) taking Z-up lab vectors to the ``up`` convention."""
    if up == "z":
        return np.eye(3)
    if up == "y":
        return Z_TO_Y_UP
    raise MocapError(f"unknown up axis {up!r}: use 'z' (as captured) or 'y' (OpenSim)")


def rotate_trial(trial, up: str):
    """A copy of a Z-up trial with the lab turned to ``up`` (points, segment poses, plates).

    Parameters
    ----------
    trial : Trial
        Points (frames, markers, 3) in a Z-up lab.
    up : {"z", "y"}

    Returns
    -------
    Trial
        The same trial when ``up == "z"``; otherwise a copy whose points, ROTATION
        segment poses (``poses``) and force-plate corners
        (``FORCE_PLATFORM:CORNERS``, lab coordinates) are turned, and whose
        ``metadata["up"]`` says so. Modelled points are not turned (angles are not
        vectors) and are dropped from the copy.
    """
    turn = up_rotation(up)
    if up == "z":
        return trial
    metadata = dict(trial.metadata)
    metadata["up"] = up
    poses = trial.poses.rotated(turn) if trial.poses is not None else None
    parameters = trial.parameters
    if parameters and "FORCE_PLATFORM" in parameters:
        plates = dict(parameters["FORCE_PLATFORM"])
        corners = plates.get("CORNERS")
        if isinstance(corners, np.ndarray) and corners.ndim >= 2 and corners.shape[0] == 3:
            plates["CORNERS"] = np.einsum("ij,j...->i...", turn, corners.astype(float))
        parameters = dict(parameters)
        parameters["FORCE_PLATFORM"] = plates
    copy = replace(trial.with_points(trial.points @ turn.T), metadata=metadata, poses=poses,
                   parameters=parameters, modelled=None)
    return copy
