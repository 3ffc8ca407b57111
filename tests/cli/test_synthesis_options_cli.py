"""Issue 26's synthesis paths: clips at the corpus' frame rate (``--fps``), every option
used or refused, ``decompose --hold-out``, ``recognize`` ranked by distance in degrees, and
a model that survives its reader going away (``mocap decompose … | head``)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mocap.cli import main
from mocap.io.angles_csv import read_angles_csv
from mocap.io.bvh import read_bvh
from synthesis.model_file import load_model
from tests.cli.test_synthesis_cli import write_corpus
from tests.conftest import realdata_path
from tests.synthesis.test_model import multilinear_corpus

ROOT = Path(__file__).resolve().parents[2]
STYLES = ("active", "elderly", "exhausted")
ACTIONS = ("walk", "raise-up-both-hands")


@pytest.fixture(scope="module")
def corpus():
    return multilinear_corpus()


@pytest.fixture(scope="module")
def folder(tmp_path_factory, corpus):
    return write_corpus(tmp_path_factory.mktemp("corpus"), corpus)


@pytest.fixture(scope="module")
def rig_model(tmp_path_factory):
    """A bandai2 model (30 fps BVH, the rig's own joints): 3 styles × walk and raise."""
    bandai = realdata_path("bandai2")
    folder = tmp_path_factory.mktemp("bandai")
    rows = ["path,person,action"] + [
        f"{bandai / f'dataset-2_{action}_{style}_001.bvh'},{style},{action}"
        for style in STYLES for action in ACTIONS]
    (folder / "manifest.csv").write_text("\n".join(rows) + "\n")
    model = folder / "model.npz"
    assert main(["decompose", "--manifest", str(folder / "manifest.csv"), "--samples", "30",
                 "-o", str(model)]) == 0
    return model


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_a_30_fps_corpus_gives_30_fps_clips(rig_model, capsys, tmp_path):
    out = tmp_path / "walk.bvh"
    status, text, err = run(capsys, "synthesize", rig_model, "--person", "active", "--action",
                            "walk", "-o", out)
    assert status == 0, err
    motion = read_bvh(out)
    assert motion.rate == pytest.approx(30.0, rel=1e-6)         # was 109.72 fps on main
    assert "at 30 fps" in text
    status, _, err = run(capsys, "synthesize", rig_model, "--person", "active", "--action",
                         "walk", "--fps", 60, "-o", tmp_path / "walk60.bvh")
    assert status == 0, err
    faster = read_bvh(tmp_path / "walk60.bvh")
    assert faster.rate == pytest.approx(60.0, rel=1e-6)
    assert faster.duration == pytest.approx(motion.duration, abs=1 / 30)
    # the same motion: the 60 fps clip's every other frame is the 30 fps clip
    assert np.allclose(faster.root_translation[::2][:motion.frames],
                       motion.root_translation[:len(faster.root_translation[::2])], atol=1e-3)


@pytest.mark.parametrize("extra, message", [
    (["--skeleton", "{other}", "-o", "{tmp}/w.bvh"], "--skeleton applies to models of marker"),
    (["--samples", "50", "-o", "{tmp}/w.csv"], "--samples sets the frames"),
    (["--weight", "0.3", "-o", "{tmp}/w.bvh"], "--weight is the blend weight of --to"),
    (["--from-action", "walk", "-o", "{tmp}/w.bvh"], "--from-action names the action"),
])
def test_options_a_rig_model_cannot_use_are_refused(rig_model, capsys, tmp_path, extra, message):
    """On main ``--skeleton OTHER.bvh`` was ignored (byte-identical output), and so were
    ``--samples``, ``--weight`` without ``--to`` and ``--from-action`` without ``--from``."""
    other = realdata_path("bandai2", "dataset-2_walk_elderly_002.bvh")
    argv = ["synthesize", rig_model, "--person", "active", "--action", "walk"] + [
        word.format(other=other, tmp=tmp_path) for word in extra]
    status, _, err = run(capsys, *argv)
    assert status == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not any(tmp_path.iterdir())


def test_options_of_a_marker_model_are_used_or_refused(folder, capsys, tmp_path):
    model = tmp_path / "m.npz"
    assert main(["decompose", str(folder), "--samples", "40", "-o", str(model)]) == 0
    capsys.readouterr()
    base = ["synthesize", model, "--person", "p1", "--action", "walk"]
    for extra, message in ((["--skeleton", folder / "p1_walk.csv", "-o", tmp_path / "a.csv"],
                            "an angle CSV has no body"),
                           (["--cycles", 2, "-o", tmp_path / "a.csv"], "--cycles repeats a BVH"),
                           (["--samples", 30, "--fps", 50, "-o", tmp_path / "a.csv"],
                            "not both"),
                           (["--samples", 30, "-o", tmp_path / "a.bvh"], "timed by --fps")):
        status, _, err = run(capsys, *base, *extra)
        assert status == 2 and message in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.npz"]
    # --fps on an angle CSV: the cycle's frames at that rate over its predicted duration
    status, _, err = run(capsys, *base, "-o", tmp_path / "cycle.csv")
    cycle = read_angles_csv(tmp_path / "cycle.csv")
    status, _, err = run(capsys, *base, "--fps", 50, "-o", tmp_path / "fifty.csv")
    assert status == 0, err
    fifty = read_angles_csv(tmp_path / "fifty.csv")
    assert fifty.frames == int(np.floor(cycle.times[-1] * 50 + 1e-9)) + 1
    assert np.allclose(np.diff(fifty.times), np.diff(fifty.times)[0], atol=1e-6)


def test_decompose_hold_out_leaves_the_cell_out(folder, capsys, tmp_path, corpus):
    """``--hold-out p3:run`` gives the model of the corpus without that trial: the same
    synthesis as a model decomposed from a folder lacking the file."""
    held = tmp_path / "held.npz"
    status, out, err = run(capsys, "decompose", folder, "--samples", 40, "--hold-out", "p3:run",
                           "-o", held)
    assert status == 0, err and "held out (not in the model): p3 run" in out
    lacking = write_corpus(tmp_path / "lacking", corpus, skip={("p3", "run")})
    assert main(["decompose", str(lacking), "--samples", "40", "-o", str(tmp_path / "l.npz")]) == 0
    capsys.readouterr()
    assert load_model(held).summary()["missing_cells"] == ["p3_run"]
    for name in ("held", "l"):
        assert main(["synthesize", str(tmp_path / f"{name}.npz"), "--person", "p3", "--action",
                     "run", "-o", str(tmp_path / f"{name}.csv")]) == 0
    assert np.array_equal(read_angles_csv(tmp_path / "held.csv").values,
                          read_angles_csv(tmp_path / "l.csv").values)
    for cell, message in (("p9:run", "no person 'p9'"), ("p3:fly", "no action 'fly'"),
                          ("p3run", "is not PERSON:ACTION")):
        status, _, err = run(capsys, "decompose", folder, "--hold-out", cell, "-o",
                             tmp_path / "x.npz")
        assert status == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.npz").exists()


def test_recognize_ranks_people_by_distance_in_degrees(folder, capsys, tmp_path, corpus):
    model = tmp_path / "m.npz"
    assert main(["decompose", str(folder), "--samples", "40", "-o", str(model)]) == 0
    capsys.readouterr()
    trial = folder / "p2_walk.csv"
    status, out, _ = run(capsys, "recognize", model, trial, "--json")
    result = json.loads(out)
    ranking = result["ranking"]
    distances = [row["distance_deg"] for row in ranking]
    assert distances == sorted(distances) and ranking[0]["person"] == result["person"] == "p2"
    assert {row["person"]: row["distance_deg"] for row in ranking} == result["distances_deg"]
    assert result["margin_deg"] == pytest.approx(distances[1] - distances[0])
    status, out, _ = run(capsys, "recognize", model, trial)
    lines = out.splitlines()
    assert lines[0] == (f"{trial}: p2 doing walk, {distances[1] - distances[0]:.2f}° nearer "
                        f"than {ranking[1]['person']}")
    shown = [line.split() for line in lines[2:]]
    assert [row[0] for row in shown] == [row["person"] for row in ranking]
    # Each person's score beside the distance, as in --json (summing to 1).
    assert [float(row[2]) for row in shown] == \
        [round(result["scores"][row["person"]], 3) for row in ranking]
    assert sum(result["scores"].values()) == pytest.approx(1.0)


def test_decompose_piped_into_head_keeps_its_model(folder, tmp_path):
    """The reader of decompose's summary goes away before it is printed (``| head -0``):
    the model, complete before the summary, stays (main deleted it)."""
    model = tmp_path / "m.npz"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    process = subprocess.Popen([sys.executable, "-m", "mocap", "decompose", str(folder),
                                "--samples", "40", "-o", str(model)], cwd=tmp_path, env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    process.stdout.close()                           # the reader leaves at once
    err = process.stderr.read().decode()
    process.wait(timeout=120)
    assert "Traceback" not in err
    assert model.exists()
    assert load_model(model).people


def test_export_fps_resamples_the_clip(capsys, tmp_path):
    source = realdata_path("bandai2", "dataset-2_walk_active_001.bvh")
    status, _, err = run(capsys, "export", source, "--fps", 60, "-o", tmp_path / "w60.bvh")
    assert status == 0, err
    original, faster = read_bvh(source), read_bvh(tmp_path / "w60.bvh")
    assert faster.rate == pytest.approx(60.0, rel=1e-9)
    assert faster.frames == 2 * original.frames - 1
    # every other frame is an original frame (cm in both files)
    assert np.allclose(faster.root_translation[::2], original.root_translation, atol=1e-6)
    status, _, err = run(capsys, "export", source, "--fps", 60, "--round-rate", "-o",
                         tmp_path / "x.bvh")
    assert status == 2 and "not both" in err and not (tmp_path / "x.bvh").exists()


def test_preview_of_a_synthesised_clip_frames_the_body(rig_model, capsys, tmp_path):
    """The animator's path: a clip synthesised on bandai2's rig, previewed. Its root joint
    travels metres from the hips (the rig's Hips OFFSET is 4.3 m); it is not drawn, and
    the body fills the picture."""
    from PIL import Image

    from dynamics.viz.preview import COLOURS

    clip, gif = tmp_path / "run.bvh", tmp_path / "run.gif"
    assert main(["synthesize", str(rig_model), "--person", "elderly", "--action", "walk",
                 "-o", str(clip)]) == 0
    motion = read_bvh(clip)
    world = motion.forward_kinematics()[1]
    hips = motion.skeleton.names.index("Hips")
    assert np.linalg.norm(world[:, hips] - world[:, 0], axis=1).min() > 2.0
    assert main(["animate", str(clip), "--max-frames", "6", "--dpi", "40", "-o", str(gif)]) == 0
    with Image.open(gif) as image:
        for k in range(image.n_frames):
            image.seek(k)
            rows, columns = np.nonzero((np.asarray(image.convert("RGB"))
                                        == COLOURS["bone"]).all(axis=2))
            assert np.ptp(rows) > 0.6 * image.size[1]          # ~70 px of 400 on main
            assert np.ptp(columns) < 0.9 * image.size[0]       # no 4 m line across
