"""Joint-angle throughput: segment frames + relative rotations + Euler angles.

Prints segment-frames per second for 100 000 frames x 15 segments (the
synthetic15 marker set) through the vectorised path, beside a plain per-frame
Python reference (a loop over frames and segments calling numpy and scipy for
each) on fewer frames, and the ratio.  Timings are noisy on a shared machine:
compare the ratio, not the absolute figures.  Never asserts.

    /tmp/venv/bin/python benchmarks/angles.py [--frames 100000] [--reference-frames 2000]
"""
from __future__ import annotations

import argparse
import os
import statistics
import time
import warnings

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.rotations.angles import (GimbalLockWarning, joint_angles, matrices_to_angles,
                          relative_rotations)
from mocap.rotations.frames import segment_frames
from mocap.markersets import load_markerset
from mocap.trial import Trial


def make_trial(markerset, frames: int, seed: int = 0) -> Trial:
    """Markers of a smoothly moving tree: 3 per segment (origin, +0.1 e1, +0.1 e2)."""
    rng = np.random.default_rng(seed)
    segments = len(markerset.segments)
    t = np.arange(frames) / 100.0
    amplitude = rng.uniform(10, 40, (segments, 3))
    frequency = rng.uniform(0.5, 2.0, (segments, 3))
    phase = rng.uniform(0, 2 * np.pi, (segments, 3))
    angles = amplitude * np.sin(2 * np.pi * frequency * t[:, None, None] + phase)
    rot = Rotation.from_euler("ZXY", angles.reshape(-1, 3), degrees=True).as_matrix() \
        .reshape(frames, segments, 3, 3)
    origin = rng.normal(scale=0.3, size=(segments, 3)) + 0.01 * t[:, None, None]
    points = np.stack([origin, origin + 0.1 * rot[..., 0], origin + 0.1 * rot[..., 1]],
                      axis=2).reshape(frames, 3 * segments, 3)
    labels = [m for s in markerset.segments for m in s.markers]
    return Trial(labels, points, 100.0)


def reference(trial: Trial, markerset, sequence: str) -> np.ndarray:
    """Plain per-frame loop: numpy per segment, one scipy call per joint and frame."""
    columns = markerset.marker_columns(trial.labels)
    parents = markerset.parent_index
    out = np.empty((trial.frames, len(parents), 3))
    for f in range(trial.frames):
        frames = []
        for s in range(len(parents)):
            p1, p2, p3 = trial.points[f, columns[s, :3]]
            e1 = (p2 - p1) / np.linalg.norm(p2 - p1)
            e3 = np.cross(e1, p3 - p1)
            e3 /= np.linalg.norm(e3)
            frames.append(np.column_stack([e1, np.cross(e3, e1), e3]))
        for s, parent in enumerate(parents):
            relative = frames[s] if parent < 0 else frames[parent].T @ frames[s]
            out[f, s] = Rotation.from_matrix(relative).as_euler(sequence, degrees=True)
    return out


