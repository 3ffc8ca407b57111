"""What a new user meets first: help texts that spell one idea one way, folders that say
why they hold nothing, and pictures whose every panel is labelled (issue 11)."""
from __future__ import annotations

import numpy as np
import pytest

from dynamics.humanoid.check import check_motion
from dynamics.viz.animate import plot_check
from mocap.body.segments import default_skeleton
from mocap.cli import build_parser, main
from mocap.cli.forces import load_plates, plot_forces
from mocap.skeleton import Motion
from tests.conftest import realdata_path

#: One metavar per idea, whatever the command (issue 11: "one spelling per idea").
METAVARS = {"--markerset": "SET", "--sequence": "SEQ", "--mass": "KG", "--lowpass": "HZ"}


def _options():
    parser = build_parser(None)
    for name, command in parser.commands.items():
        for action in command._actions:
            for flag in action.option_strings:
                yield name, flag, action


def test_every_command_spells_an_option_with_the_same_metavar():
    seen = {}
    for command, flag, action in _options():
        if flag in METAVARS:
            seen.setdefault(flag, set()).add((command, action.metavar))
    assert set(seen) == set(METAVARS)
    for flag, uses in seen.items():
        wrong = sorted(command for command, metavar in uses if metavar != METAVARS[flag])
        assert not wrong, f"{flag} has another metavar in: {wrong}"


def test_no_help_says_default_none():
    for command, flag, action in _options():
        text = (action.help or "") % {"default": action.default, "prog": "mocap"}
        assert "default None" not in text, (command, flag)


