"""Inputs of a kind a command does not take, or given oddly (issue 11, found by the second
hostile harness): one line naming the file or the option, exit status 2, nothing written."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from mocap.cli import main

ROOT = Path(__file__).resolve().parents[2]
BVH = ROOT / "tests" / "data" / "mocapbank_walk.bvh"


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def test_angles_of_a_skeleton_motion_is_one_line(tmp_path, capsys):
    """A BVH given to 'angles' with a marker set was an AttributeError traceback."""
    for extra in (["-m", "plugingait-lower"], ["-m", "synthetic15"], ["--from-rotations"]):
        assert main(["angles", str(BVH), *extra, "-o", str(tmp_path / "a.csv")]) == 2
        line = _one_error_line(capsys)
        assert "mocapbank_walk.bvh" in line and "skeleton motion" in line, line
    assert list(tmp_path.iterdir()) == []


def test_generate_with_an_action_given_twice_is_one_line(tmp_path, capsys):
    """'--actions walk,walk' wrote each trial twice inside the corpus being made, and the
    backups of the first writes stayed in it as hidden .part files."""
    assert main(["generate", "-o", str(tmp_path / "c"), "--people", "2",
                 "--actions", "walk,walk"]) == 2
    assert "walk given more than once" in _one_error_line(capsys)
    assert list(tmp_path.iterdir()) == []


def _amc_pair(tmp_path: Path, edit) -> Path:
    data = ROOT / "tests" / "data"
    (tmp_path / "s.asf").write_text((data / "cmu_lambada.asf").read_text())
    lines = (data / "cmu_lambada.amc").read_text().splitlines()
    amc = tmp_path / "s_01.amc"
    amc.write_text("\n".join(edit(lines)) + "\n")
    return amc


def test_an_amc_frame_without_its_number_is_refused(tmp_path, capsys):
    """Without the frame numbers every bone line fell into frame 1, each one overwriting the
    last: a 1-frame motion, exit 0, no word."""
    amc = _amc_pair(tmp_path, lambda lines: [l for l in lines if not l.strip().isdigit()
                                             or l.strip() == "1"])
    assert main(["export", str(amc), "-f", "csv", "-o", str(tmp_path / "o.csv")]) == 2
    line = _one_error_line(capsys)
    assert "s_01.amc" in line and "second time in frame 1" in line, line
    assert not (tmp_path / "o.csv").exists()


def test_a_bone_missing_from_some_amc_frames_is_warned(tmp_path, capsys):
    def drop(lines):
        numbers = [i for i, l in enumerate(lines) if l.strip().isdigit()]
        return [l for i, l in enumerate(lines) if i != numbers[2] + 3]
    amc = _amc_pair(tmp_path, drop)
    assert main(["export", str(amc), "-f", "csv", "-o", str(tmp_path / "o.csv")]) == 0
    err = capsys.readouterr().err
    assert "missing from some frames" in err and "1 of 4 frames" in err, err


def test_every_output_of_an_analog_only_c3d_reads_back(tmp_path, capsys):
    """A C3D of EMG channels and no markers (Cometa): convert wrote a TRC with no marker
    columns, which the TRC reader then refuses; a TRC of nothing is refused at once now,
    and the CSV and C3D outputs read back with their 199 frames at 10 Hz."""
    from tests.conftest import realdata_path
    emg = realdata_path("c3dorg_via_c3dio", "sample_00", "Cometa_Systems", "EMG_Data_Cometa.c3d")
    assert main(["convert", str(emg), str(tmp_path / "e.trc")]) == 2
    assert "no markers to write" in _one_error_line(capsys)
    assert not (tmp_path / "e.trc").exists()
    for suffix in (".csv", ".c3d"):
        out = tmp_path / f"e{suffix}"
        assert main(["convert", str(emg), str(out)]) == 0
        capsys.readouterr()
        assert main(["info", "--json", str(out)]) == 0
        record = json.loads(capsys.readouterr().out.splitlines()[0])
        assert (record["frames"], record["rate"], record["markers"]) == (199, 10.0, [])


def test_a_dash_for_standard_output_is_refused_not_written_as_a_file(tmp_path, capsys,
                                                                     monkeypatch):
    """'export -f csv -o -' wrote a file named '-' in the working folder ("wrote -")."""
    monkeypatch.chdir(tmp_path)
    for argv in (["export", str(BVH), "-f", "csv", "-o", "-"],
                 ["check", str(BVH), "--plot", "-"], ["info", "-"]):
        assert main(argv) == 2
        assert "'-' (standard input or output) is not supported" in _one_error_line(capsys)
    assert list(tmp_path.iterdir()) == []


def test_a_start_time_a_c3d_cannot_keep_is_said(tmp_path, capsys):
    """OpenSim's Leg39 TRC starts at -0.0333 s; its C3D starts at frame 1, 0 s: every time
    moved by one frame without a word (found by the round-trip family)."""
    from tests.conftest import realdata_path
    leg = realdata_path("opensim_models", "Pipelines", "Leg39", "leg39_swing_short.trc")
    assert main(["convert", str(leg), str(tmp_path / "leg.c3d")]) == 0
    err = capsys.readouterr().err
    assert "the start time -0.0333333 s" in err and "frame 1 at 0 s" in err, err
    assert main(["convert", str(tmp_path / "leg.c3d"), str(tmp_path / "again.c3d")]) == 0
    assert "start time" not in capsys.readouterr().err


def test_a_one_frame_csv_says_it_cannot_keep_the_rate(tmp_path, capsys):
    """A CSV's clock is its time column: a 1-frame C3D converted to CSV lost its 100 Hz
    without a word (its reader then finds no rate; found by the c3d2 family)."""
    from mocap.io import write
    from mocap.trial import Trial
    one = tmp_path / "one.c3d"
    write(Trial(["A", "B", "C"], np.full((1, 3, 3), 0.5), 100.0, units="m"), one)
    assert main(["convert", str(one), str(tmp_path / "one.csv")]) == 0
    err = capsys.readouterr().err
    assert "not kept in one.csv: the rate (100 Hz" in err, err
    assert main(["convert", str(one), str(tmp_path / "one.trc")]) == 0
    assert "rate" not in capsys.readouterr().err.split("wrote")[0]


def test_a_denormal_cutoff_is_one_line(capsys):
    """'check --lowpass 5e-324' passed the option's '> 0' and traced back in the filter
    (OverflowError: rate / cutoff is infinite; found by the numeric2 family)."""
    assert main(["check", str(BVH), "--json", "--lowpass", "5e-324"]) == 2
    assert "too small for a rate of" in _one_error_line(capsys)


def test_cycle_angle_without_cycles_is_refused(tmp_path, capsys):
    """Without --cycles each trial is one cycle and --cycle-angle was ignored without a word,
    whatever it named ('--cycle-angle 1e9'; found by the numeric2 family)."""
    assert main(["decompose", str(tmp_path), "-m", "synthetic15", "-o", str(tmp_path / "m.npz"),
                 "--cycle-angle", "r_thigh.Y"]) == 2
    assert "applies with --cycles only" in _one_error_line(capsys)
    assert list(tmp_path.iterdir()) == []
