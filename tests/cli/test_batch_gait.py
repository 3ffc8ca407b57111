"""``mocap batch -r --clinical --gait`` over a lab's Subject/Condition/*.c3d archive (issue
22 item 6): each walk with its session's static gets the gait-cycle parameters and the Gait
Profile Score that the library (and ``mocap report``) gives for that walk and static; a walk
too short for a gait cycle still gets a row and a note; Dask gives the same table."""
from __future__ import annotations

import csv
import io
import re
from dataclasses import asdict

import numpy as np
import pytest

from mocap import io as mocap_io
from mocap.cli import main
from mocap.plugingait.normative import lab_reference, read_normative, write_normative
from mocap.plugingait.parameters import VICON_NAMES
from mocap.plugingait.scores import gait_scores
from mocap.plugingait.walks import analyse_walk
from mocap.trial import Trial
from tests.conftest import realdata_path, require_module

SUBJECTS = ("HC002D", "HC030A")
#: Frames kept of a walk for the one without a gait cycle: 0.6 s at 100 Hz, less than a
#: stride (about 0.9 s in these walks).
SHORT_FRAMES = 60


def table(text: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))


@pytest.fixture(scope="module")
def archive(tmp_path_factory):
    """Two subjects of the biomechzoo study as symlinks, plus a walk cut short of a cycle
    (beside HC030A's walks, so it takes HC030A's static) and a walk's markers alone, without
    its force plates (beside HC002D's)."""
    study = realdata_path("biomechzoo_sample_study")
    root = tmp_path_factory.mktemp("archive")
    for subject in SUBJECTS:
        for trial in (study / subject).glob("*/*.c3d"):
            link = root / subject / trial.parent.name / trial.name
            link.parent.mkdir(parents=True, exist_ok=True)
            link.symlink_to(trial)
    short = root / "HC030A" / "Short" / "HC030A99.c3d"
    short.parent.mkdir()
    mocap_io.write(mocap_io.read(study / "HC030A" / "Straight" / "HC030A05.c3d")
                   .slice(0, SHORT_FRAMES), short)
    walk = mocap_io.read(study / "HC002D" / "Straight" / "HC002D06.c3d")
    bare = root / "HC002D" / "NoPlates" / "HC002D98.c3d"
    bare.parent.mkdir()
    mocap_io.write(Trial(walk.labels, walk.points, walk.rate), bare)
    return root


@pytest.fixture(scope="module")
def on_processes(archive, tmp_path_factory):
    out = tmp_path_factory.mktemp("tables") / "processes.csv"
    assert main(["batch", "-r", "--clinical", "--gait", "--jobs", "2", str(archive),
                 "-o", str(out)]) == 0
    return out.read_text()


def _same(cell: str, value: float, decimals: int) -> None:
    if np.isfinite(value):
        assert float(cell) == pytest.approx(value, abs=0.6 * 10.0 ** -decimals)
    else:
        assert cell == ""


def test_each_walk_gets_the_librarys_parameters_and_scores(archive, on_processes):
    rows = table(on_processes)
    walks = sorted(p for p in archive.glob("*/*/*.c3d") if p.parent.name != "Static")
    assert [r["path"] for r in rows] == [str(p) for p in walks]      # statics are no rows
    normative = read_normative()
    full = [r for r in rows if r["action"] in ("Straight", "Turn")]
    assert len(full) == 2 * len(SUBJECTS)
    for row in full:
        assert row["status"] == "ok" and row["static"].endswith(".c3d")
        assert row["static"] == str(next((archive / row["person"] / "Static").glob("*.c3d")))
        analysis = analyse_walk(row["path"], row["static"])
        for p in analysis.parameters:
            context = {"l": "Left", "r": "Right"}[p.side]
            assert int(row[f"{context} Cycles"]) == p.cycles >= 1
            values = asdict(p)
            for key, (name, unit) in VICON_NAMES.items():
                _same(row[f"{context} {name} ({unit})"], values[key], 4)
        scores = gait_scores(analysis.curves, normative)
        _same(row["GPS (deg)"], scores.overall, 3)
        for side, context in (("l", "Left"), ("r", "Right")):
            _same(row[f"{context} GPS (deg)"], scores.gps[side], 3)
            for title, value in zip(scores.titles, scores.gvs[side]):
                _same(row[f"{context} GVS {title} (deg)"], value, 3)
        assert row["events"] == analysis.events
        # a healthy adult's walk: a speed and cadence of walking, not noise
        assert 0.5 < float(row["Left Walking Speed (m/s)"]) < 2.0
        assert 80 < float(row["Right Cadence (steps/min)"]) < 160


