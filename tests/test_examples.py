"""Every script of examples/ runs as a user runs it (a fresh process, its own output folder)
and gives results that are right, not only files: Plug-in Gait angles equal to the
generator's truth and to Vicon's stored outputs, a synthesised walk closer to the capture
than the baseline, a cape that hangs, moves and stays above the floor."""
from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from mocap import io
from mocap.io.angles_csv import read_angles_csv
from mocap.io.motion import read_motion
from tests.conftest import realdata_path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
CLINICAL = [f"{side}_{joint}" for side in "lr"
            for joint in ("pelvis", "hip", "knee", "ankle", "foot_progress")]


def run_example(name: str, tmp_path: Path, *args) -> str:
    """Run examples/<name> in ``tmp_path``; its stdout (fails with its stderr)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    started = time.perf_counter()
    done = subprocess.run([sys.executable, str(EXAMPLES / name), *map(str, args),
                           "-o", str(tmp_path / "out")], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    print(f"{name}: {time.perf_counter() - started:.1f} s")
    return done.stdout


def rms(a, b) -> float:
    ok = np.isfinite(a) & np.isfinite(b)
    assert ok.mean() > 0.9
    return float(np.sqrt(np.mean((a[ok] - b[ok]) ** 2)))


def test_every_example_is_short_and_tested():
    scripts = sorted(p.name for p in EXAMPLES.glob("*.py"))
    assert scripts == ["bvh_corpus_to_walk.py", "cape_on_a_walk.py", "gait_lab_c3d_walk.py"]
    for script in scripts:
        assert len((EXAMPLES / script).read_text().splitlines()) <= 90, script
        assert "mocap.cli" not in (EXAMPLES / script).read_text()     # the library API only
    gallery = (ROOT / "docs" / "examples.md").read_text()
    assert all(f"examples/{script}" in gallery for script in scripts)


def check_cycles(out: Path) -> list[dict]:
    with open(out / "cycles.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert rows and len(rows) % 101 == 0 and {r["side"] for r in rows} == {"l", "r"}
    with Image.open(out / "cycles.png") as image:
        assert image.format == "PNG" and image.size[0] > 400
    return rows


def test_gait_lab_walk_on_the_generated_c3d_equals_the_generator_truth(tmp_path):
    from mocap.synthetic import synthesize_trial
    from mocap.synthetic.corpus import truth_angles

    stdout = run_example("gait_lab_c3d_walk.py", tmp_path)
    out = tmp_path / "out"
    walk = io.read(out / "generated_walk.c3d")          # a real C3D with Plug-in Gait labels
    assert {"LASI", "RASI", "SACR", "LKNE", "RANK", "LHEE", "RTOE"} <= set(walk.labels)
    angles = read_angles_csv(out / "angles.csv")
    assert angles.segments == CLINICAL and angles.axes == ["flexion", "adduction", "rotation"]
    # the walker's own joint angles (about its segments' y axes) are Plug-in Gait's flexion,
    # hip extension and ankle plantar flexion positive in the walker's (ZXY) convention
    _, truth = synthesize_trial(person=0, action="walk", seed=0, cycles=3)
    exact = truth_angles(truth, "ZXY")
    for side in "lr":
        knee = angles.segment(f"{side}_knee")[:, 0]
        assert rms(knee, exact.segment(f"{side}_shank")[:, 2]) < 3.0
        assert 50 < np.nanmax(knee) < 80
        assert rms(angles.segment(f"{side}_hip")[:, 0], -exact.segment(f"{side}_thigh")[:, 2]) < 3.0
        # dorsiflexion: the foot's rotation about its y axis, the other way round
        assert rms(angles.segment(f"{side}_ankle")[:, 0], -exact.segment(f"{side}_foot")[:, 2]) < 3.0
    rows = check_cycles(out)
    assert len(rows) // 101 >= 2
    assert "cycles" in stdout


def test_gait_lab_walk_on_a_real_vicon_walk_matches_vicons_angles(tmp_path):
    walk = realdata_path("biomechzoo_sample_study", "HC002D", "Straight", "HC002D06.c3d")
    static = realdata_path("biomechzoo_sample_study", "HC002D", "Static", "HC002D02.c3d")
    run_example("gait_lab_c3d_walk.py", tmp_path, walk, "--static", static)
    out = tmp_path / "out"
    angles = read_angles_csv(out / "angles.csv")
    modelled = io.read(walk).modelled
    for label, segment in (("LKneeAngles", "l_knee"), ("RKneeAngles", "r_knee"),
                           ("LHipAngles", "l_hip"), ("RHipAngles", "r_hip"),
                           ("LFootProgressAngles", "l_foot_progress"),
                           ("RFootProgressAngles", "r_foot_progress")):
        vicon = modelled["values"][:, modelled["labels"].index(label), 0]
        assert rms(angles.segment(segment)[:, 0], vicon) < 1.5, label
    check_cycles(out)


def check_synthesis(out: Path, stdout: str) -> dict:
    summary = json.loads((out / "summary.json").read_text())
    assert summary["action"] == "walk"
    assert 0 < summary["synthesis_rms_deg"] < 0.7 * summary["baseline_rms_deg"]
    assert abs(summary["predicted_duration_s"] - summary["captured_duration_s"]) < 0.25
    motion = read_motion(out / f"{summary['person']}_walk_synthesised.bvh")
    assert motion.frames > 200 and np.isfinite(motion.rotations).all()
    travel = np.linalg.norm((motion.root_translation[-1] - motion.root_translation[0])[[0, 2]])
    assert travel > 1.5                                  # three cycles of walking forward
    assert f"synthesised {summary['person']}'s walk" in stdout
    return summary


def test_bvh_corpus_to_walk_on_a_generated_corpus(tmp_path):
    stdout = run_example("bvh_corpus_to_walk.py", tmp_path)
    out = tmp_path / "out"
    assert len(list((out / "corpus").glob("*.bvh"))) == 12       # 4 people x 3 actions
    check_synthesis(out, stdout)


def test_bvh_corpus_to_walk_on_the_bandai_corpus(tmp_path):
    corpus = realdata_path("bandai2")
    stdout = run_example("bvh_corpus_to_walk.py", tmp_path, corpus)
    assert "7 people x 6 actions" in stdout
    check_synthesis(tmp_path / "out", stdout)


def test_cape_on_a_walk_hangs_moves_and_stays_above_the_floor(tmp_path):
    stdout = run_example("cape_on_a_walk.py", tmp_path)
    out = tmp_path / "out"
    data = np.load(out / "cape.npz")
    cape, rope, times = data["cape"], data["rope"], data["times"]
    assert cape.shape[1:] == (9 * 14, 3) and rope.shape[1:] == (10, 3)
    assert cape.shape[0] == rope.shape[0] == len(times) > 100
    assert np.isfinite(cape).all() and np.isfinite(rope).all()
    assert np.all(np.diff(times) > 0)
    height = cape[..., 1]                                # Y up, metres
    assert height.min() > 0.0                            # never through the floor
    assert 0.5 < height.max() - height.min() < 1.5      # from the shoulders, 0.8 m long
    centre = cape.mean(axis=1)
    assert np.linalg.norm(centre[-1] - centre[0]) > 1.0  # carried along by the walker
    springs = data["cape_springs"]
    stretch = np.linalg.norm(cape[:, springs[:, 0]] - cape[:, springs[:, 1]], axis=2)
    rest = np.linalg.norm(cape[0, springs[:, 0]] - cape[0, springs[:, 1]], axis=1)
    assert np.all(stretch < 2.0 * rest + 0.05)          # cloth, not a torn or exploded mesh
    with Image.open(out / "cape.gif") as gif:
        assert gif.format == "GIF" and gif.n_frames > 20
    assert "wrote" in stdout
