"""End-to-end: mocap decompose / synthesize / recognize / evaluate on files."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from mocap.rotations.angles import JointAngles
from mocap.io.angles_csv import read_angles_csv, write_angles_csv
from mocap.cli import main
from tests.synthesis.test_model import SEGMENTS, multilinear_corpus


def write_corpus(folder, corpus, skip=()):
    """Each cell of a MotionCorpus as an angle CSV ``<person>_<action>.csv`` over its duration."""
    folder.mkdir(parents=True, exist_ok=True)
    for p, person in enumerate(corpus.people):
        for a, action in enumerate(corpus.actions):
            if (person, action) in skip:
                continue
            values = corpus.angles[p, a]
            angles = JointAngles(times=np.linspace(0.0, corpus.durations[p, a], len(values)),
                                 values=values.reshape(len(values), len(SEGMENTS), 3),
                                 segments=list(SEGMENTS), sequence="ZXY", parents=[-1, 0, 0, 2])
            write_angles_csv(angles, folder / f"{person}_{action}.csv")
    return folder


@pytest.fixture(scope="module")
def corpus():
    return multilinear_corpus()


@pytest.fixture(scope="module")
def model_path(tmp_path_factory, corpus):
    folder = write_corpus(tmp_path_factory.mktemp("corpus"), corpus, skip={("p3", "run")})
    path = folder.parent / "model.npz"
    assert main(["decompose", str(folder), "--samples", str(corpus.samples), "-o", str(path)]) == 0
    return path


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_decompose_reports_the_model(model_path, capsys, tmp_path, corpus):
    folder = write_corpus(tmp_path / "c", corpus)
    status, out, _ = run(capsys, "decompose", folder, "--samples", 40, "-o", tmp_path / "m.npz",
                         "--json")
    summary = json.loads(out)
    assert status == 0 and summary["missing_cells"] == []
    assert summary["people"] == corpus.people and summary["samples"] == 40
    assert summary["sequence"] == "ZXY" and summary["loo_rms_deg"] < 0.05


def test_synthesize_a_missing_cell_to_csv_with_the_predicted_duration(model_path, capsys,
                                                                      tmp_path, corpus):
    out_csv = tmp_path / "p3_run.csv"
    status, out, _ = run(capsys, "synthesize", model_path, "--person", "p3", "--action", "run",
                         "-o", out_csv)
    assert status == 0 and "wrote" in out
    angles = read_angles_csv(out_csv)
    assert angles.segments == SEGMENTS and angles.sequence == "ZXY"
    assert angles.frames == corpus.samples
    assert angles.times[0] == 0.0
    assert angles.times[-1] == pytest.approx(corpus.durations[3, 2], rel=0.01)
    truth = corpus.angles[3, 2].reshape(corpus.samples, -1, 3)
    assert np.sqrt(np.mean((angles.values - truth) ** 2)) < 0.5
    with open(out_csv, newline="") as handle:
        header = next(csv.reader(handle))
    assert header[:4] == ["time", "pelvis.Z", "pelvis.X", "pelvis.Y"]


def test_synthesize_blend_resampled_and_from_a_new_trial(model_path, capsys, tmp_path, corpus):
    status, _, _ = run(capsys, "synthesize", model_path, "--person", "p0", "--to", "p1",
                       "--weight", 0.3, "--action", "walk", "--samples", 101,
                       "-o", tmp_path / "blend.csv")
    assert status == 0 and read_angles_csv(tmp_path / "blend.csv").frames == 101
    # A captured walk of p5, under another name, is enough to synthesise p5's run.
    trial = write_corpus(tmp_path / "new", corpus.subset(people=["p5"], actions=["walk"]))
    (trial / "p5_walk.csv").rename(trial / "zoe_walk.csv")
    status, _, _ = run(capsys, "synthesize", model_path, "--from", trial / "zoe_walk.csv",
                       "--action", "run", "-o", tmp_path / "zoe_run.csv")
    assert status == 0
    values = read_angles_csv(tmp_path / "zoe_run.csv").values
    truth = corpus.angles[5, 2].reshape(values.shape)
    assert np.sqrt(np.mean((values - truth) ** 2)) < 0.5


def _synthesized_csv(model_path, capsys, tmp_path):
    path = tmp_path / "p1_walk.csv"
    assert main(["synthesize", str(model_path), "--person", "p1", "--action", "walk", "-o",
                 str(path)]) == 0
    capsys.readouterr()
    return path


def test_synthesize_bvh(model_path, capsys, tmp_path, corpus):
    pytest.importorskip("mocap.io.bvh")
    from mocap.io.bvh import read_bvh

    status, _, err = run(capsys, "synthesize", model_path, "--person", "p1", "--action", "walk",
                         "-o", tmp_path / "p1_walk.bvh")
    assert status == 0, err
    motion = read_bvh(tmp_path / "p1_walk.bvh")
    # written at the corpus' frame rate (the median over its files), not the model's sampling
    captured = np.isfinite(corpus.durations)
    captured[3, 2] = False                                  # p3 run, left out of the model
    rate = np.median((corpus.samples - 1) / corpus.durations[captured])
    assert motion.rate == pytest.approx(rate, rel=1e-4)     # the CSV times hold 1 us of 24 ms
    cycle = read_angles_csv(_synthesized_csv(model_path, capsys, tmp_path)).times[-1]
    assert motion.frames == int(np.floor(cycle * motion.rate + 1e-6)) + 1


def test_recognize_json(model_path, capsys, tmp_path, corpus):
    trial = write_corpus(tmp_path / "t", corpus.subset(people=["p4"], actions=["descend"]))
    status, out, _ = run(capsys, "recognize", model_path, trial / "p4_descend.csv", "--json")
    result = json.loads(out)
    assert status == 0
    assert result["person"] == "p4" and result["action"] == "descend"
    assert set(result["scores"]) == set(corpus.people)
    assert result["scores"]["p4"] == max(result["scores"].values())


def test_evaluate_leave_one_out_with_plot(capsys, tmp_path, corpus):
    folder = write_corpus(tmp_path / "c", corpus.subset(people=corpus.people[:5]))
    status, out, _ = run(capsys, "evaluate", folder, "--samples", 40, "--leave-one-out",
                         "--json", "--plot", tmp_path / "loo.png")
    result = json.loads(out)
    assert status == 0
    assert len(result["cells"]) == 20
    assert result["synthesis_rms_deg"] < 0.5 and result["recognition_accuracy"] == 1.0
    assert result["baseline_rms_deg"] > result["synthesis_rms_deg"]
    assert (tmp_path / "loo.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # The paired comparison with the additive model, overall and per action: on an exactly
    # multilinear corpus every cell is won, by the additive model's whole error.
    differences = [c["synthesis_rms_deg"] - c["additive_rms_deg"] for c in result["cells"]]
    assert result["versus_additive"] == {"wins": 20, "losses": 0, "ties": 0,
                                         "median_difference_deg": float(np.median(differences))}
    for action, figures in result["actions"].items():
        mine = [d for c, d in zip(result["cells"], differences) if c["action"] == action]
        assert figures["versus_additive"]["wins"] == len(mine) == 5
        assert figures["versus_additive"]["median_difference_deg"] == \
            pytest.approx(float(np.median(mine)))
    assert result["recognition_top3"] == 1.0
    # Each cell's rank agrees with its top-1 answer (0 exactly when recognised).
    assert all((c["recognised_rank"] == 0) == (c["recognised"] == c["person"])
               for c in result["cells"])
    status, out, _ = run(capsys, "evaluate", folder, "--samples", 40, "--leave-one-out")
    assert "overall RMS joint-rotation error" in out and "person recognition: 20/20" in out
    assert "against the additive model: 20 cells better, 0 worse" in out and "(top 3: 100 %)" in out


@pytest.mark.parametrize("argv, message", [
    (["synthesize", "{model}", "--person", "zed", "--action", "run", "-o", "{tmp}/x.csv"],
     "unknown person 'zed'"),
    (["synthesize", "{model}", "--person", "p0", "--action", "swim", "-o", "{tmp}/x.csv"],
     "unknown action 'swim'"),
    (["synthesize", "{model}", "--person", "p0", "--action", "run", "-o", "{tmp}/x.txt"],
     "output must be an angle CSV"),
    (["synthesize", "{tmp}/none.npz", "--person", "p0", "--action", "run", "-o", "{tmp}/x.csv"],
     "model file not found"),
    (["decompose", "{one_person}", "-o", "{tmp}/x.npz"],
     "need at least 2 people and 2 actions"),
    (["evaluate", "{one_person}"], "--leave-one-out"),
])
def test_user_mistakes_exit_2_with_one_line_and_no_output(argv, message, model_path, capsys,
                                                          tmp_path, corpus):
    one_person = write_corpus(tmp_path / "one", corpus.subset(people=["p0"]))
    argv = [a.format(model=model_path, tmp=tmp_path, one_person=one_person) for a in argv]
    status, out, err = run(capsys, *argv)
    assert status == 2
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.csv").exists() and not (tmp_path / "x.npz").exists()


def test_recognize_answers_unknown_for_a_stranger(model_path, capsys, tmp_path, corpus):
    """A motion far from every known person (here: everyone's mean walk of the action
    shifted by 15 degrees on every angle) is "unknown", not the least unlike person."""
    stranger = corpus.subset(people=["p4"], actions=["descend"])
    stranger.angles[0, 0] = np.nanmean(corpus.angles[:, corpus.actions.index("descend")],
                                       axis=0) + 15.0
    trial = write_corpus(tmp_path / "s", stranger)
    status, out, _ = run(capsys, "recognize", model_path, trial / "p4_descend.csv", "--json")
    result = json.loads(out)
    assert status == 0 and result["person"] == "unknown"
    assert result["nearest_person"] in corpus.people
    assert result["distances_deg"][result["nearest_person"]] > result["max_distance_deg"]
    status, out, _ = run(capsys, "recognize", model_path, trial / "p4_descend.csv")
    assert out.startswith(f"{trial / 'p4_descend.csv'}: unknown person")
