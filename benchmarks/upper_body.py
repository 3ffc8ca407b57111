"""Plug-in Gait upper body and foot progression: agreement with Vicon, and time.

Agreement: every real C3D file that stores Vicon's upper-body angles (LThoraxAngles …:
the 24 biomechzoo files, 8 subjects × static, straight and turn, and pyCGM's three) is
run through ``plugingait_angles(..., upper_body=True)`` (walks with their session's
static; a static with itself) and compared with Vicon's stored angles per file × side ×
output × component (RMS over the frames where both exist).  The foot progression, a
lower-body angle, is taken from the same file with its upper-body markers removed
(``plugingait_angles(lower_body_only, static=...)``), as a lower-body marker set gives it.  pyCGM's ROM static has no
subject measurements (no PROCESSING group): only its thorax, spine, neck and head, which
need none, are computed (from the markers, without the lower body).  The files are split
by alternate subjects: design (HC002D, HC031A, HC033A, HC038A, pyCGM's Test subject) and
held out (HC030A, HC032A, HC036A, HC039A, pyCGM's ROM subject).  The one constant chosen
from data, the marker radius of the upper-body joint centres, is chosen on the design
half (lowest median, then mean, RMS of the arms) among the subject's MarkerDiameter / 2
and 7 mm; both halves are printed for both.

With ``--lower-chords`` it also measures what the foot progression (and the lower
body) would gain if the knee and ankle chords used the same 7 mm marker radius as
Vicon's upper body (the lower body keeps ``MarkerDiameter / 2``, docs/plugingait.md):
the walks' per-component RMS, both halves.

With ``--fill`` it measures the gap filling of the thorax and head markers: each blanked
for 20 frames at 30, 50 and 70 % of every walk and filled by ``fill_plugingait`` (from
the other markers of its group, :data:`mocap.plugingait.clinical.UPPER_RIGID_SEGMENTS`)
or by its own cubic spline; the worst upper-body joint-plane RMS inside the gap.

Time: CPU seconds of ``plugingait_angles`` on a walk (lower body only, then with the
upper body) and on the same walk tiled to 100 000 frames, medians of repeats.  Never
asserts.

    .venv/bin/python benchmarks/upper_body.py [--repeats 5] [--skip-agreement] [--lower-chords] [--fill]
"""
from __future__ import annotations

import argparse
import statistics
import time
import warnings
from pathlib import Path

import numpy as np

import mocap.plugingait.upper as upper
from mocap.io import read
from mocap.plugingait.clinical import plugingait_angles, vicon_label
from mocap.plugingait.model import (MARKERS, Kinematics, markers_from_trial, pelvis_frame,
                                    progression_frame)
from mocap.plugingait.upper import (UPPER_JOINTS, UPPER_MARKERS, UpperSubject, upper_angles,
                                    upper_columns, upper_kinematics)
from mocap.trial import Trial

REALDATA = Path(__file__).resolve().parents[1].parent / "shared" / "realdata"
DESIGN = ("HC002D", "HC031A", "HC033A", "HC038A", "pycgm-Test")
TRUNK = ("thorax", "spine", "neck", "head")
ARMS = ("shoulder", "elbow", "wrist")


def files() -> list[tuple[Path, Path, str]]:
    """(trial, its static, subject) of every file that stores Vicon's upper-body angles."""
    out = []
    for folder in sorted((REALDATA / "biomechzoo_sample_study").iterdir()):
        static = sorted((folder / "Static").glob("*.c3d"))[0]
        for walk in [static] + sorted(folder.glob("Straight/*.c3d")) + sorted(
                folder.glob("Turn/*.c3d")):
            out.append((walk, static, folder.name))
    test = REALDATA / "pycgm" / "Test_Files"
    out += [(test / "Movement_trial.c3d", test / "Static_trial.c3d", "pycgm-Test"),
            (test / "Static_trial.c3d", test / "Static_trial.c3d", "pycgm-Test"),
            (REALDATA / "pycgm" / "ROM" / "Sample_Static.c3d", None, "pycgm-ROM")]
    return out


def _stored(trial: Trial) -> dict:
    modelled = trial.modelled
    return {label.rpartition(":")[2]: modelled["values"][:, k]
            for k, label in enumerate(modelled["labels"])}


def trunk_only(trial: Trial) -> dict:
    """Thorax, spine, neck and head angles of a trial without subject measurements."""
    markers, _ = markers_from_trial(trial, MARKERS + UPPER_MARKERS)
    pelvis, origin, _ = pelvis_frame(markers)
    lower = Kinematics({"pelvis": origin}, {"pelvis": pelvis})
    values = upper_angles(lower, upper_kinematics(markers, UpperSubject()),
                          progression_frame(origin, pelvis))
    return dict(zip(upper_columns(), np.moveaxis(values, 1, 0)))


