"""Numeric options whose only bound was '> 0' or none at all (found by the hostile re-run of
issue 11): a value that parses as a finite number but is absurd must stop at parsing with one
line stating the limit, not overflow later (``check --rate 1e-300``: savgol's
``1/rate ** 2``; ``animate --fps 1e-300``: a GIF delay beyond 16 bits) or be taken as given
(``check --floor 1e23`` judged a floor 1e26 mm away; ``decompose --ridge inf`` fitted with an
infinite ridge and printed ``ridge α = inf``)."""
from __future__ import annotations

from pathlib import Path

import pytest

from dynamics.viz.render import GIF_MAX_DELAY, gif_delay, real_time_stride
from mocap.cli import main

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.mark.parametrize("argv, limit", [
    (["check", "{data}/cmu_lambada.amc", "--rate", "1e-300"], ">= 0.001"),
    (["animate", "{data}/mocapbank_walk.bvh", "-o", "{tmp}/a.gif", "--fps", "1e-300"], ">= 0.01"),
    (["simulate", "swinging-rope", "-o", "{tmp}/s.npz", "--gif", "{tmp}/s.gif", "--fps", "1e-9"],
     ">= 0.01"),
    (["check", "{data}/mocapbank_walk.bvh", "--floor", "1e23"], "<= 1000"),
    (["check", "{data}/mocapbank_walk.bvh", "--floor", "nan"], "'auto' or a finite number"),
    (["decompose", "{tmp}", "-m", "synthetic15", "-o", "{tmp}/m.npz", "--ridge", "inf"], "<= 1e+06"),
    (["evaluate", "{tmp}", "-m", "synthetic15", "--ridge", "-1"], ">= 0"),
])
def test_absurd_finite_values_stop_at_parsing_with_the_limit(argv, limit, tmp_path, capsys):
    argv = [a.format(data=DATA, tmp=tmp_path) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "must be" in err[0] and limit in err[0], err
    assert list(tmp_path.iterdir()) == []


def test_values_inside_the_ranges_still_run(tmp_path, capsys):
    assert main(["check", str(DATA / "mocapbank_walk.bvh"), "--floor", "auto"]) == 0
    assert main(["check", str(DATA / "mocapbank_walk.bvh"), "--floor", "-0.02"]) == 0


def test_the_slowest_allowed_animation_is_written_with_the_longest_gif_delay(tmp_path, capsys):
    # 4 AMC frames at the slowest rate allowed: 1000 s per frame, more than a GIF can hold
    amc = tmp_path / "cmu_lambada.amc"
    amc.write_bytes((DATA / "cmu_lambada.amc").read_bytes())
    (tmp_path / "cmu_lambada.asf").write_bytes((DATA / "cmu_lambada.asf").read_bytes())
    out = tmp_path / "slow.gif"
    assert main(["animate", str(amc), "--rate", "0.001", "--max-frames", "3", "--dpi", "20",
                 "-o", str(out)]) == 0
    from PIL import Image
    with Image.open(out) as image:
        delays = []
        for index in range(image.n_frames):
            image.seek(index)
            delays.append(image.info["duration"])
    assert delays and set(delays) == {10 * GIF_MAX_DELAY}
    assert gif_delay(0.01) == 10000 and gif_delay(1e-9) == GIF_MAX_DELAY
    assert real_time_stride(0.001, 4, 3)[1] == GIF_MAX_DELAY
    assert real_time_stride(100.0, 300, 300) == (2, 2)
