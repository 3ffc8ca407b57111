"""``mocap batch -r --clinical`` over a Subject/Condition/*.c3d tree (issue 26): each walk
with its subject's static, the same clinical angles as the Python API gives."""
from __future__ import annotations

import csv
import io

import numpy as np
import pytest

from mocap.cli import main
from mocap.pipeline import Cleaning, clinical_angles
from tests.conftest import realdata_path

SUBJECTS = ("HC002D", "HC030A")


def rows(text: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))


@pytest.fixture(scope="module")
def study():
    return realdata_path("biomechzoo_sample_study")


def test_batch_walks_the_tree_with_each_subjects_static(study, capsys):
    folders = [str(study / subject) for subject in SUBJECTS]
    assert main(["batch", "-r", "--clinical", "--fill-gaps", "0.2", *folders]) == 0
    table = rows(capsys.readouterr().out)
    walks = sorted(p for s in SUBJECTS for p in (study / s).glob("*/*.c3d")
                   if p.parent.name != "Static")
    assert [row["path"] for row in table] == [str(p) for p in walks]    # statics are no rows
    for row in table:
        walk = study.joinpath(row["path"])
        assert (row["person"], row["action"]) == (walk.parent.parent.name, walk.parent.name)
        static = next((walk.parent.parent / "Static").glob("*.c3d"))
        assert row["static"] == str(static) and row["status"] == "ok"
    # the numbers are the Python API's for the same walk and static
    row = table[0]
    angles = clinical_angles(row["path"], row["static"],
                             cleaning=Cleaning(max_gap_seconds=0.2)).angles
    knee = angles.segments.index("l_knee")
    flexion = angles.values[:, knee, angles.axes.index("flexion")]
    assert float(row["l_knee_flexion_max_deg"]) == pytest.approx(np.nanmax(flexion), abs=1e-3)
    assert float(row["l_knee_flexion_min_deg"]) == pytest.approx(np.nanmin(flexion), abs=1e-3)


def test_batch_static_given_once_and_refusals(study, capsys, tmp_path):
    static = study / "HC030A" / "Static" / "HC030A01.c3d"
    walk = study / "HC030A" / "Straight" / "HC030A05.c3d"
    assert main(["batch", "--clinical", "--static", str(static), str(walk)]) == 0
    (row,) = rows(capsys.readouterr().out)
    assert row["static"] == str(static)
    # a walk without any static nearby: calibrated nowhere, said in its warnings
    assert main(["batch", "--clinical", str(walk), "--json"]) == 0
    captured = capsys.readouterr()
    assert "uncalibrated" in captured.err
    for argv, message in ((["--static", str(static), str(walk)], "go with --clinical"),
                          (["--clinical", "--static", str(tmp_path / "none.c3d"), str(walk)],
                           "static trial not found"),
                          (["--clinical", str(static)], "every trial found is a static")):
        assert main(["batch", *argv]) == 2
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1
