"""A synthesised cycle on the person's own body, feet planted, passes the dynamics check."""
from __future__ import annotations

import json

from mocap.cli import main
from mocap.io import read
from mocap.io.angles_csv import read_angles_csv
from mocap.io.bvh import read_bvh
from mocap.synthetic import generate_corpus


def cycle_seconds(model, capsys, tmp_path) -> float:
    """The duration of ben's synthesised walk cycle (its angle CSV's last time)."""
    path = tmp_path / "walk.csv"
    assert main(["synthesize", str(model), "--person", "ben", "--action", "walk", "-o",
                 str(path)]) == 0
    capsys.readouterr()
    return float(read_angles_csv(path).times[-1])


def test_synthesised_walk_on_the_persons_body_is_plausible(tmp_path, capsys):
    generate_corpus(tmp_path / "corpus", people=5, actions=["walk", "run", "ascend"], seed=2)
    model = tmp_path / "model.npz"
    assert main(["decompose", str(tmp_path / "corpus"), "-m", "synthetic15", "-o", str(model)]) == 0
    bvh = tmp_path / "walk.bvh"
    assert main(["synthesize", str(model), "--person", "ben", "--action", "walk", "--cycles", "2",
                 "--skeleton", str(tmp_path / "corpus" / "ben_run.c3d"), "-o", str(bvh)]) == 0
    motion = read_bvh(bvh)
    capsys.readouterr()
    assert main(["check", str(bvh), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    # the clip comes at the corpus' capture rate, over two cycles of the model's duration
    assert motion.rate == read(tmp_path / "corpus" / "ben_run.c3d").rate
    assert report["frames"] == motion.frames
    # (two cycles of the model's samples join with the seam frame doubled: a frame longer)
    span = (motion.frames - 1) / motion.rate
    assert abs(span - 2 * cycle_seconds(model, capsys, tmp_path)) <= 1.5 / motion.rate
    assert report["residual_force_rms_pct_bw"] < 5.0
    assert report["foot_skate_mm"] < 3.0 and report["penetration_mm"] < 10.0
    assert report["verdict"] == "plausible", report["reasons"]
    # the walk moves forward: about a stride per cycle
    forward = abs(motion.root_translation[-1, 2] - motion.root_translation[0, 2])
    assert 1.5 < forward < 4.0
