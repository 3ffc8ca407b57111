"""``mocap angles --upper-body``: Plug-in Gait's upper body beside the lower body (whose
columns hold the foot progression with or without it), as Vicon stores them; bad combinations are one line, exit 2, nothing written."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.cli import main
from mocap.io import read
from mocap.io.angles_csv import read_angles_csv
from mocap.plugingait.clinical import clinical_columns
from mocap.plugingait.upper import VICON_NAMES, upper_columns
from tests.conftest import realdata_path

WALK = ("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")
STATIC = ("biomechzoo_sample_study", "HC030A", "Static", "HC030A01.c3d")
LOWER_ONLY = ("c3dorg_via_c3dio", "sample_00", "Vicon_Motion_Systems",
              "pyCGM2_lower_limb_CGM24_Walking01.c3d")


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_upper_body_columns_equal_vicons_outputs(tmp_path, capsys):
    out = tmp_path / "walk.csv"
    status, _, err = run(capsys, "angles", realdata_path(*WALK), "-m", "plugingait-lower",
                         "--static", realdata_path(*STATIC), "--upper-body", "-o", out)
    assert status == 0, err
    assert "warning" not in err
    angles = read_angles_csv(out)
    assert angles.segments == clinical_columns() + upper_columns()
    modelled = read(realdata_path(*WALK)).modelled
    for column in ("l_thorax", "r_spine", "l_neck", "r_head", "l_shoulder", "r_elbow",
                   "l_wrist"):
        side, joint = column.split("_", 1)
        vicon = modelled["values"][:, modelled["labels"].index(
            side.upper() + VICON_NAMES[joint])]
        ours = angles.segment(column)
        ok = np.isfinite(vicon).all(axis=1) & np.isfinite(ours).all(axis=1)
        assert ok.sum() > 150
        # the CSV's six decimals
        np.testing.assert_allclose(ours[ok], vicon[ok], atol=2e-3, err_msg=column)


def test_a_lower_body_marker_set_gets_the_foot_progression(tmp_path, capsys):
    """pyCGM2's lower-limb walk (no upper-body markers): without --upper-body the clinical
    columns, both feet's progression among them, filled on most frames."""
    out = tmp_path / "walk.csv"
    status, _, err = run(capsys, "angles", realdata_path(*LOWER_ONLY), "-m", "plugingait-lower",
                         "-o", out)
    assert status == 0, err
    angles = read_angles_csv(out)
    assert angles.segments == clinical_columns()
    for side in "lr":
        assert np.isfinite(angles.segment(f"{side}_foot_progress")).all(axis=1).mean() > 0.9


@pytest.mark.parametrize("source, extra, problem", [
    (WALK, ["--no-clinical"], "--upper-body adds Plug-in Gait's upper body"),
    (LOWER_ONLY, [], "no Plug-in Gait upper-body markers with data"),
])
def test_bad_upper_body_runs_are_one_line(tmp_path, capsys, source, extra, problem):
    out = tmp_path / "out.csv"
    status, _, err = run(capsys, "angles", realdata_path(*source), "-m", "plugingait-lower",
                         "--upper-body", *extra, "-o", out)
    assert status == 2
    assert problem in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []
