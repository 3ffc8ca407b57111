"""``mocap check``, ``mocap export`` and ``mocap animate`` end to end."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mocap.cli import main
from mocap.io.bvh import read_bvh, write_bvh
from mocap.body.segments import default_skeleton
from mocap.skeleton import Motion

DATA = Path(__file__).resolve().parents[1] / "data"
DESIGN_KEYS = {"mass_kg", "frames", "residual_force_rms_N", "residual_force_peak_N",
               "residual_force_rms_pct_bw", "residual_torque_rms_Nm", "foot_skate_mm",
               "penetration_mm", "floating_mm", "peak_joint_torque_Nm", "verdict", "reasons"}


@pytest.fixture
def standing_bvh(tmp_path):
    path = tmp_path / "stand.bvh"
    write_bvh(Motion.still(default_skeleton(1.75), 40, 100.0), path)
    return path


def test_check_json_has_the_design_keys_and_known_answers(standing_bvh, tmp_path, capsys):
    plot = tmp_path / "check.png"
    assert main(["check", str(standing_bvh), "--mass", "70", "--json",
                 "--plot", str(plot)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert DESIGN_KEYS <= set(summary)
    assert summary["mass_kg"] == 70.0 and summary["frames"] == 40
    assert summary["verdict"] == "plausible" and summary["residual_force_rms_pct_bw"] < 1.0
    assert set(summary["peak_joint_torque_Nm"]) >= {"l_thigh", "r_foot", "head"}
    assert plot.stat().st_size > 10_000


def test_check_text_report_of_a_real_bvh(capsys):
    assert main(["check", str(DATA / "mocapbank_walk.bvh")]) == 0
    out = capsys.readouterr().out
    assert "residual force" in out and "peak joint torques" in out


@pytest.mark.parametrize("file_format", ["bvh", "csv", "c3d", "trc", "mot", "json"])
def test_export_every_format_from_asf_amc(file_format, tmp_path, capsys):
    out = tmp_path / f"lambada.{file_format}"
    assert main(["export", str(DATA / "cmu_lambada.amc"), "--body", "--format", file_format,
                 "-o", str(out)]) == 0
    assert out.stat().st_size > 0
    if file_format == "bvh":
        motion = read_bvh(out)
        assert motion.frames == 4 and len(motion.names) == 15
    elif file_format == "json":
        document = json.loads(out.read_text())
        assert document["joints"][0] == "pelvis"
        assert np.array(document["positions"]).shape == (4, 15, 3)
    elif file_format in ("c3d", "trc"):
        from mocap.io import read
        trial = read(out)
        assert trial.frames == 4 and "l_thigh" in trial.labels
        # Z-up lab: the head is the highest joint.
        assert trial.marker("head")[0, 2] > trial.marker("pelvis")[0, 2]
    elif file_format == "csv":
        # A body angle CSV plays back on the default body.
        assert main(["check", str(out), "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["frames"] == 4


def test_export_mot_and_csv_give_the_same_angles(tmp_path):
    """One motion -> angles: the .mot columns are the angle CSV's numbers (Z-up lab axes)."""
    from mocap.io.angles_csv import read_angles_csv

    mot, csv = tmp_path / "lambada.mot", tmp_path / "lambada.csv"
    for out in (mot, csv):
        assert main(["export", str(DATA / "cmu_lambada.amc"), "--body", "--sequence", "YXZ",
                     "--format", out.suffix[1:], "-o", str(out)]) == 0
    lines = mot.read_text().splitlines()
    start = lines.index("endheader") + 2
    table = np.array([[float(v) for v in line.split("\t")] for line in lines[start:]])
    angles = read_angles_csv(csv)
    assert lines[start - 1].split("\t")[4:7] == ["pelvis_Y", "pelvis_X", "pelvis_Z"]
    np.testing.assert_allclose(table[:, 4:], angles.values.reshape(4, -1), atol=1e-6)
    # The root's origin in the same lab: Z up, so the pelvis is ~1 m above z = 0.
    assert 0.5 < table[0, 3] < 1.5


def test_animate_a_tiny_gif_with_cape_and_physics(standing_bvh, tmp_path, capsys):
    out = tmp_path / "stand.gif"
    assert main(["animate", str(standing_bvh), "--cape", "--rope", "--physics",
                 "--max-frames", "3", "--dpi", "30", "-o", str(out)]) == 0
    assert out.read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    assert "physics:" in capsys.readouterr().err


@pytest.mark.parametrize("argv, message", [
    (["check", "missing.bvh"], "file not found"),
    (["check", "{data}/cmu_lambada.asf"], "skeleton only"),
    (["check", "{bad}"], "not a BVH file"),
    (["export", "{data}/mocapbank_walk.bvh", "--format", "bvh", "-o", "{out}", "--units",
      "mm"], None),
    (["animate", "{data}/mocapbank_walk.bvh", "-o", "{tmp}/a.mp4"], "ffmpeg"),
    (["animate", "{data}/mocapbank_walk.bvh", "-o", "{tmp}/a.png"], ".gif or .mp4"),
    (["check", "{data}/mocapbank_walk.bvh", "--mass", "-3"], ">= 0.001"),
    # a denormal mass passed '> 0' and made the % BW infinite: a JSON ValueError traceback
    (["check", "{data}/mocapbank_walk.bvh", "--json", "--mass", "5e-324"], ">= 0.001"),
])
def test_bad_input_is_one_line_exit_2_and_no_output(argv, message, tmp_path, capsys,
                                                    monkeypatch):
    bad = tmp_path / "bad.bvh"
    bad.write_text("HIERARCHY\nROOT Hips\n{\n")
    out = tmp_path / "out.bvh"
    argv = [a.format(data=DATA, bad=bad, out=out, tmp=tmp_path) for a in argv]
    if message == "ffmpeg":
        import shutil
        if shutil.which("ffmpeg"):
            pytest.skip("ffmpeg is installed")
    if message is None:
        # Stated units that make no sense still convert (the user said so); the output
        # appears whole.
        assert main(argv) == 0
        assert out.exists()
        return
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]
    assert not any(p.suffix in (".mp4", ".png") for p in tmp_path.iterdir())


def test_check_real_captured_walk_with_a_lower_body_marker_set(capsys):
    """Vicon Plug-in Gait walk (real data): pelvis and legs only, upper body lumped."""
    from tests.conftest import realdata_path

    trial = realdata_path("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")
    assert main(["check", str(trial), "--markerset", "plugingait-lower", "--mass", "70",
                 "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert "thorax" in summary["lumped_segments"]
    assert set(summary["peak_joint_torque_Nm"]) == {"l_thigh", "l_shank", "l_foot",
                                                    "r_thigh", "r_shank", "r_foot"}
    # A real walk: small residuals, feet planted in stance, plausible knee and hip torques.
    assert summary["residual_force_rms_pct_bw"] < 8.0
    assert summary["skating_ratio"] < 0.1
    assert 20.0 < summary["peak_joint_torque_Nm"]["l_thigh"] < 250.0