def lower_body_only(trial: Trial) -> Trial:
    """The trial without its upper-body markers (a lower-body marker set)."""
    return trial.select([label for label in trial.labels
                         if label.rpartition(":")[2] not in UPPER_MARKERS])


def agreement(radius: float | None) -> list[tuple]:
    """Rows (subject, file, side, joint, component, RMS degrees, is a static) with the
    upper body's marker radius ``radius`` metres (None: the subject's MarkerDiameter / 2);
    the foot progression (``foot_progress``) from the trial without its upper-body markers."""
    rows = []
    for path, static_path, subject in files():
        trial = read(path)
        joints = UPPER_JOINTS
        if static_path is None:
            ours = trunk_only(trial)
        else:
            static = read(static_path)
            from mocap.plugingait.clinical import prepare_subject

            chosen = radius
            if chosen is None:
                chosen = prepare_subject(trial, static=static, warn=False).radius
            upper.upper_kinematics.__defaults__ = (chosen,)
            try:
                angles = plugingait_angles(trial, static=static, upper_body=True)
            finally:
                upper.upper_kinematics.__defaults__ = (upper.UPPER_MARKER_RADIUS_M,)
            ours = {c: angles.segment(c) for c in upper_columns()}
            lower = plugingait_angles(lower_body_only(trial), static=static)
            ours.update({f"{s}_foot_progress": lower.segment(f"{s}_foot_progress")
                         for s in "lr"})
            joints = UPPER_JOINTS + ("foot_progress",)
        stored = _stored(trial)
        for side in "lr":
            for joint in joints:
                vicon = stored[vicon_label(f"{side}_{joint}")]
                mine = ours[f"{side}_{joint}"]
                for k, component in enumerate("XYZ"):
                    both = np.isfinite(mine[:, k]) & np.isfinite(vicon[:, k])
                    if both.any():
                        rms = float(np.sqrt(np.mean((mine[both, k] - vicon[both, k]) ** 2)))
                        rows.append((subject, path.name, side, joint, component, rms,
                                     static_path in (None, path)))
    return rows


def _summary(rows: list[tuple], label: str) -> None:
    for half, keep in (("design", lambda r: r[0] in DESIGN),
                       ("held out", lambda r: r[0] not in DESIGN)):
        mine = [r for r in rows if keep(r)]
        parts = (("upper body", lambda r: r[3] != "foot_progress"),
                 ("  trunk, head", lambda r: r[3] in TRUNK),
                 ("  arms", lambda r: r[3] in ARMS),
                 ("foot progression", lambda r: r[3] == "foot_progress"),
                 ("  walks", lambda r: r[3] == "foot_progress" and not r[6]),
                 ("  statics", lambda r: r[3] == "foot_progress" and r[6]))
        for name, keep_part in parts:
            rms = np.array([r[5] for r in mine if keep_part(r)])
            print(f"{label:>14s} {half:8s} {name:18s} {len(rms):4d} values  median "
                  f"{np.median(rms):6.3f}  mean {np.mean(rms):6.3f}  max {np.max(rms):7.2f}"
                  f"  over 1 deg {np.sum(rms > 1.0)}")


def lower_chords() -> None:
    """Walks' foot progression and lower-body RMS (lower-body markers only) with the knee
    and ankle chords at the subject's marker radius (as now) and at 7 mm (the widths
    2 × 2 mm wider)."""
    from dataclasses import replace

    from mocap.plugingait.clinical import prepare_subject
    from mocap.plugingait.model import JOINTS

    rms: dict = {}
    for path, static_path, subject in files():
        if static_path in (None, path):
            continue
        trial, static = read(path), read(static_path)
        stored = _stored(trial)
        measured = prepare_subject(trial, static=static, warn=False)
        for variant in ("marker radius", "7 mm"):
            sub = measured
            if variant == "7 mm":
                extra = 2 * (0.007 - measured.radius)
                sub = replace(measured,
                              knee_width={s: w + extra for s, w in measured.knee_width.items()},
                              ankle_width={s: w + extra
                                           for s, w in measured.ankle_width.items()})
            angles = plugingait_angles(lower_body_only(trial), subject=sub)
            for side in "lr":
                outputs = [("foot_progress", "FootProgressAngles")] + [
                    (j, j.capitalize() + "Angles") for j in JOINTS]
                for joint, name in outputs:
                    ours, vicon = angles.segment(f"{side}_{joint}"), stored[side.upper() + name]
                    for k in range(3):
                        both = np.isfinite(ours[:, k]) & np.isfinite(vicon[:, k])
                        difference = (ours[both, k] - vicon[both, k] + 180) % 360 - 180
                        key = (variant, "design" if subject in DESIGN else "held out",
                               "foot progression" if joint == "foot_progress" else "lower body")
                        rms.setdefault(key, []).append(np.sqrt(np.mean(difference ** 2)))
    for (variant, half, part), values in sorted(rms.items()):
        print(f"knee/ankle chords at {variant:13s} {half:8s} {part:16s} {len(values):4d} "
              f"values  median {np.median(values):6.3f} (circular differences)")


