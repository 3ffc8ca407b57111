"""Known answers of the dynamics check on rigs of every kind it reads (issue 21).

Each trial is a rig moved along a known root path, so its exact residual, penetration,
floating and skating are known: still (0, 0, 0, none), raised 30 cm (100 % BW, 300 mm
floating), free fall (0: gravity alone explains it), sliding at 1 m/s (skating), a
ballistic jump (no residual in flight, no floating). The rigs: a CMU-named BVH whose
ankle and toe joints touch the floor (game and tool exports), the same with its joints
inside the foot, and the body the marker trials are built on.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from dynamics.humanoid.check import DEFAULT_LOWPASS, check_motion
from mocap.body.retarget import reduce_to_segments
from mocap.cli import main
from mocap.filtering import butterworth_lowpass
from mocap.io.motion import read_motion
from tests.dynamics.rigs import cmu_like_bvh, root_path

MASS = 70.0


def _check(path, **options):
    body = reduce_to_segments(read_motion(path), partial=True)
    return check_motion(body, body_mass=MASS, **options).summary()


def test_curvature_ends_keep_a_free_fall_falling_at_g():
    """filtfilt's odd reflection turns a trial that ends accelerating into one that
    decelerates there: 0.3 s of free fall at 60 Hz, low-passed at 6 Hz, read -4.1 m/s²
    in its first frame; padded to keep the ends' curvature it falls at g throughout."""
    t = np.arange(18) / 60.0
    fall = 1.5 - 0.5 * 9.81 * t ** 2
    reflected = np.diff(butterworth_lowpass(fall, 6.0, 60.0), 2) * 60.0 ** 2
    assert reflected[0] > -5.0                                    # the old ends
    kept = np.diff(butterworth_lowpass(fall, 6.0, 60.0, ends="curvature"), 2) * 60.0 ** 2
    np.testing.assert_allclose(kept, -9.81, atol=1e-9)
    # Far from the ends both pad the same; a sine's ends are no worse than reflected.
    noise = np.random.default_rng(0).normal(0.0, 1e-3, (300, 3))
    assert np.abs(butterworth_lowpass(noise, 6.0, 100.0, ends="curvature")
                  - butterworth_lowpass(noise, 6.0, 100.0))[50:-50].max() < 2e-4
    t = np.arange(60) / 60.0
    cycle = np.sin(2 * np.pi * t)
    error = {ends: np.abs(np.diff(butterworth_lowpass(cycle, 6.0, 60.0, ends=ends) - cycle,
                                  2) * 3600).max() for ends in ("reflect", "curvature")}
    assert error["curvature"] < 0.6 * error["reflect"]


@pytest.mark.parametrize("seconds", [0.3, 0.5])
def test_free_fall_of_a_rig_needs_no_residual(tmp_path, seconds):
    """Dropped from rest, 0.3 s and 0.5 s at 60 Hz with the default 6 Hz low-pass: the
    residual read 28 % and 22 % of body weight (the filter's ends)."""
    path = cmu_like_bvh(tmp_path / "fall.bvh", root_path("free fall", seconds))
    summary = _check(path)
    assert summary["residual_force_rms_pct_bw"] < 1.0
    assert summary["penetration_mm"] == 0.0
    assert not any(r.startswith("floating") for r in summary["reasons"])


def test_check_command_and_library_agree(tmp_path, capsys):
    """``mocap check`` and ``check_motion`` with its defaults give the same numbers: the
    6 Hz low-pass is the library's default (DEFAULT_LOWPASS), not only the command's."""
    path = cmu_like_bvh(tmp_path / "jump.bvh", root_path("jump", 1.5))
    assert main(["check", str(path), "--json", "--mass", str(MASS)]) == 0
    cli = json.loads(capsys.readouterr().out)
    library = _check(path)
    assert cli["lowpass_hz"] == DEFAULT_LOWPASS
    for key in ("residual_force_rms_N", "residual_torque_rms_Nm", "penetration_mm",
                "floating_mm", "foot_skate_mm", "verdict"):
        assert cli[key] == library[key], key
    assert _check(path, lowpass=None) != library                  # the filter matters
