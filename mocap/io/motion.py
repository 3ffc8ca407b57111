"""The ONE "open any motion file": :func:`read_motion` gives a :class:`~mocap.skeleton.Motion`
from a BVH, an ASF/AMC pair, a joint-angle CSV (``docs/formats/angles-csv.md``, on the 15-segment body) or a
marker trial (C3D/TRC/CSV) with its marker set."""
from __future__ import annotations

import os
import warnings
from pathlib import Path

from mocap.body.angles import motion_from_angles
from mocap.body.retarget import motion_from_trial
from mocap.body.segments import BODY_SEGMENTS, map_segments, read_joint_map
from mocap.errors import MocapError, MocapWarning
from mocap.io import file_kind, motion_suffixes, read, suffixes
from mocap.io.angles_csv import read_angles_csv
from mocap.io.asfamc import read_asf_amc
from mocap.io.bvh import read_bvh
from mocap.io.discovery import find_asf
from mocap.markersets import load_markerset
from mocap.skeleton import Motion

#: Marker-trial suffixes :func:`read_motion` turns into motions with a marker set (the
#: registry's marker formats).
MARKER_SUFFIXES = suffixes("markers")
#: Suffixes :func:`read_motion` reads directly as motions.
MOTION_SUFFIXES = motion_suffixes()


def read_motion(path: str | os.PathLike, asf: str | os.PathLike | None = None,
                units: str | None = None, markerset: str | None = None,
                rate: float = 120.0, joint_map: str | os.PathLike | dict | None = None
                ) -> Motion:
    """A :class:`Motion` from any motion file: BVH, ASF/AMC, joint angles or markers.

    Parameters
    ----------
    path : str or PathLike
        BVH, AMC, joint-angle CSV, or marker trial (C3D/TRC/CSV).
    asf : str or PathLike, optional
        ASF skeleton of an AMC (default: :func:`~mocap.io.discovery.find_asf`).
    units : str, optional
        Length unit of a BVH/ASF (``m``, ``cm``, ``mm``, ``in``, ``cmu``; default detected).
    markerset : str, optional
        Marker set (preset name or TOML path) of a marker trial.
    rate : float
        Frame rate of an AMC, Hz (the format does not store it).
    joint_map : str, PathLike or dict, optional
        Which joint is which body segment, for rigs whose joint names do not say it: a TOML
        file of ``segment = "joint"`` lines (:func:`~mocap.body.segments.read_joint_map`)
        or such a dict. Checked against the skeleton now; used whenever the motion is
        mapped onto the body (``metadata["joint_map"]``).

    Returns
    -------
    Motion
        Y up, metres; a joint-angle CSV plays on the default 15-segment body.

    Raises
    ------
    MocapError
        Missing or unreadable file, unknown suffix, a marker trial without a marker set, a
        joint map naming joints the skeleton lacks.

    Warns
    -----
    MocapWarning
        One per note the reader left in ``metadata["warnings"]``.
    """
    if joint_map is not None and not isinstance(joint_map, dict):
        joint_map = read_joint_map(joint_map)
    motion = _read(Path(path), asf, units, markerset, rate)
    if joint_map:
        try:
            map_segments(motion.skeleton.names, motion.skeleton.parents, joint_map)
        except MocapError as error:
            raise MocapError(error.problem, path) from None
        motion.metadata["joint_map"] = dict(joint_map)
    for note in motion.metadata.get("warnings", []):
        warnings.warn(f"{os.fspath(path)}: {note}", MocapWarning, stacklevel=2)
    return motion


def _read(path: Path, asf: str | os.PathLike | None, units: str | None,
          markerset: str | None, rate: float) -> Motion:
    if not path.exists():
        raise MocapError("file not found", path)
    if path.is_dir():
        raise MocapError("is a directory, not a motion file", path)
    if not path.is_file():
        raise MocapError("not a regular file (a pipe or device cannot be read)", path)
    suffix = path.suffix.lower()
    try:
        kind = file_kind(path)
    except MocapError:
        kind = None                 # the last line below says what a motion can be
    if suffix == ".bvh":
        return read_bvh(path, units=units)
    if suffix == ".amc":
        skeleton = Path(asf) if asf else find_asf(path)
        if not skeleton.is_file():
            raise MocapError("ASF file not found", skeleton)
        return read_asf_amc(skeleton, path, rate=rate, units=units)
    if kind == "skeleton":
        raise MocapError("an ASF file is the skeleton only: give the AMC motion (and this "
                         "file with asf=)", path)
    if kind == "angles":
        angles = read_angles_csv(path)
        foreign = [s for s in angles.segments if s not in BODY_SEGMENTS]
        if foreign:
            raise MocapError("a joint-angle CSV carries no skeleton, so it plays only on the "
                             "15-segment body (pelvis, thorax, …); it has other segments: "
                             + ", ".join(foreign[:6]) + (" …" if len(foreign) > 6 else "")
                             + " (mocap.body.retarget.reduce_to_segments gives one)", path)
        return motion_from_angles(angles)
    if kind == "markers":
        if not markerset:
            raise MocapError("a marker trial needs markerset= (e.g. synthetic15) to build "
                             "the skeleton", path)
        return motion_from_trial(read(path), load_markerset(markerset))
    raise MocapError("unknown motion file type: use .bvh, .amc, a joint-angle .csv, or a "
                     ".c3d/.trc/.csv marker trial with markerset=", path)