def fill(gap: int = 20) -> None:
    """Upper-body angles inside a gap of a thorax or head marker: group fill vs spline."""
    from mocap.clean.gapfill import fill_gaps
    from mocap.plugingait.clinical import (UPPER_RIGID_SEGMENTS, fill_plugingait,
                                           plugingait_labels, prepare_subject)
    from mocap.plugingait.upper import upper_subject_from_trial

    grouped = {name for group in UPPER_RIGID_SEGMENTS for name in group}
    worst: dict = {}
    for path, static_path, subject in files():
        if static_path in (None, path):
            continue
        static = read(static_path)
        trial = read(path)
        trial = trial.select(plugingait_labels(trial, upper_body=True))
        measured = prepare_subject(trial, static=static, warn=False)
        measurements = upper_subject_from_trial(trial, static)
        first = len(upper_columns())

        def angles(t: Trial) -> np.ndarray:
            return plugingait_angles(t, subject=measured, upper_body=True,
                                     upper_subject=measurements).values[:, -first:]

        truth = angles(trial)
        for fraction in (0.3, 0.5, 0.7):
            start = int(trial.frames * fraction) - gap // 2
            inside = slice(start, start + gap)
            for m, label in enumerate(trial.labels):
                if label.rpartition(":")[2] not in grouped or not np.isfinite(
                        trial.points[start - 1:start + gap + 1, m]).all():
                    continue
                points = trial.points.copy()
                points[inside, m] = np.nan
                gapped = trial.with_points(points)
                for method in ("group", "spline"):
                    filled = (fill_plugingait(gapped, measured, gap)[0] if method == "group"
                              else fill_gaps(gapped, max_gap_frames=gap, only=[label])[0])
                    difference = (angles(filled)[inside] - truth[inside]).reshape(gap, -1)
                    rms = np.nan_to_num(np.sqrt(np.nanmean(difference ** 2, axis=0)))
                    key = (method, "design" if subject in DESIGN else "held out")
                    worst.setdefault(key, []).append(float(rms.max()))
    for (method, half), values in sorted(worst.items()):
        values = np.array(values)
        print(f"thorax/head gaps of {gap} frames, {method:6s} fill, {half:8s}: {len(values)} "
              f"gaps, worst upper-body joint-plane RMS median {np.median(values):.3f}, "
              f"p90 {np.percentile(values, 90):.3f}, worst {values.max():.2f}, "
              f"over 1 deg {int((values > 1).sum())}")


def timing(repeats: int) -> None:
    base = REALDATA / "biomechzoo_sample_study" / "HC030A"
    walk, static = read(base / "Straight" / "HC030A05.c3d"), read(base / "Static" / "HC030A01.c3d")
    from mocap.plugingait.clinical import prepare_subject

    subject = prepare_subject(walk, static=static, warn=False)
    long = Trial(walk.labels, np.tile(walk.points, (100_000 // walk.frames + 1, 1, 1))[:100_000],
                 walk.rate, parameters=walk.parameters)
    for name, trial in ((f"{walk.frames}-frame walk", walk), ("100 000 frames", long)):
        times = {}
        for flag in (False, True):
            spent = []
            for _ in range(repeats):
                start = time.process_time()
                plugingait_angles(trial, subject=subject, upper_body=flag)
                spent.append(time.process_time() - start)
            times[flag] = statistics.median(spent)
        print(f"plugingait_angles, {name}: lower body {times[False] * 1e3:8.1f} ms CPU, "
              f"with upper body {times[True] * 1e3:8.1f} ms CPU "
              f"({times[True] / times[False]:.2f}x)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--skip-agreement", action="store_true")
    parser.add_argument("--lower-chords", action="store_true")
    parser.add_argument("--fill", action="store_true")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    if not args.skip_agreement:
        results = {}
        for radius, label in ((None, "radius MD/2"), (0.007, "radius 7 mm")):
            results[label] = rows = agreement(radius)
            _summary(rows, label)
        design_arms = {label: [r[5] for r in rows if r[0] in DESIGN and r[3] in ARMS]
                       for label, rows in results.items()}
        chosen = min(design_arms, key=lambda k: (np.median(design_arms[k]),
                                                 np.mean(design_arms[k])))
        print(f"chosen on the design half: {chosen} "
              f"(mocap.plugingait.upper.UPPER_MARKER_RADIUS_M = "
              f"{upper.UPPER_MARKER_RADIUS_M * 1e3:g} mm)")
    if args.lower_chords:
        lower_chords()
    if args.fill:
        fill()
    timing(args.repeats)


if __name__ == "__main__":
    main()
