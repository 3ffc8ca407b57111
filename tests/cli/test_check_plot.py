"""``mocap check --plot`` agrees with the text it illustrates (issue 26): force and torque
residuals in their own panels, each with the RMS the verdict judges and its own limit; the
measured plates drawn with ``--forces plates``; the floor panel the penetration series whose
deepest point is the reported penetration."""
from __future__ import annotations

import numpy as np
import pytest

from dynamics.viz.animate import plot_check
from mocap.cli import main
from mocap.cli.check import check_file
from tests.conftest import realdata_path

WALK = ("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")


@pytest.fixture(scope="module")
def checked():
    return check_file(realdata_path(*WALK), markerset="plugingait-full", plates=True)


def _line(axis, start: str):
    return next(line for line in axis.get_lines() if line.get_label().startswith(start))


def test_residual_panels_show_what_the_verdict_judges(checked):
    report, summary = checked["report"], checked["summary"]
    figure = plot_check(report, plates=checked["plates"])
    force_axis, torque_axis = figure.axes[0], figure.axes[1]
    for axis, key in ((force_axis, "residual_force_rms_pct_bw"),
                      (torque_axis, "residual_torque_rms_Nm")):
        judged = summary["limits"][key]
        rms = _line(axis, "RMS ").get_ydata()[0]
        limit = _line(axis, "RMS limit").get_ydata()[0]
        assert rms == pytest.approx(judged["value"]) and limit == pytest.approx(judged["limit"])
        per_frame = _line(axis, "residual").get_ydata()
        assert np.sqrt(np.mean(np.square(per_frame))) == pytest.approx(judged["value"], abs=1e-3)
        # the title's verdict follows from the drawn lines
        assert (rms <= limit) == (summary["verdict"] == "plausible")
    assert "N·m" in torque_axis.get_ylabel() and "% BW" in force_axis.get_ylabel()


def test_measured_plates_are_drawn(checked):
    report, plates = checked["report"], checked["plates"]
    axis = plot_check(report, plates=plates).axes[2]
    measured = [line for line in axis.get_lines() if "measured" in line.get_label()]
    assert [line.get_label().split()[0] for line in measured] == plates.names
    total = sum(line.get_ydata() for line in measured) * report.weight
    series = checked["series"]["measured_ground_reaction"]["force_N"]
    assert np.allclose(total, np.asarray(series)[:, 1], atol=0.01)
    assert not [line for line in plot_check(report).axes[2].get_lines()
                if "measured" in line.get_label()]


def test_floor_panel_is_the_reported_penetration(checked):
    report, summary = checked["report"], checked["summary"]
    axis = plot_check(report).axes[4]
    drawn = _line(axis, "penetration").get_ydata()
    assert np.max(drawn) == pytest.approx(summary["penetration_mm"], abs=1e-3)
    assert np.max(report.penetration_series_mm) == pytest.approx(report.penetration_mm)
    assert _line(axis, "limit").get_ydata()[0] == report.thresholds.penetration_mm


def test_penetration_series_of_a_body_sunk_into_the_floor():
    """A body sunk 20 mm into the floor in its second half: the series is the depth beyond
    the 5 mm tolerance of the lowest body point, nothing in the first half, and its deepest
    frame is the penetration the text reports."""
    from dynamics.humanoid.check import check_motion
    from mocap.body.segments import default_skeleton
    from mocap.skeleton import Motion

    skeleton = default_skeleton(1.75)
    frames = 40
    root = np.zeros((frames, 3))
    root[frames // 2:, 1] = -0.020
    report = check_motion(Motion(skeleton, root, np.tile(np.eye(3), (frames, skeleton.count,
                                                                   1, 1)), 50.0), floor=0.0)
    series = report.penetration_series_mm
    assert np.array_equal(series, np.clip(-report.lowest_point_mm - 5.0, 0.0, None))
    assert not series[:frames // 2].any() and (series[frames // 2:] > 0).all()
    assert series.max() == report.penetration_mm


def test_check_plot_from_the_command_line(tmp_path, capsys):
    out = tmp_path / "check.png"
    assert main(["check", str(realdata_path(*WALK)), "-m", "plugingait-full", "--forces",
                 "plates", "--plot", str(out)]) == 0
    assert out.stat().st_size > 10_000
