"""Do a walk's and its static's PROCESSING groups disagree, and does reading the static's
first change any angle?

Over every real walk with Vicon's angles and a static (the pairs of
``tests/mocap/plugingait/test_clinical.py``): the subject values where the two groups
differ, then the clinical angles with the static's PROCESSING read first (today's
``prepare_subject``) against the walk's first (a ``Subject`` from the walk's group, the
static's filling the rest, as ``prepare_subject`` did before), max absolute difference in
degrees per pair, lower body; the upper-body measurements and body mass compared too.

Run: ``python benchmarks/plugingait_sources.py``
"""
from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mocap.io import read  # noqa: E402
from mocap.plugingait.clinical import _merge, plugingait_angles  # noqa: E402
from mocap.plugingait.kinetics import body_mass_of  # noqa: E402
from mocap.plugingait.model import SIDES, subject_from_trial  # noqa: E402
from mocap.plugingait.upper import upper_subject_from_trial  # noqa: E402
from tests.mocap.plugingait.test_clinical import plugingait_pairs  # noqa: E402

ROOT = Path(__file__).resolve().parents[2] / "shared" / "realdata"
KEYS = ("leg_length", "asis_trochanter", "knee_width", "ankle_width", "tibial_torsion",
        "thigh_rotation", "shank_rotation")


def differences(walk, static) -> list[str]:
    a, b = subject_from_trial(walk), subject_from_trial(static)
    out = [f"{key} walk {getattr(a, key)} static {getattr(b, key)}"
           for key in ("marker_diameter", "inter_asis") if getattr(a, key) != getattr(b, key)]
    out += [f"{key}[{side}] walk {getattr(a, key)[side]:.4g} static {getattr(b, key)[side]:.4g}"
            for key in KEYS for side in SIDES if getattr(a, key)[side] != getattr(b, key)[side]]
    if upper_subject_from_trial(walk, static) != upper_subject_from_trial(static, walk):
        out.append("upper-body measurements")
    if body_mass_of(walk, static) != body_mass_of(static, walk):
        out.append("body mass")
    return out


def main() -> None:
    pairs = plugingait_pairs(ROOT)
    changed, worst = 0, 0.0
    for walk_path, static_path in pairs:
        walk, static = read(walk_path), read(static_path)
        walk_first = _merge(subject_from_trial(walk, source="walk PROCESSING"),
                            subject_from_trial(static, source="static PROCESSING"))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            now = plugingait_angles(walk, static=static, flat_foot="auto").values
            before = plugingait_angles(walk, walk_first, static=static,
                                       flat_foot="auto").values
        both = np.isfinite(now) & np.isfinite(before)
        same_gaps = np.array_equal(np.isfinite(now), np.isfinite(before))
        diff = float(np.max(np.abs(now[both] - before[both]))) if both.any() else 0.0
        changed += diff > 0 or not same_gaps
        worst = max(worst, diff)
        print(f"{walk_path.relative_to(ROOT)} | {static_path.name} | "
              f"{'; '.join(differences(walk, static)) or 'agree'} | max {diff:.3g} deg")
    print(f"{len(pairs)} pairs; angles changed in {changed}; max difference {worst:.3g} deg")


if __name__ == "__main__":
    main()
