"""A TRC file's Time column is kept only when it can be the frames' times (found by the
hostile re-run of issue 11: a Time column running backwards, standing still or at another
rate than DataRate was read without a word and written again as it was)."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from mocap.io import read, write
from tests.conftest import REALDATA, realdata_path

SHORT = ("opensim_models", "Pipelines", "Leg39", "leg39_swing_short.trc")   # 14 frames, 60 Hz


def _with_times(source: Path, target: Path, change) -> None:
    lines = source.read_text().splitlines(keepends=True)
    rows = [line.split("\t") for line in lines[5:] if line.strip()]
    times = [row[1] for row in rows]
    for row, time in zip(rows, change(times)):
        row[1] = time
    target.write_text("".join(lines[:5]) + "".join("\t".join(row) for row in rows))


@pytest.mark.parametrize("change, words", [
    (lambda t: t[:5] + [t[6], t[5]] + t[7:], "runs backwards or stands still at row 7"),
    (lambda t: t[::-1], "runs backwards or stands still at row 2"),
    (lambda t: ["0.5"] * len(t), "runs backwards or stands still at row 2"),
    (lambda t: t[:3] + [""] + t[4:], "1 empty or non-numeric cell(s) (first at row 4)"),
    (lambda t: [f"{2 * float(x):.9f}" for x in t], "spans 0.433333 s but DataRate (60 Hz)"),
])
def test_a_time_column_that_cannot_be_the_frames_times_warns_and_is_replaced(
        change, words, tmp_path):
    source = realdata_path(*SHORT)
    bad = tmp_path / "bad.trc"
    _with_times(source, bad, change)
    trial = read(bad)
    warnings = trial.metadata["warnings"]
    assert len(warnings) == 1 and words in warnings[0] and "timed by DataRate" in warnings[0]
    # written again, the frames are timed by the rate: frame numbers kept, times (n-1)/60
    write(trial, tmp_path / "out.trc")
    again = read(tmp_path / "out.trc")
    assert again.metadata["warnings"] == []
    frames = again.frame_numbers
    np.testing.assert_allclose(again.frame_times, (frames - 1) / 60.0, atol=1e-9)
    np.testing.assert_allclose(again.points, read(source).points, atol=1e-9)   # 1 nm places


def test_every_real_trc_keeps_its_time_column_without_a_time_warning():
    files = sorted(realdata_path("opensim_models").rglob("*.trc")) + \
        [REALDATA / "pyomeca" / "markers.trc"]
    assert len(files) >= 13
    for path in files:
        trial = read(path)
        assert not any("Time column" in w for w in trial.metadata["warnings"]), path
        rows = [re.split("[\t,]", line) for line in path.read_text().splitlines()[5:]]
        rows = [row for row in rows if len(row) > 1 and row[1].strip()]
        times = np.array([float(row[1]) for row in rows])
        np.testing.assert_array_equal(trial.frame_times, times[:trial.frames])
