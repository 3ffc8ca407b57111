"""Inputs of a kind a command does not take, or given oddly (issue 11, found by the second
hostile harness): one line naming the file or the option, exit status 2, nothing written."""
from __future__ import annotations

from pathlib import Path

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
