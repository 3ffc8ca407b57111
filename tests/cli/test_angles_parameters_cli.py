"""``mocap angles --parameters``: Vicon's gait-cycle parameters, one row per side."""
from __future__ import annotations

import json

import pytest

from mocap.cli import main
from tests.conftest import realdata_path

SUB_LABELS = ("c3dorg_via_c3dio", "sample_04", "sub_labels.c3d")


def test_parameters_csv_and_json(tmp_path, capsys):
    source = realdata_path(*SUB_LABELS)
    for name in ("p.csv", "p.json"):
        status = main(["angles", str(source), "-m", "plugingait-lower", "--no-clinical",
                       "-o", str(tmp_path / "a.csv"), "--parameters", str(tmp_path / name)])
        assert status == 0
    rows = (tmp_path / "p.csv").read_text().splitlines()
    assert rows[0].startswith("Context,Cycles,Cadence (steps/min),Walking Speed (m/s)")
    assert [r.split(",")[0] for r in rows[1:]] == ["Left", "Right"]
    left = json.loads((tmp_path / "p.json").read_text())[0]
    # the file's two left strikes are 86 frames apart at 60 Hz
    assert left["Stride Time (s)"] == pytest.approx(86 / 60)
    assert left["Cadence (steps/min)"] == pytest.approx(120 / (86 / 60))


def test_parameters_with_a_wrong_suffix_is_one_line_exit_2(tmp_path, capsys):
    status = main(["angles", str(realdata_path(*SUB_LABELS)), "-m", "plugingait-lower",
                   "-o", str(tmp_path / "a.csv"), "--parameters", str(tmp_path / "p.txt")])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and ".csv or .json" in err
    assert not (tmp_path / "a.csv").exists() and not (tmp_path / "p.txt").exists()
