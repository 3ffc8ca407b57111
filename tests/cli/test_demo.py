"""mocap demo end to end: every promised output exists and is valid."""
from __future__ import annotations

import json
import re

import numpy as np

from mocap.cli import main


def test_demo_writes_every_promised_output(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "-o", str(out), "--people", "5"]) == 0
    printed = capsys.readouterr().out
    assert "Report:" in printed and str(out / "index.html") in printed
    summary = json.loads((out / "summary.json").read_text())
    # the corpus and one angle CSV per trial
    assert summary["trials"] == 5 * 4
    assert len(list((out / "angles").glob("*_angles.csv"))) == 20
    # synthesis of the held-out walk beats the mean of the other people
    synthesis = summary["synthesis"]
    assert synthesis["synthesis_rms_deg"] < synthesis["baseline_rms_deg"]
    # recognising a person from a walk the model never saw for them is hard: ask only
    # that the answer is one of the corpus' people with a proper score
    people = {p.stem.split("_")[0] for p in (out / "corpus").glob("*.c3d")}
    assert synthesis["recognised_person"] in people
    assert 0 < synthesis["recognition_score"] <= 1
    # the synthesised walk on the person's skeleton, feet planted, passes the check
    assert summary["check"]["foot_skate_mm"] < 5 and summary["check"]["penetration_mm"] < 10
    # the BVH re-reads into a motion with the 15 body segments
    from mocap.io.bvh import read_bvh
    motion = read_bvh(summary["bvh"])
    assert motion.frames > 100 and motion.skeleton.count == 15
    assert np.isfinite(motion.rotations).all()
    # the synthesised CSV re-reads with the model's columns
    from mocap.io.angles_csv import read_angles_csv
    angles = read_angles_csv(next((out / "synthesis").glob("*_synthesised.csv")))
    assert angles.values.shape[1:] == (15, 3) and np.isfinite(angles.values).all()
    # the check is a full report (docs/formats/check-json.md)
    check = json.loads((out / "check.json").read_text())
    assert check["verdict"] in ("plausible", "implausible") and "peak_joint_torque_Nm" in check
    # the GIF is a GIF with many frames
    from PIL import Image
    with Image.open(out / "animation.gif") as gif:
        assert gif.format == "GIF" and gif.n_frames > 20
    # the HTML report references only files that exist
    page = (out / "index.html").read_text()
    references = re.findall(r'(?:src|href)="([^"]+)"', page)
    assert len(references) >= 8
    for reference in references:
        assert (out / reference).exists(), reference
    # ... among them the 3-D view of the captured and synthesised walks, embedded
    assert '<iframe src="view.html"' in page and summary["view"] == str(out / "view.html")
    view = (out / "view.html").read_text()
    assert '"name":"check l_foot"' in view and '"name":"check r_foot"' in view
    assert len(view) < 5e6
    # ... and explains the verdict and the baseline in words, not raw summary keys
    assert "the mean walk of the other 4 people" in page and "Verdict: <b>" in page
    assert "synthesis_rms_deg" not in page and "residual_force_rms_pct_bw" not in page
    # ... says which version wrote it, when and from which command (issue 26) ...
    from mocap.cli import package_version
    made = re.search(r"Written by mocap (\S+) on (\d{4}-\d\d-\d\d \d\d:\d\d) UTC from "
                     r"<code>([^<]+)</code>", page)
    assert made and made.group(1) == package_version()
    assert made.group(3) == f"mocap demo -o {out} --people 5"
    # ... and what the angle names mean
    assert "<code>.Y</code> about the left axis (flexion/extension" in page
    # every path it reports is where the files are now (not the staging folder)
    assert all(str(out) in summary[key] for key in ("output", "corpus", "bvh", "report"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demo"]


def test_demo_rejects_a_corpus_without_walks(tmp_path, capsys):
    from mocap.synthetic import generate_corpus
    generate_corpus(tmp_path / "c", people=2, actions=["run", "ascend"])
    assert main(["demo", "-o", str(tmp_path / "o"), "--data", str(tmp_path / "c")]) == 2
    assert "walk" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_demo_checks_hold_out_and_data_before_writing(tmp_path, capsys):
    assert main(["demo", "-o", str(tmp_path / "o"), "--hold-out", "nobody"]) == 2
    assert "nobody" in capsys.readouterr().err
    assert main(["demo", "--output", str(tmp_path / "o"), "--data", str(tmp_path / "none")]) == 2
    assert "must be a folder" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_demo_refuses_too_few_people_before_starting(tmp_path, capsys):
    """Two people cannot predict one's walk from the other (the model needs 3 to fill the
    held-out cell): it was found out at step 4, after generating and extracting every
    trial (~50 s); now at once, with nothing started or written (hostile harness, issue 11)."""
    assert main(["demo", "-o", str(tmp_path / "o"), "--people", "2", "--no-animation"]) == 2
    out, err = capsys.readouterr()
    assert "[1/" not in out and "--people 2 is too few" in err
    assert list(tmp_path.iterdir()) == []
    from mocap.synthetic import generate_corpus
    generate_corpus(tmp_path / "c", people=3, actions=["walk"])
    assert main(["demo", "-o", str(tmp_path / "o"), "--data", str(tmp_path / "c")]) == 2
    out, err = capsys.readouterr()
    assert "[1/" not in out and "2 actions" in err
    assert not (tmp_path / "o").exists()


def test_demo_body_comes_from_a_trial_on_flat_ground(tmp_path):
    """The synthesised walk's skeleton is built from one of the person's trials whose feet
    stood on one level: emil's ascent (seed 0) stands the left foot a stair's rise up, and
    its left sole came out 0.17 m low (the demo's emil walk then needed 139 % body weight
    of residual); his run gives soles at one height."""
    from mocap.cli.demo import _flat_ground_skeleton
    from mocap.markersets import load_markerset
    from mocap.synthetic import STEP_RISE, generate_corpus

    generate_corpus(tmp_path, people=6, actions=["ascend", "run"], seed=0)
    chosen = load_markerset("synthetic15")

    def sole_gap(skeleton):
        left, right = (skeleton.end_sites[skeleton.index(f"{side}_foot"), 1] for side in "lr")
        return abs(left - right)

    stairs = _flat_ground_skeleton([tmp_path / "emil_ascend.c3d"], chosen)
    assert abs(sole_gap(stairs) - STEP_RISE) < 0.01          # the fault the choice avoids
    flat = _flat_ground_skeleton([tmp_path / "emil_ascend.c3d", tmp_path / "emil_run.c3d"],
                                 chosen)
    assert sole_gap(flat) < 0.01