@pytest.mark.parametrize("command", ["info", "batch"])
def test_a_folder_of_sub_folders_says_they_are_not_searched(capsys, command):
    subject = realdata_path("biomechzoo_sample_study", "HC002D")   # Static/ Straight/ Turn/
    assert main([command, str(subject)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(subject) in err
    assert "sub-folders are not searched" in err


def test_force_plot_has_time_ticks_and_units_on_every_panel():
    path = realdata_path("biomechzoo_sample_study", "HC030A", "Turn", "HC030A22.c3d")
    _, plates, total = load_plates(path)
    parts = [(f"plate{p.plate.index + 1}", p) for p in plates] + [("total", total)]
    figure = plot_forces(parts, title="HC030A22.c3d")
    assert len(figure.axes) == 3
    for axis, (name, _) in zip(figure.axes, parts):
        assert axis.get_xlabel() == "time (s)"
        assert axis.xaxis.get_tick_params()["labelbottom"]
        assert name in axis.get_ylabel() and "(N)" in axis.get_ylabel()
    assert "HC030A22.c3d" in figure.get_suptitle()


def test_check_plot_names_joints_and_tells_sides_apart():
    skeleton = default_skeleton(1.75)
    frames = 12
    motion = Motion(skeleton, np.zeros((frames, 3)),
                    np.tile(np.eye(3), (frames, skeleton.count, 1, 1)), 50.0)
    torque_axis = plot_check(check_motion(motion)).axes[3]
    lines = {line.get_label(): line for line in torque_axis.get_lines()}
    left, right = lines["l_thigh (hip)"], lines["r_thigh (hip)"]      # named as the text is
    assert left.get_color() == right.get_color()
    assert left.get_linestyle() != right.get_linestyle()
    knee = lines["l_shank (knee)"]
    assert knee.get_color() != left.get_color()
    legend = [text.get_text() for text in torque_axis.get_legend().get_texts()]
    assert "l_foot (ankle)" in legend


def test_simulate_gif_plays_at_the_runs_own_speed(tmp_path, capsys):
    from PIL import Image

    gif = tmp_path / "rope.gif"
    assert main(["simulate", "swinging-rope", "--steps", "2000", "-o", str(tmp_path / "r.npz"),
                 "--gif", str(gif), "--no-progress"]) == 0
    times = np.load(tmp_path / "r.npz")["times"]
    span = len(times) * float(np.median(np.diff(times)))      # seconds the run covers
    with Image.open(gif) as image:
        delays = []
        for index in range(image.n_frames):
            image.seek(index)
            delays.append(image.info["duration"])
    assert all(d >= 20 and d % 10 == 0 for d in delays)        # whole centiseconds
    assert abs(sum(delays) / 1000 - span) <= 0.1 * span + max(delays) / 1000
    assert main(["simulate", "swinging-rope", "--steps", "2000", "-o", str(tmp_path / "f.npz"),
                 "--gif", str(tmp_path / "f.gif"), "--fps", "5", "--no-progress"]) == 0
    with Image.open(tmp_path / "f.gif") as image:
        assert image.info["duration"] == 200


@pytest.mark.parametrize("suffix", [".trc", ".c3d"])
def test_export_takes_its_format_from_the_output_name(tmp_path, capsys, suffix):
    import json

    bvh = realdata_path("bandai2", "dataset-2_walk_normal_001.bvh")   # 273 frames at 30 Hz
    out = tmp_path / f"walk{suffix}"
    # the refusal's own advice ("or leave --format out") has to work
    assert main(["export", str(bvh), "--format", "bvh", "-o", str(out)]) == 2
    assert "leave --format out" in capsys.readouterr().err
    assert main(["export", str(bvh), "-o", str(out)]) == 0
    assert f"({suffix[1:]}, 273 frames)" in capsys.readouterr().err
    assert main(["info", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["format"], summary["frames"], summary["rate"], summary["units"]) == \
        (suffix[1:], 273, 30.0, "mm")


def test_info_summarises_a_bvh_and_an_amc(capsys):
    import json
    from pathlib import Path

    bvh = realdata_path("bandai2", "dataset-2_walk_normal_001.bvh")
    assert main(["info", str(bvh)]) == 0
    out = capsys.readouterr().out
    assert "rate:      30 Hz" in out and "frames:    273 (9.067 s)" in out
    assert "units:     cm (detected from a standing height of 140.6 file units" in out
    assert main(["info", str(bvh), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["format"], summary["frames"], summary["rate"], summary["units"]) == \
        ("bvh", 273, 30.0, "cm")
    assert summary["joints"][:2] == ["joint_Root", "Hips"]
    amc = Path(__file__).resolve().parents[1] / "data" / "cmu_lambada.amc"
    assert main(["info", str(amc), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["format"], summary["frames"], summary["rate"]) == ("amc", 4, 120.0)
    assert "lfemur" in summary["joints"]


def test_convert_spells_the_output_unit_as_export_does(tmp_path, capsys):
    import json

    source = realdata_path("pyomeca", "markers.trc")
    out = tmp_path / "m.trc"
    assert main(["convert", str(source), "-o", str(out), "--out-units", "m"]) == 0
    capsys.readouterr()
    assert main(["info", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["units"] == "m"


def test_cycle_plot_names_the_foot_off_lines_and_ticks_every_panel():
    from mocap.plugingait.events import Cycles, cycles_figure

    percent = np.linspace(0, 1, 101)[None, :, None, None]
    values = np.sin(2 * np.pi * percent) * np.ones((2, 101, 2, 3))       # one cycle a side
    cycles = Cycles(["l", "r"], [1, 1], [0.0, 50.0], [100.0, 150.0], [61.0, 63.0], values,
                    ["hip", "knee"], ["flexion", "adduction", "rotation"])
    figure = cycles_figure(cycles)
    legend = [t.get_text() for t in figure.axes[0].get_legend().get_texts()]
    assert "left foot off (61 %)" in legend and "right foot off (63 %)" in legend
    assert all(ax.xaxis.get_tick_params()["labelbottom"] for ax in figure.axes)


def test_export_says_which_joint_markers_would_read_back_as_gaps(tmp_path, capsys):
    import json

    bvh = realdata_path("bandai2", "dataset-2_walk_normal_001.bvh")   # joint_Root at 0, 0, 0
    out = tmp_path / "walk.trc"
    assert main(["export", str(bvh), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    note = next(line for line in err.splitlines() if line.startswith("note:"))
    assert "joint_Root (273 of 273 frames) at exactly (0, 0, 0)" in note and "gap" in note
    assert "Hips" not in note
    assert main(["info", str(out), "--json"]) == 0              # and so it does read back
    assert json.loads(capsys.readouterr().out)["missing"]["joint_Root"] == 1.0
    assert main(["export", str(bvh), "-o", str(tmp_path / "walk.bvh")]) == 0
    assert "note:" not in capsys.readouterr().err               # BVH keeps the root as it is
