"""Plug-in Gait angles against Vicon's own outputs stored in the real C3D files.

Every walk in ../shared/realdata that stores Vicon's Plug-in Gait angles
(``LHipAngles`` …) and has a static trial of the same subject is run through
``plugingait_angles(walk, static=static)``; per joint, plane and side the RMS
difference and correlation with Vicon's curves are checked against what a gait
lab signs off (issue 12).  The static calibration is also checked against the
offsets Vicon stored (PROCESSING StaticPlantFlex / StaticRotOff).
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from mocap.plugingait.calibration import calibrate, resolve_flat_foot
from mocap.io import read
from mocap.plugingait.clinical import plugingait_angles
from mocap.plugingait.model import JOINTS, PLANES, SIDES, AnatomicalOffsetWarning, subject_from_trial
from tests.conftest import realdata_path

#: (joint, plane) -> largest RMS against Vicon, degrees (issue 12).
TARGETS = {("pelvis", "flexion"): 2.0, ("hip", "flexion"): 2.0, ("knee", "flexion"): 2.0,
           ("ankle", "flexion"): 2.0, ("hip", "adduction"): 3.0, ("knee", "adduction"): 3.0,
           ("hip", "rotation"): 3.0, ("knee", "rotation"): 5.0}


def _is_static(path: Path) -> bool:
    return "static" in path.name.lower() or "static" in path.parent.name.lower()


def _subject_name(trial) -> str | None:
    names = trial.metadata.get("subjects_names")
    if isinstance(names, list):
        names = names[0] if names else None
    return names.strip() or None if isinstance(names, str) else None


def _vicon_outputs(trial) -> dict:
    """Vicon's modelled outputs by bare name (a subject prefix "Name:" dropped)."""
    modelled = (trial.modelled or {})
    return {label.rpartition(":")[2]: modelled["values"][:, k]
            for k, label in enumerate(modelled.get("labels", []))}


def _has_vicon_angles(trial) -> bool:
    outputs = _vicon_outputs(trial)
    return "LHipAngles" in outputs and "LKneeAngles" in outputs


def plugingait_pairs(root: Path) -> list[tuple[Path, Path]]:
    """(walk, static) of every Plug-in Gait walk with Vicon angles and a static.

    The static is a C3D named or filed as "static" with the Plug-in Gait
    markers, in the walk's folder (the same SUBJECTS:NAMES when both files give
    one) or in a sibling folder (the same SUBJECTS:NAMES, required).
    """
    pairs = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for walk in sorted(root.rglob("*.c3d")):
            if _is_static(walk):
                continue
            try:
                trial = read(walk)
            except Exception:          # unreadable files are other tests' business
                continue
            if not _has_vicon_angles(trial):
                continue
            here = sorted(p for p in walk.parent.glob("*.c3d") if _is_static(p))
            siblings = sorted(p for p in walk.parent.parent.glob("*/*.c3d")
                              if _is_static(p) and p.parent != walk.parent)
            name = _subject_name(trial)
            for candidate in here + siblings:
                standing = read(candidate)
                if not {"LASI", "RASI", "LKNE", "LANK", "LHEE", "LTOE"} <= {
                        label.rpartition(":")[2] for label in standing.labels}:
                    continue
                other = _subject_name(standing)
                same = name == other if candidate in siblings or (name and other) else True
                if same:
                    pairs.append((walk, candidate))
                    break
    return pairs


@pytest.fixture(scope="module")
def pairs():
    found = plugingait_pairs(realdata_path())
    assert len(found) >= 17, found          # 16 biomechzoo walks + pyCGM's movement trial
    return found


def _score(ours: np.ndarray, vicon: np.ndarray) -> tuple[float, float]:
    ok = np.isfinite(ours) & np.isfinite(vicon)
    a, b = ours[ok], vicon[ok]
    return float(np.corrcoef(a, b)[0, 1]), float(np.sqrt(np.mean((a - b) ** 2)))


def vicon_comparison(walk: Path, static: Path) -> dict:
    """{(side, joint, plane): (r, rms)} of our angles against Vicon's."""
    trial, standing = read(walk), read(static)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AnatomicalOffsetWarning)
        angles = plugingait_angles(trial, static=standing, flat_foot="auto")
    outputs = _vicon_outputs(trial)
    out = {}
    for side in SIDES:
        for joint in JOINTS:
            name = f"{side.upper()}{joint.capitalize()}Angles"
            if name not in outputs:
                continue
            vicon = outputs[name]
            ours = angles.segment(f"{side}_{joint}")
            for k, plane in enumerate(PLANES):
                out[(side, joint, plane)] = _score(ours[:, k], vicon[:, k])
    return out


def test_angles_match_vicon_plugingait_on_every_real_trial(pairs):
    worst: dict = {}
    for walk, static in pairs:
        scores = vicon_comparison(walk, static)
        for (side, joint, plane), (r, rms) in scores.items():
            target = TARGETS.get((joint, plane))
            if target is not None:
                assert rms <= target, (walk.name, side, joint, plane, r, rms)
            key = (joint, plane)
            worst[key] = (min(worst.get(key, (1, 0))[0], r), max(worst.get(key, (1, 0))[1], rms))
    print("\njoint plane: lowest r, largest RMS (degrees) over", len(pairs), "trials")
    for (joint, plane), (r, rms) in sorted(worst.items()):
        print(f"  {joint:7s} {plane:9s} r >= {r:.3f}  RMS <= {rms:.2f}")
    # ankle inversion (Vicon's AnkleAngles Y): reported; issue 12 asks r >= 0.9
    assert worst[("ankle", "adduction")][0] >= 0.9


def test_static_offsets_match_those_vicon_stored(pairs):
    checked = 0
    for walk, static in pairs:
        standing, trial = read(static), read(walk)
        stored = subject_from_trial(trial, offsets=True)
        measured_static = subject_from_trial(standing)
        measured_walk = subject_from_trial(trial)
        if measured_static != measured_walk:
            continue   # the subject file changed between the static and the walk
        flat = resolve_flat_foot(standing, measured_walk, "auto", walk=trial)
        ours = calibrate(standing, measured_walk, flat_foot=flat)
        for side in SIDES:
            assert np.degrees(abs(ours.static_plantar_flexion[side]
                                  - stored.static_plantar_flexion[side])) < 0.5
            assert np.degrees(abs(ours.static_rotation_offset[side]
                                  - stored.static_rotation_offset[side])) < 0.5
        checked += 1
    assert checked >= 10


def test_tibial_torsion_from_the_medial_malleoli_matches_vicons():
    """The biomechzoo statics carry medial malleolus markers (LMMA, RMMA) and the
    tibial torsion Vicon stored (PROCESSING LTibialTorsion / RTibialTorsion):
    the torsion calibrated from the markers, with the stored one withheld,
    matches it within half a degree.  HC036A is left out: its subject file was
    re-calibrated after the static was saved (see the offsets test above)."""
    from dataclasses import replace

    root = realdata_path("biomechzoo_sample_study")
    statics = sorted(p for p in root.glob("*/Static/*.c3d") if "HC036A" not in p.name)
    assert len(statics) >= 7, statics
    for path in statics:
        static = read(path)
        given = subject_from_trial(static)
        assert all(given.tibial_torsion[s] for s in SIDES), path.name
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ours = calibrate(static, replace(given, tibial_torsion={"l": 0.0, "r": 0.0}))
        for side in SIDES:
            assert abs(np.degrees(ours.tibial_torsion[side] - given.tibial_torsion[side])) \
                < 0.5, (path.name, side)
