"""Estimated subject measurements (mocap.plugingait.estimates) against the measured ones.

Eleven subjects of the corpus store Vicon's PROCESSING measurements; alternate subjects
(sorted as below) are the design half, on which the ratios of
``mocap/plugingait/estimates.py`` were chosen (median ratio; the candidates are printed),
the others the held-out half.  For each subject, from one walk: the knee and ankle
widths' error (mm) of each candidate predictor.  Then, on every walk with Vicon's stored
angles: the clinical angles with the measured widths and with the estimated ones (the
static calibrating both), RMS against Vicon's per plane (hip, knee, ankle, both sides;
median over trials × side × joint), and the RMS between the two runs; and the same
without a static, the file's measurements against all four lengths estimated (inter-ASIS
distance, leg lengths, knee and ankle widths; the file's wand rotations and tibial
torsions kept, as no marker gives them).

Run: ``nice python benchmarks/plugingait_estimates.py``
"""
from __future__ import annotations

import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from mocap.io import read
from mocap.plugingait.clinical import plugingait_angles
from mocap.plugingait.estimates import estimate_missing
from mocap.plugingait.model import (MARKERS, PLANES, SIDES, hip_joint_centres,
                                    markers_from_trial, pelvis_frame, subject_from_trial)

ROOT = Path(__file__).resolve().parents[2] / "shared" / "realdata"
ZOO = "biomechzoo_sample_study"
#: subject -> (walks, static or None); alternate subjects are design / held out.
SUBJECTS = {
    "HC002D": (f"{ZOO}/HC002D/Straight/HC002D06.c3d", f"{ZOO}/HC002D/Turn/HC002D25.c3d"),
    "HC030A": (f"{ZOO}/HC030A/Straight/HC030A05.c3d", f"{ZOO}/HC030A/Turn/HC030A22.c3d"),
    "HC031A": (f"{ZOO}/HC031A/Straight/HC031A06.c3d", f"{ZOO}/HC031A/Turn/HC031A23.c3d"),
    "HC032A": (f"{ZOO}/HC032A/Straight/HC032A03.c3d", f"{ZOO}/HC032A/Turn/HC032A18.c3d"),
    "HC033A": (f"{ZOO}/HC033A/Straight/HC033A10.c3d", f"{ZOO}/HC033A/Turn/HC033A22.c3d"),
    "HC036A": (f"{ZOO}/HC036A/Straight/HC036A10.c3d", f"{ZOO}/HC036A/Turn/HC036A23.c3d"),
    "HC038A": (f"{ZOO}/HC038A/Straight/HC038A11.c3d", f"{ZOO}/HC038A/Turn/HC038A27.c3d"),
    "HC039A": (f"{ZOO}/HC039A/Straight/HC039A17.c3d", f"{ZOO}/HC039A/Turn/HC039A31.c3d"),
    "CGM24": ("c3dorg_via_c3dio/sample_00/Vicon_Motion_Systems/"
              "pyCGM2_lower_limb_CGM24_Walking01.c3d",),
    "Drummond": ("c3dorg_via_c3dio/sample_32/vicon_zerowire.c3d",),
    "pyCGM": ("pycgm/Test_Files/Movement_trial.c3d",),
}
STATICS = {**{s: f"{ZOO}/{s}/Static/{next((ROOT / ZOO / s / 'Static').glob('*.c3d')).name}"
              for s in SUBJECTS if s.startswith("HC")},
           "pyCGM": "pycgm/Test_Files/Static_trial.c3d"}
NAMES = list(SUBJECTS)
DESIGN, HELD_OUT = NAMES[0::2], NAMES[1::2]


def features(walk) -> dict:
    """side -> measured widths and candidate predictors (metres), from the walk's markers."""
    s = subject_from_trial(walk)
    m, _ = markers_from_trial(walk, MARKERS)
    pelvis, origin, _ = pelvis_frame(m)
    hips = hip_joint_centres(pelvis, origin, s)
    lengths = estimate_missing(replace(s, inter_asis=None, leg_length={"l": None, "r": None}),
                               m, warn=False, widths=False)
    asis = float(np.nanmedian(np.linalg.norm(m["LASI"] - m["RASI"], axis=1)))
    out = {}
    for side in SIDES:
        S = side.upper()
        hjc, knee, ankle = hips[side], m[f"{S}KNE"], m[f"{S}ANK"]
        axis = (ankle - hjc) / np.linalg.norm(ankle - hjc, axis=1, keepdims=True)
        v = knee - hjc
        off = np.linalg.norm(v - (v * axis).sum(1, keepdims=True) * axis, axis=1)
        reach = np.linalg.norm(ankle - hjc, axis=1)
        out[side] = {
            "kw": s.knee_width[side], "aw": s.ankle_width[side],
            "leg length": s.leg_length[side], "inter-ASIS": s.inter_asis,
            "constant": 1.0, "leg length (est.)": lengths.leg_length[side],
            "LASI-RASI": asis,
            "HEE-TOE": float(np.nanmedian(np.linalg.norm(m[f"{S}HEE"] - m[f"{S}TOE"], axis=1))),
            "KNE off hip-ankle line": float(np.nanmedian(
                off[reach >= np.nanpercentile(reach, 90)]))}
    return out


