"""``mocap angles`` and ``mocap plugingait`` on a walk whose PROCESSING group is gone and
with no static: clinical angles from estimated measurements, one warning line each."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.cli import main
from mocap.io import read
from mocap.io.angles_csv import read_angles_csv
from mocap.io.c3d.write import write_c3d
from tests.conftest import realdata_path

WALK = ("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")
#: What Plug-in Gait needs and a walk without PROCESSING must estimate.
ESTIMATED = ("inter-ASIS distance", "L leg length", "R leg length", "L knee width",
             "R knee width", "L ankle width", "R ankle width")


@pytest.fixture(scope="module")
def stripped(tmp_path_factory):
    trial = read(realdata_path(*WALK))
    trial.parameters = {g: v for g, v in trial.parameters.items() if g != "PROCESSING"}
    path = tmp_path_factory.mktemp("bare") / "walk_bare.c3d"
    write_c3d(trial, path)
    assert "PROCESSING" not in read(path).parameters
    return path


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _one_line_each(err: str) -> None:
    lines = [line for line in err.splitlines() if "not measured: estimated" in line]
    assert len(lines) == len(ESTIMATED), err
    for name in ESTIMATED:
        assert sum(f": {name} not measured: estimated " in line for line in lines) == 1, err
    assert all(line.endswith(")") and " mm (" in line for line in lines)
    # the marker diameter, not in the file either, is said once like the estimates
    said = [line for line in err.splitlines() if "marker diameter not measured" in line]
    assert len(said) == 1 and "assumed 14 mm" in said[0], err


def test_angles_gives_clinical_angles_and_says_each_estimate(stripped, tmp_path, capsys):
    status, _, err = run(capsys, "angles", stripped, "-m", "plugingait-lower",
                         "-o", tmp_path / "a.csv")
    assert status == 0, err
    _one_line_each(err)
    assert "segment angles instead" not in err
    angles = read_angles_csv(tmp_path / "a.csv")
    assert "l_knee" in angles.segments and "r_ankle" in angles.segments
    knee = angles.segment("l_knee")[:, 0]
    # a walk's knee flexes through ~60 degrees (segment angles would have other columns)
    assert np.nanmax(knee) - np.nanmin(knee) > 40


def test_plugingait_gives_clinical_angles_and_says_each_estimate(stripped, tmp_path, capsys):
    out = tmp_path / "p.c3d"
    status, _, err = run(capsys, "plugingait", stripped, "-o", out)
    assert status == 0, err
    _one_line_each(err)
    assert "kinetics skipped" in err                    # no body mass without PROCESSING
    modelled = read(out).modelled
    assert "LKneeAngles" in modelled["labels"] and "RAnkleAngles" in modelled["labels"]
