"""Every motion option of check, export and animate is used or refused (issue 26): an
option the input's kind ignores is one line, exit 2, and nothing written (on main each
was silently ignored: the output was the same without it)."""
from __future__ import annotations

from pathlib import Path

import pytest

from mocap.cli import main

DATA = Path(__file__).resolve().parents[1] / "data"
BVH = DATA / "mocapbank_walk.bvh"


@pytest.mark.parametrize("command", ["export", "animate", "check"])
@pytest.mark.parametrize("extra, message", [
    (["--rate", "60"], "--rate gives the frame rate of an AMC motion"),
    (["--asf", str(DATA / "cmu_lambada.asf")], "--asf gives the skeleton of an AMC motion"),
    (["--markerset", "synthetic15"], "--markerset builds a skeleton from a marker trial"),
])
def test_options_a_bvh_ignores_are_refused(command, extra, message, tmp_path, capsys):
    out = {"export": ["-o", str(tmp_path / "o.csv")], "animate": ["-o", str(tmp_path / "o.gif")],
           "check": ["--plot", str(tmp_path / "o.png")]}[command]
    assert main([command, str(BVH), *extra, *out]) == 2
    err = capsys.readouterr().err
    assert message in err and "is a BVH motion" in err and len(err.strip().splitlines()) == 1
    assert not any(tmp_path.iterdir())


def test_units_and_joint_map_are_refused_for_a_marker_trial(tmp_path, capsys):
    from mocap.synthetic import generate_corpus

    generate_corpus(tmp_path / "c", people=2, actions=["walk"], seed=1)
    trial = next((tmp_path / "c").glob("*.c3d"))
    for extra, message in ((["--units", "mm"], "--units is the length unit of a BVH"),
                           (["--joint-map", str(tmp_path / "map.toml")], "--joint-map names")):
        assert main(["export", str(trial), "-m", "synthetic15", *extra, "-o",
                     str(tmp_path / "o.bvh")]) == 2
        err = capsys.readouterr().err
        assert message in err and "is a marker trial" in err
    assert not (tmp_path / "o.bvh").exists()
    # the same trial without them is exported
    assert main(["export", str(trial), "-m", "synthetic15", "-o", str(tmp_path / "o.bvh")]) == 0


@pytest.mark.parametrize("argv, message", [
    (["batch", "{trial}", "--sequence", "XYZ"], "--sequence orders the angles of --markerset"),
    (["batch", "{trial}", "-m", "synthetic15", "--mass", "60"], "--mass and --lowpass go with --check"),
    (["batch", "{trial}", "-m", "synthetic15", "--lowpass", "0"], "--mass and --lowpass go with --check"),
    (["convert", "{trial}", "{tmp}/o.csv", "--out-units", "cm"], "a CSV holds metres"),
])
def test_batch_and_convert_options_are_used_or_refused(argv, message, tmp_path, capsys):
    from mocap.synthetic import generate_corpus

    generate_corpus(tmp_path / "c", people=2, actions=["walk"], seed=1)
    trial = next((tmp_path / "c").glob("*.c3d"))
    assert main([w.format(trial=trial, tmp=tmp_path) for w in argv]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o.csv").exists()
