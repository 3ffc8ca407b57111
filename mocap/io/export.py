"""Write a motion (skeleton + joint rotations) in any of the toolkit's export formats.

BVH for animation tools, a joint-angle CSV (``docs/formats/angles-csv.md``), C3D/TRC of the joint positions
(Z-up lab, as marker files are), OpenSim ``.mot`` and a JSON document of the skeleton,
quaternions and positions.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.atomic import atomic_path
from mocap.body.angles import motion_joint_angles
from mocap.body.retarget import Z_UP_TO_Y_UP
from mocap.errors import MocapError, one_line
from mocap.io import write
from mocap.io.angles_csv import write_angles_csv
from mocap.io.bvh import write_bvh
from mocap.io.lab import rotate_trial
from mocap.io.mot import write_motion_mot
from mocap.io.opensim_models import write_model_mot
from mocap.trial import Trial

#: The formats :func:`export_motion` writes (``--format`` of ``mocap export``).
EXPORT_FORMATS = ("bvh", "csv", "c3d", "trc", "mot", "json")


def export_motion(motion, path: str | Path, file_format: str, sequence: str = "ZXY",
                  model: str | None = None, up: str = "z",
                  precision: int | None = None, units: str = "cm",
                  round_rate: bool = False, clinical=None) -> list[str]:
    """Write a motion in one of :data:`EXPORT_FORMATS` (all-or-nothing).

    Parameters
    ----------
    motion : mocap.skeleton.Motion
        The motion (BVH convention: Y up, metres).
    path : path-like
        Output file; written to a temporary name and renamed when complete.
    file_format : str
        One of :data:`EXPORT_FORMATS`.
    sequence : str
        Euler sequence of the angle outputs (``csv``, ``mot``), scipy convention.
    model : {"gait2392", "rajagopal"}, optional
        ``mot``: write the coordinates of this OpenSim model
        (:mod:`mocap.io.opensim_models`) instead of the generic joint angles.
    up : {"z", "y"}
        ``c3d``, ``trc``: the written lab's vertical axis (:mod:`mocap.io.lab`).
    precision : int, optional
        Decimal places of ``trc`` coordinates and ``mot`` values.
    units : {"cm", "m", "mm", "in"}
        Length unit of a BVH output (Blender works in metres).
    round_rate : bool
        Resample a BVH output to the nearest whole frame rate (default: kept exactly).
    clinical : JointAngles, optional
        ``mot`` with ``model``: Plug-in Gait's calibrated clinical angles of the motion's
        frames, which give the hip, knee and ankle coordinates
        (:func:`mocap.io.opensim_models.model_coordinates`).

    Returns
    -------
    list of str
        Notes on what a reader of the file will see differently: for ``c3d`` and
        ``trc``, the joint markers written at exactly the lab origin (C3D and TRC
        readers, the toolkit's own and Qualisys's convention, read a marker at
        (0, 0, 0) as a gap, so a rig whose root joint stays there, Bandai Namco's
        ``joint_Root``, reads back missing).
    """
    notes: list[str] = []
    if file_format == "bvh":
        write_bvh(motion, path, units=units, round_rate=round_rate)
    elif file_format == "mot" and model:
        write_model_mot(motion, path, model, precision=6 if precision is None else precision,
                        clinical=clinical)
    elif file_format == "mot":
        write_motion_mot(motion, path, sequence=sequence)
    elif file_format == "csv":
        write_angles_csv(motion_joint_angles(motion, sequence, body=False), path)
    elif file_format in ("c3d", "trc"):
        world = motion.forward_kinematics()
        index, ends = motion.end_site_positions(world)
        points = np.concatenate([world[1], ends], axis=1) @ Z_UP_TO_Y_UP   # Y up → Z-up lab
        labels = list(motion.names) + [f"{motion.names[i]}_end" for i in index]
        trial = rotate_trial(Trial(labels, points, motion.rate, units="m",
                                   format=file_format), up)
        write(trial, path, **({"precision": precision} if file_format == "trc" else {}))
        at_origin = np.all(world[1] == 0.0, axis=2).sum(axis=0)      # frames per joint
        named = [f"{one_line(motion.names[j])} ({at_origin[j]} of {motion.frames} frames)"
                 for j in np.flatnonzero(at_origin)]
        if named:
            notes.append(", ".join(named) + " at exactly (0, 0, 0), which C3D and TRC "
                         "readers (mocap's too) read as a gap")
    elif file_format == "json":
        sk = motion.skeleton
        quats = Rotation.from_matrix(motion.rotations.reshape(-1, 3, 3)).as_quat()
        positions = motion.forward_kinematics()[1]
        document = {
            "rate_hz": motion.rate, "frames": motion.frames, "up": "y", "units": "m",
            "joints": list(sk.names), "parents": list(sk.parents),
            "offsets": np.round(sk.offsets, 6).tolist(),
            "end_sites": [None if not np.isfinite(e).all() else np.round(e, 6).tolist()
                          for e in sk.end_sites],
            "root_translation": np.round(motion.root_translation, 6).tolist(),
            "rotations_xyzw": np.round(quats.reshape(motion.frames, sk.count, 4), 7).tolist(),
            "positions": np.round(positions, 6).tolist(),
        }
        if motion.translations is not None:     # joints moved per frame (BVH positions)
            document["translations"] = np.round(motion.translations, 6).tolist()
        with atomic_path(path) as tmp:
            tmp.write_text(json.dumps(document), encoding="utf-8")
    else:
        raise MocapError(f"unknown export format {file_format!r}: use one of "
                         + ", ".join(EXPORT_FORMATS))
    return notes
