"""``mocap info`` and ``mocap convert`` from the command line."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mocap.cli import main
from mocap.io import read, write
from tests.conftest import realdata_path
from tests.mocap.io.test_roundtrip import synthetic_trial

ROOT = Path(__file__).resolve().parents[2]


def run(argv: list[str], capsys) -> tuple[int, str, str]:
    status = main(argv)
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.mark.parametrize("local, frames, markers, rate, units", [
    ("ezc3d_testFiles/Vicon.c3d", 580, 51, 100.0, "mm"),
    ("pyomeca/markers.trc", 93, 51, 100.0, "mm"),
    ("pyomeca/markers.csv", 580, 51, 100.0, "mm"),
    ("c3dorg_via_c3dio/sample_26/Capture0004.c3d", 453, 18, 240.0, "mm"),
])
def test_info_json_on_real_files(capsys, local, frames, markers, rate, units):
    path = realdata_path(local)
    status, out, _ = run(["info", str(path), "--json"], capsys)
    assert status == 0
    summary = json.loads(out)
    assert summary["path"] == str(path)
    assert summary["format"] == path.suffix.lower()[1:]
    assert (summary["frames"], len(summary["markers"]), summary["rate"]) == (frames, markers, rate)
    assert summary["duration"] == pytest.approx((frames - 1) / rate)
    assert summary["units"] == units
    assert set(summary["missing"]) == set(summary["markers"])
    trial = read(path)
    for label, fraction in trial.missing_fraction().items():
        assert summary["missing"][label] == pytest.approx(fraction)


def test_info_json_counts_gaps(tmp_path, capsys):
    trial = synthetic_trial(frames=40, markers=3)
    trial.points[:] = 1.0
    trial.points[5:8, 1] = np.nan          # gap of 3
    trial.points[20, 1] = np.nan           # gap of 1
    trial.points[-4:, 2] = np.nan          # gap of 4 at the end
    write(trial, tmp_path / "g.trc")
    status, out, _ = run(["info", str(tmp_path / "g.trc"), "--json"], capsys)
    summary = json.loads(out)
    assert summary["gaps"] == {"LASI": 0, "RASI": 2, "L.Knee": 1}
    assert summary["longest_gap"] == {"LASI": 0, "RASI": 3, "L.Knee": 4}
    assert summary["missing"]["RASI"] == pytest.approx(4 / 40)


def test_info_text_form(capsys):
    status, out, _ = run(["info", str(realdata_path("c3dorg_via_c3dio/sample_06/MACsample.c3d"))],
                         capsys)
    assert status == 0
    assert "rate:      60 Hz" in out and "frames:    180 (2.983 s)" in out
    assert "warning:   header scale" in out
    assert "longest gap" in out


def test_info_missing_file_is_one_line_and_status_2(tmp_path, capsys):
    status, out, err = run(["info", str(tmp_path / "missing.c3d")], capsys)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and "missing.c3d" in err and "no such file" in err


def test_info_on_many_files_reports_bad_ones_and_goes_on(tmp_path, capsys):
    write(synthetic_trial(), tmp_path / "a.c3d")
    write(synthetic_trial(), tmp_path / "b.csv")
    (tmp_path / "bad.c3d").write_bytes(b"\x02P" + bytes(600))
    status, out, err = run(["info", str(tmp_path), "--json"], capsys)
    assert status == 2
    assert [json.loads(line)["path"] for line in out.splitlines()] == \
        [str(tmp_path / "a.c3d"), str(tmp_path / "b.csv")]
    assert err.count("\n") == 1 and "bad.c3d" in err


@pytest.mark.parametrize("target", ["out.trc", "out.csv", "out.c3d"])
def test_convert_real_c3d_to_every_format(tmp_path, capsys, target):
    source = realdata_path("ezc3d_testFiles/Vicon.c3d")
    status, _, err = run(["convert", str(source), str(tmp_path / target)], capsys)
    assert status == 0 and "580 frames" in err
    original, converted = read(source), read(tmp_path / target)
    assert converted.labels == original.labels and converted.rate == original.rate
    np.testing.assert_allclose(converted.points, original.points, atol=1e-6, equal_nan=True)


def test_convert_units_option_and_refusals(tmp_path, capsys):
    source = tmp_path / "a.csv"
    write(synthetic_trial(), source)
    assert run(["convert", str(source), str(tmp_path / "a.trc"), "--units", "m"], capsys)[0] == 0
    assert read(tmp_path / "a.trc").units == "m"
    status, _, err = run(["convert", str(source), str(tmp_path / "a.bvhx")], capsys)
    assert status == 2 and "cannot write files with suffix '.bvhx'" in err
    status, _, err = run(["convert", str(tmp_path / "none.c3d"), str(tmp_path / "b.csv")], capsys)
    assert status == 2 and "no such file" in err
    assert not (tmp_path / "b.csv").exists()


def test_console_script_exit_status(tmp_path):
    """The installed entry point, as a user runs it."""
    completed = subprocess.run([sys.executable, "-m", "mocap", "info",
                                str(tmp_path / "missing.c3d")],
                               cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert completed.returncode == 2
    assert completed.stderr.count("\n") == 1 and "Traceback" not in completed.stderr


def test_info_and_convert_refuse_motion_formats(tmp_path, capsys):
    (tmp_path / "walk.bvh").write_text("HIERARCHY\n")
    status, out, err = run(["info", str(tmp_path / "walk.bvh")], capsys)   # read as a motion
    assert status == 2 and out == "" and len(err.splitlines()) == 1 and "walk.bvh" in err
    source = tmp_path / "a.csv"
    write(synthetic_trial(), source)
    status, _, err = run(["convert", str(source), str(tmp_path / "a.bvh")], capsys)
    assert status == 2 and "convert writes marker files" in err
    assert not (tmp_path / "a.bvh").exists()