def median_of(function, repeats: int) -> tuple[float, float]:
    """Median wall-clock and median CPU (process) time of ``repeats`` runs, seconds.

    On a shared machine the wall clock includes time the process waited for a
    core; the CPU time is what one core spent, the figure the target is about.
    """
    wall, cpu = [], []
    for _ in range(repeats):
        start, start_cpu = time.perf_counter(), time.process_time()
        function()
        wall.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return statistics.median(wall), statistics.median(cpu)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=100_000)
    parser.add_argument("--reference-frames", type=int, default=2000)
    parser.add_argument("--sequence", default="ZXY")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()

    markerset = load_markerset("synthetic15")
    segments = len(markerset.segments)
    trial = make_trial(markerset, args.frames)
    small = make_trial(markerset, args.reference_frames)

    def whole_arrays():
        # the public building blocks on whole-trial arrays
        rotations, _ = segment_frames(trial, markerset)
        relative = relative_rotations(rotations, markerset.parent_index)
        return matrices_to_angles(relative, args.sequence)

    def full():
        # the product path: frames + relative rotations + Euler angles, block by
        # block of frames, plus unwrapping and the gimbal-lock check
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", GimbalLockWarning)
            return joint_angles(trial, markerset, args.sequence)

    full_s, full_cpu = median_of(full, args.repeats)
    whole_s, whole_cpu = median_of(whole_arrays, args.repeats)
    ref_s, ref_cpu = median_of(lambda: reference(small, markerset, args.sequence), 1)

    # the vectorised and per-frame paths agree (principal values) on the small trial
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        vectorised = joint_angles(small, markerset, args.sequence, unwrap=False).values
    difference = np.abs(vectorised - reference(small, markerset, args.sequence)).max()

    work = args.frames * segments
    ref_work = args.reference_frames * segments
    print(f"joint angles, {args.frames} frames x {segments} segments, sequence {args.sequence}; "
          f"medians of {args.repeats} runs, load average {os.getloadavg()[0]:.1f}; "
          f"M segment-frames/s by wall clock and (per CPU second)")
    rows = [("joint_angles: frames+relative+Euler, unwrap, gimbal check", full_s, full_cpu, work),
            ("whole-trial segment_frames+relative_rotations+matrices_to_angles", whole_s,
             whole_cpu, work),
            (f"per-frame Python reference ({args.reference_frames} frames)", ref_s, ref_cpu,
             ref_work)]
    for name, wall, cpu, count in rows:
        print(f"  {name:66s} {wall:7.3f} s  {count / wall / 1e6:7.3f}  ({count / cpu / 1e6:.3f})")
    ratio_wall = (work / full_s) / (ref_work / ref_s)
    ratio_cpu = (work / full_cpu) / (ref_work / ref_cpu)
    rate_cpu = work / full_cpu
    print(f"  ratio joint_angles / reference: {ratio_wall:.0f} x wall ({ratio_cpu:.0f} x CPU)")
    print(f"  target 3 M segment-frames/s on one core: "
          f"{'met' if rate_cpu >= 3e6 else 'NOT met'} ({rate_cpu / 1e6:.2f} M per CPU second)")
    print(f"  max |vectorised - reference| = {difference:.2e} degrees")
    plugingait_throughput(args.frames, args.repeats)


def plugingait_throughput(frames: int, repeats: int) -> None:
    """Clinical Plug-in Gait angles and the static calibration on a real walk
    tiled to ``frames`` frames (skipped without ../shared/realdata)."""
    from pathlib import Path

    from mocap.plugingait.calibration import calibrate
    from mocap.plugingait.clinical import plugingait_angles
    from mocap.io import read
    from mocap.plugingait.model import CLINICAL_SEGMENTS, SIDES, subject_from_trial
    from mocap.trial import Trial

    root = Path(__file__).resolve().parents[1].parent / "shared" / "realdata" / \
        "biomechzoo_sample_study" / "HC002D"
    if not root.exists():
        print("  plugingait: real-data corpus not found, skipped")
        return
    walk, static = read(root / "Straight" / "HC002D06.c3d"), read(root / "Static" / "HC002D02.c3d")
    tile = -(-frames // walk.frames)
    # a new Trial: with_points keeps the frame count
    long_walk = Trial(walk.labels, np.tile(walk.points, (tile, 1, 1))[:frames], walk.rate,
                      parameters=walk.parameters)
    long_static = Trial(static.labels, np.tile(static.points,
                                               (-(-frames // static.frames), 1, 1))[:frames],
                        static.rate, parameters=static.parameters)
    subject = calibrate(static, subject_from_trial(walk), flat_foot=True)
    angles_s, angles_cpu = median_of(lambda: plugingait_angles(long_walk, subject=subject), repeats)
    calib_s, calib_cpu = median_of(lambda: calibrate(long_static, subject_from_trial(walk),
                                                   flat_foot=True), repeats)
    joints = len(SIDES) * len(CLINICAL_SEGMENTS)
    print(f"  plugingait_angles ({frames} frames x {joints} angles, foot progression "
          f"included): {angles_s:.3f} s, "
          f"{frames * joints / angles_cpu / 1e6:.2f} M angle-frames per CPU second")
    print(f"  calibrate (a {frames}-frame static): {calib_s:.3f} s, "
          f"{frames / calib_cpu / 1e6:.2f} M frames per CPU second (whole-array, no frame loop)")

if __name__ == "__main__":
    main()