def test_a_walk_without_a_cycle_keeps_its_angles_and_says_why(on_processes):
    (row,) = [r for r in table(on_processes) if r["action"] == "Short"]
    assert row["status"] == "ok" and row["static"].endswith("HC030A01.c3d")
    assert int(row["frames"]) == SHORT_FRAMES
    assert float(row["l_knee_flexion_max_deg"]) > float(row["l_knee_flexion_min_deg"])
    assert row["Left Cycles"] == row["Right Cycles"] == "0"
    assert row["Left Cadence (steps/min)"] == "" and row["GPS (deg)"] == ""
    assert "no complete gait cycle" in row["notes"]


def test_a_walk_without_plates_gets_the_same_gait_numbers_and_a_note(on_processes):
    rows = {r["action"]: r for r in table(on_processes) if r["person"] == "HC002D"}
    bare, plated = rows["NoPlates"], rows["Straight"]
    assert "no force plates" in bare["notes"] and "no force plates" not in plated["notes"]
    gait = [key for key in plated if key.startswith(("Left ", "Right ", "GPS"))]
    assert len(gait) == 2 * (1 + len(VICON_NAMES)) + 3 + 18
    assert [bare[key] for key in gait] == [plated[key] for key in gait]
    assert bare["GPS (deg)"] != ""


def test_the_score_is_the_one_mocap_report_prints(archive, on_processes, tmp_path, capsys):
    row = table(on_processes)[0]
    capsys.readouterr()
    assert main(["report", row["path"], "--static", "auto", "-o",
                 str(tmp_path / "report.html")]) == 0
    printed = re.search(r"GPS ([0-9.]+) deg", capsys.readouterr().err)
    assert printed and printed.group(1) == f"{float(row['GPS (deg)']):.1f}"


def test_a_lab_reference_scores_against_itself(archive, tmp_path, capsys):
    walk = archive / "HC002D" / "Straight" / "HC002D06.c3d"
    static = archive / "HC002D" / "Static" / "HC002D02.c3d"
    analysis = analyse_walk(walk, static)
    reference = lab_reference([analysis.curves], "one walk", min_cycles=1)
    write_normative(reference, tmp_path / "lab.json")
    out = tmp_path / "lab.csv"
    assert main(["batch", "--clinical", "--gait", "--static", str(static), str(walk),
                 "--normative", str(tmp_path / "lab.json"), "-o", str(out)]) == 0
    (row,) = table(out.read_text())
    expected = gait_scores(analysis.curves, read_normative(tmp_path / "lab.json")).overall
    _same(row["GPS (deg)"], expected, 3)
    # against the mean of its own two cycles the walk scores far less than against adults'
    assert float(row["GPS (deg)"]) < 0.5 * gait_scores(analysis.curves, read_normative()).overall


def test_dask_gives_the_same_table(archive, on_processes, tmp_path):
    require_module("dask.distributed")
    out = tmp_path / "dask.csv"
    assert main(["batch", "-r", "--clinical", "--gait", "--dask", "--jobs", "1",
                 str(archive), "-o", str(out)]) == 0
    assert out.read_text() == on_processes


def test_refusals_are_one_line(archive, tmp_path, capsys):
    walk = str(archive / "HC002D" / "Straight" / "HC002D06.c3d")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    for argv, message in ((["--gait", walk], "give --clinical"),
                          (["--clinical", "--normative", str(bad), walk], "goes with --gait"),
                          (["--clinical", "--gait", "--normative", str(bad), walk], "bad.json")):
        assert main(["batch", *argv]) == 2
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1