def measurement_errors(table: dict) -> None:
    for key, label in (("leg length (est.)", "leg length"), ("LASI-RASI", "inter-ASIS")):
        def err(names):
            return np.array([1000 * (table[n][s][key] - table[n][s][label]) for n in names
                             for s in SIDES])
        d, h = err(DESIGN), err(HELD_OUT)
        print(f"{label} estimate (no constant fitted): error mean {d.mean():+.1f}, |max| "
              f"{np.abs(d).max():.1f} mm on design legs; {h.mean():+.1f}, {np.abs(h).max():.1f} "
              f"mm held out")
    for target, label in (("kw", "knee width"), ("aw", "ankle width")):
        print(f"\n{label}: ratio = median over design legs; |error| mean (max), mm")
        for predictor in ("constant", "leg length (est.)", "LASI-RASI", "HEE-TOE",
                          "KNE off hip-ankle line"):
            ratio = np.median([table[n][s][target] / table[n][s][predictor]
                               for n in DESIGN for s in SIDES])

            def err(names):
                return 1000 * np.abs([ratio * table[n][s][predictor] - table[n][s][target]
                                      for n in names for s in SIDES])
            d, h = err(DESIGN), err(HELD_OUT)
            print(f"  {ratio:8.4f} x {predictor:24s} design {d.mean():5.1f} ({d.max():5.1f})"
                  f"   held out {h.mean():5.1f} ({h.max():5.1f})")


def _vicon(trial) -> dict:
    m = trial.modelled or {}
    return {label.rpartition(":")[2]: m["values"][:, k] for k, label in enumerate(m.get("labels", []))}


def _rms(a, b) -> float:
    ok = np.isfinite(a) & np.isfinite(b)
    return float(np.sqrt(np.mean((a[ok] - b[ok]) ** 2))) if ok.sum() > 10 else np.nan


def angle_errors(names) -> None:
    rows = {k: [] for k in ("measured", "estimated", "difference",
                            "measured, no static", "widths estimated, no static",
                            "all estimated, no static", "difference, no static",
                            "widths only, no static", "inter-ASIS only, no static",
                            "leg lengths only, no static")}
    for name in names:
        static = read(ROOT / STATICS[name]) if name in STATICS else None
        for rel in SUBJECTS[name]:
            walk = read(ROOT / rel)
            vicon = _vicon(walk)
            if "LKneeAngles" not in vicon:
                continue
            markers, _ = markers_from_trial(walk, MARKERS)
            measured = subject_from_trial(walk)
            estimated = estimate_missing(
                replace(measured, knee_width={"l": None, "r": None},
                        ankle_width={"l": None, "r": None}), markers, warn=False)
            lengths = estimate_missing(
                replace(measured, inter_asis=None, leg_length={"l": None, "r": None},
                        knee_width={"l": None, "r": None}, ankle_width={"l": None, "r": None}),
                markers, warn=False)
            runs = {"measured": plugingait_angles(walk, static=static) if static else None,
                    "estimated": plugingait_angles(walk, estimated, static=static)
                    if static else None,
                    "measured, no static": plugingait_angles(walk),
                    "widths estimated, no static": plugingait_angles(walk, estimated),
                    "leg lengths estimated, no static": plugingait_angles(
                        walk, estimate_missing(replace(measured, leg_length={"l": None,
                                                                              "r": None}),
                                               markers, warn=False)),
                    "inter-ASIS estimated, no static": plugingait_angles(
                        walk, estimate_missing(replace(measured, inter_asis=None), markers,
                                               warn=False)),
                    "all estimated, no static": plugingait_angles(walk, lengths)}
            for side in SIDES:
                for joint in ("hip", "knee", "ankle"):
                    theirs = vicon[f"{side.upper()}{joint.capitalize()}Angles"]
                    col = f"{side}_{joint}"
                    for key, run in runs.items():
                        if run is not None and key in rows:
                            rows[key].append([_rms(run.segment(col)[:, k], theirs[:, k])
                                              for k in range(3)])
                    for a, b, key in (("measured", "estimated", "difference"),
                                      ("measured, no static", "all estimated, no static",
                                       "difference, no static"),
                                      ("measured, no static", "widths estimated, no static",
                                       "widths only, no static"),
                                      ("measured, no static", "inter-ASIS estimated, no static",
                                       "inter-ASIS only, no static"),
                                      ("measured, no static", "leg lengths estimated, no static",
                                       "leg lengths only, no static")):
                        if runs[a] is not None:
                            rows[key].append([_rms(runs[a].segment(col)[:, k],
                                                   runs[b].segment(col)[:, k])
                                              for k in range(3)])
    print("  deg RMS, median (max) over trial x side x joint (hip, knee, ankle):")
    print("  " + " " * 28 + "".join(f"{p:>18s}" for p in PLANES))
    for key, values in rows.items():
        if values:
            v = np.array(values)
            print(f"  {key:28s}" + "".join(f"{np.nanmedian(v[:, k]):9.2f} ({np.nanmax(v[:, k]):5.2f})"
                                           for k in range(3)))
    print("  per joint, median deg RMS (flexion / adduction / rotation); rows are appended "
          "hip, knee, ankle per side:")
    print("  " + " " * 28 + "".join(f"{j:>20s}" for j in ("hip", "knee", "ankle")))
    for key, values in rows.items():
        if values:
            v = np.array(values)
            print(f"  {key:28s}" + "".join(
                "      " + " / ".join(f"{np.nanmedian(v[j::3, k]):.2f}" for k in range(3))
                for j in range(3)))


def main() -> None:
    warnings.simplefilter("ignore")
    print("design:", ", ".join(DESIGN), "| held out:", ", ".join(HELD_OUT))
    table = {n: features(read(ROOT / SUBJECTS[n][0])) for n in NAMES}
    measurement_errors(table)
    for label, names in (("design", DESIGN), ("held out", HELD_OUT)):
        print(f"\nclinical angles against Vicon's, {label} subjects")
        angle_errors(names)


if __name__ == "__main__":
    main()
