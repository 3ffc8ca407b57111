"""Known answers of the dynamics check on rigs of every kind it reads (issue 21).

Each trial is a rig moved along a known root path, so its exact residual, penetration,
floating and skating are known: still (0, 0, 0, none), raised 30 cm (100 % BW, 300 mm
floating), free fall (0: gravity alone explains it), sliding at 1 m/s (skating), a
ballistic jump (no residual in flight, no floating), walking on the spot (one foot at a
time carries the body: 0, 0, 0, none). The rigs: a CMU-named BVH whose
ankle and toe joints touch the floor (game and tool exports), the same with its joints
inside the foot, Bandai's own rig (bandai2, 30 Hz, in a real take's standing pose), the
CMU ASF/AMC skeleton and the body the marker trials are built on.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from dynamics.humanoid.check import DEFAULT_LOWPASS, check_motion
from mocap.body.retarget import reduce_to_segments
from mocap.cli import main
from mocap.clean.filtering import butterworth_lowpass
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


def test_fitted_ends_smooth_the_ends_like_the_middle():
    """``ends="fitted"`` (the check's): a free fall still falls at g to the last frame,
    and white noise comes out of the end frames no rougher than through the odd
    reflection, half as rough as through the cubic about the end sample (second
    differences of 1 mm noise at 100 Hz, 6 Hz)."""
    t = np.arange(18) / 60.0
    fall = 1.5 - 0.5 * 9.81 * t ** 2
    kept = np.diff(butterworth_lowpass(fall, 6.0, 60.0, ends="fitted"), 2) * 60.0 ** 2
    np.testing.assert_allclose(kept, -9.81, atol=1e-9)
    noise = np.random.default_rng(3).normal(0.0, 1e-3, (120, 4000))
    spread = {ends: (np.diff(butterworth_lowpass(noise, 6.0, 100.0, ends=ends), 2, axis=0)
                     * 1e4).std(axis=1) for ends in ("reflect", "curvature", "fitted")}
    assert spread["fitted"][0] < 0.6 * spread["curvature"][0]
    assert spread["fitted"][0] <= spread["reflect"][0]
    np.testing.assert_allclose(spread["fitted"][50:-50], spread["reflect"][50:-50], rtol=0.05)


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


# ---------------------------------------------------------------------------------------
# Every kind of rig, moved along known root paths
# ---------------------------------------------------------------------------------------
#: rig → its frame rate (Hz)
RIGS = {"bvh joints on the floor": 60.0, "bvh joints above the floor": 60.0,
        "bandai2 rig": 30.0, "asf/amc skeleton": 120.0, "marker body": 100.0}


def _still(rig: str, tmp_path):
    """The rig's still motion (rest pose) standing with its lowest point on y = 0, and
    the height of the lowest point of its feet's rig points (ankle, toe) at rest."""
    from mocap.body.segments import default_skeleton
    from mocap.skeleton import Motion

    rate = RIGS[rig]
    if rig.startswith("bvh"):
        heights = (0.0, 0.0) if "on the floor" in rig else (8.0, 2.0)
        path = cmu_like_bvh(tmp_path / "rig.bvh", root_path("still", 1.0, rate), rate,
                            *heights)
        return read_motion(path), heights[1] / 100.0
    if rig == "bandai2 rig":
        # Bandai's own rig (toe joints 4-6 cm up in shoes, the foot bone pitched 40°) in
        # the first pose of a real standing take, held: its rest pose is not a stance.
        from tests.conftest import realdata_path

        take = read_motion(realdata_path("bandai2/dataset-2_raise-up-both-hands_normal_001.bvh"))
        still = Motion(take.skeleton, np.repeat(take.root_translation[:1], int(rate), axis=0),
                       np.repeat(take.rotations[:1], int(rate), axis=0), rate,
                       dict(take.metadata))
        body = reduce_to_segments(still, partial=True)
        world_r, world_p = body.forward_kinematics()
        feet = [body.skeleton.index(n) for n in ("l_foot", "r_foot")]
        toes = [world_p[0, f] + world_r[0, f] @ body.skeleton.end_sites[f] for f in feet]
        return still, min(min(t[1] for t in toes), world_p[0, feet, 1].min())
    if rig == "asf/amc skeleton":
        from pathlib import Path

        amc = read_motion(Path(__file__).resolve().parents[1] / "data" / "cmu_lambada.amc")
        still = Motion.still(amc.skeleton, int(rate), rate)
        still.metadata.update(amc.metadata)
    else:
        still = Motion.still(default_skeleton(1.75), int(rate), rate)
    world_r, world_p = still.forward_kinematics()
    _, ends = still.end_site_positions((world_r, world_p))
    lowest = min(world_p[0, :, 1].min(), ends[0, :, 1].min())
    still.root_translation[:, 1] -= lowest
    return still, 0.0


def _moved(still, kind: str, seconds: float):
    from mocap.skeleton import Motion

    path = root_path(kind, seconds, still.rate) / 100.0 - [0.0, 0.95, 0.0]
    return Motion(still.skeleton, still.root_translation[:1] + path,
                  np.repeat(still.rotations[:1], len(path), axis=0), still.rate,
                  dict(still.metadata))


@pytest.fixture(scope="module", params=list(RIGS))
def rig(request, tmp_path_factory):
    return request.param, *_still(request.param, tmp_path_factory.mktemp("rig"))


def _summary(motion):
    return check_motion(reduce_to_segments(motion, partial=True), body_mass=MASS).summary()


def test_still(rig):
    """Standing still: plausible, no residual, no penetration, no floating (a rig whose
    ankle and toe joints touch the floor read 'penetrates the floor by 66 mm': its
    sole was put 7 cm under the ankle, a Bandai-shaped prior)."""
    _, still, _ = rig
    summary = _summary(_moved(still, "still", 2.0))
    assert summary["verdict"] == "plausible", summary["reasons"]
    assert summary["residual_force_rms_pct_bw"] < 1.0
    assert summary["penetration_mm"] < 5.0 and summary["floating_mm"] < 5.0


def test_raised(rig):
    """Held 30 cm up: the whole weight is residual and the rig floats by 30 cm plus what
    its own lowest foot point stands above its rest (the joints-on-floor rig read
    229 mm: its sole was invented 7 cm below the joints)."""
    _, still, lowest = rig
    summary = _summary(_moved(still, "raised", 2.0))
    assert summary["residual_force_rms_pct_bw"] == pytest.approx(100.0, abs=0.5)
    assert summary["floating_mm"] == pytest.approx(300.0 + 1000.0 * lowest, abs=1.0)
    assert any(r.startswith("floating") for r in summary["reasons"])


def test_free_fall(rig):
    """Falling from rest for 0.3 s: gravity explains it all; the flight is not
    floating."""
    _, still, _ = rig
    summary = _summary(_moved(still, "free fall", 0.3))
    assert summary["residual_force_rms_pct_bw"] < 1.0
    assert summary["floating_mm"] == 0.0 and summary["penetration_mm"] == 0.0
    assert summary["verdict"] == "plausible", summary["reasons"]


def test_sliding(rig):
    """Gliding at 1 m/s on planted feet: skating, 1000 / rate mm per frame."""
    _, still, _ = rig
    summary = _summary(_moved(still, "sliding", 2.0))
    assert summary["foot_skate_mm"] == pytest.approx(1000.0 / still.rate, rel=1e-3)
    assert any("skate" in r for r in summary["reasons"])
    assert summary["penetration_mm"] == 0.0


def test_ballistic_jump(rig):
    """Standing, 0.3 s of flight at g (11 cm high), standing: the take-off and landing
    are the floor's, the flight gravity's: no residual, no floating (the BVH rig with
    its joints above the floor read 24 % BW: the low-pass spread the take-off and
    landing into the flight, and its apex was taken for a 105 mm platform)."""
    _, still, _ = rig
    summary = _summary(_moved(still, "jump", 1.5))
    assert summary["residual_force_rms_pct_bw"] < 1.0
    assert summary["floating_mm"] == 0.0 and summary["penetration_mm"] == 0.0
    if still.rate >= 50.0:
        assert summary["verdict"] == "plausible", summary["reasons"]
    else:
        # At 30 Hz the instant take-off and landing lie above the 6 Hz band: the residual's
        # limit passes the body weight, and the check says it cannot judge it.
        assert summary["verdict"] == "not judged" and summary["reasons"] == []
        assert summary["not_judged"][0].startswith("residual")


def test_walking_on_the_spot(rig):
    """Walking on the spot, quasi-static (tests/dynamics/rigs.walking_on_the_spot): the
    weight shifts over one foot, the other lifts 10-20 cm straight up and comes down, then
    the other way. One foot carries the whole body in turn, the centre of mass over it:
    plausible, no residual, no penetration, floating or skating."""
    from dynamics.humanoid.kinematics import centre_of_mass
    from dynamics.humanoid.model import build_humanoid
    from tests.dynamics.rigs import walking_on_the_spot

    _, still, _ = rig
    body = reduce_to_segments(still, partial=True)
    humanoid = build_humanoid(body.skeleton, MASS)
    walk = walking_on_the_spot(body, lambda m: centre_of_mass(humanoid,
                                                              *m.forward_kinematics()))
    report = check_motion(reduce_to_segments(walk, partial=True), body_mass=MASS)
    summary = report.summary()
    feet = np.array(report.contact_names)
    for side in ("l_foot", "r_foot"):                      # each foot off the floor in turn
        lifted = ~report.contact_active[:, np.char.startswith(feet, side)].any(axis=1)
        assert 0.2 * walk.rate < lifted.sum() < 1.0 * walk.rate       # of its 1 s swing
    assert summary["verdict"] == "plausible", summary["reasons"]
    assert summary["residual_force_rms_pct_bw"] < 1.0
    assert summary["residual_torque_rms_Nm"] < 5.0        # centre of mass 12 cm aside: 11
    assert summary["penetration_mm"] < 5.0 and summary["floating_mm"] == 0.0
    assert summary["foot_skate_mm"] < 0.1


# ---------------------------------------------------------------------------------------
# What a rate can judge
# ---------------------------------------------------------------------------------------
def test_a_run_at_30_hz_is_not_judged_and_never_plausible():
    """A generated run's flights (0.06 s) at 100 Hz are six frames, whose parabola the
    check tests (plausible); at 30 Hz they are 1-2 frames, too few to tell a free fall
    from a body held up: the verdict is "not judged", saying why (it was "plausible"),
    while a walk at 30 Hz is still judged and the same run held 30 cm up still fails
    (marker trials' soles are calibrated to their stances, so the lift reads as the
    weight's residual, not as floating)."""
    from mocap.body.retarget import motion_from_trial
    from mocap.markersets import load_markerset
    from mocap.synthetic import synthesize_trial

    def checked(action, rate, lift=0.0):
        trial, _ = synthesize_trial(0, action, cycles=2, rate=rate)
        trial.points[..., 2] += lift
        return check_motion(motion_from_trial(trial, load_markerset("synthetic15"))).summary()

    fast = checked("run", 100.0)
    assert fast["verdict"] == "plausible" and fast["not_judged"] == []
    slow = checked("run", 30.0)
    assert slow["verdict"] == "not judged" and slow["reasons"] == []
    assert len(slow["not_judged"]) == 1 and "too short to tell a free fall" in slow["not_judged"][0]
    assert checked("walk", 30.0)["verdict"] == "plausible"
    held = checked("run", 30.0, lift=0.3)
    assert held["verdict"] == "implausible" and held["not_judged"] == []
    assert any(r.startswith("residual force") for r in held["reasons"])


# ---------------------------------------------------------------------------------------
# The trial's own limits (dynamics.humanoid.limits)
# ---------------------------------------------------------------------------------------
def test_noise_is_measured_where_the_feet_stand_still():
    """1 mm of white noise on points that stand still a quarter of the time and swing fast
    (up to 5 m/s: at 30 Hz, a fourth difference of centimetres) the rest: the still frames
    give the noise back within 10 %; all frames would read the swing as noise."""
    from dynamics.humanoid.limits import measured_noise

    rate, frames = 30.0, 600
    t = np.arange(frames) / rate
    rng = np.random.default_rng(1)
    swing = (t % 2.0) >= 0.5
    path = np.where(swing, 0.4 * np.sin(2 * np.pi * 2.0 * t), 0.0)
    points = np.stack([path, path, path], axis=1)[:, None, :] \
        + rng.normal(0.0, 1e-3, (frames, 2, 3))
    assert measured_noise(points, rate) == pytest.approx(1e-3, rel=0.1)
    everything = np.median(np.abs(np.diff(points, 4, axis=0))) / (0.6745 * np.sqrt(70.0))
    assert everything > 1.4e-3


def test_noise_gain_is_the_pipelines_on_white_noise():
    """The gain from position noise to the check's acceleration noise, computed on an
    impulse, equals the spread of the pipeline's output on long white noise (2 %)."""
    from dynamics.humanoid.limits import noise_gain
    from mocap.clean.filtering import savgol

    rate, window, order = 100.0, 11, 3
    noise = np.random.default_rng(2).normal(0.0, 1.0, 200_000)
    out = savgol(butterworth_lowpass(noise, 6.0, rate), window, order, deriv=2,
                 delta=1.0 / rate)
    assert noise_gain(rate, 6.0, window, order) == pytest.approx(out[500:-500].std(),
                                                                 rel=0.02)
    out = savgol(noise, window, order, deriv=2, delta=1.0 / rate)
    assert noise_gain(rate, None, window, order) == pytest.approx(out[500:-500].std(),
                                                                  rel=0.02)


def test_limits_and_margins_are_in_the_json(tmp_path, capsys):
    """``--json`` carries each judged figure with its trial limit, margin and ratio, and
    the parts of the expected residual: a still rig with no noise and no acceleration is
    held to the contact model's resolution (3.1 × 1 % BW), a raised one fails it by its
    weight."""
    path = cmu_like_bvh(tmp_path / "still.bvh", root_path("still", 2.0))
    assert main(["check", str(path), "--json", "--mass", str(MASS)]) == 0
    limits = json.loads(capsys.readouterr().out)["limits"]
    force = limits["residual_force_rms_pct_bw"]
    assert force["limit"] == pytest.approx(3.1, abs=0.01) and force["source"] == "trial"
    assert force["margin"] == pytest.approx(force["limit"] - force["value"], abs=1e-3)
    assert set(limits["expected"]["force_N"]) == {"noise", "inertial", "filter", "resolution"}
    assert limits["noise_mm"] == 0.0
    path = cmu_like_bvh(tmp_path / "raised.bvh", root_path("raised", 2.0))
    assert main(["check", str(path), "--json", "--mass", str(MASS),
                 "--max-residual", "50"]) == 0
    force = json.loads(capsys.readouterr().out)["limits"]["residual_force_rms_pct_bw"]
    assert force["source"] == "given" and force["limit"] == 50.0
    assert force["margin"] == pytest.approx(-50.0, abs=0.1)


def test_the_report_as_a_table_holds_the_known_answer():
    """CheckReport.to_dataframe: a still body is held by the floor alone - the contact
    forces carry its weight, the residual is zero - frame by frame in the table."""
    pandas = pytest.importorskip("pandas")
    still, _ = _still("marker body", None)
    report = check_motion(reduce_to_segments(_moved(still, "still", 1.0), partial=True),
                          body_mass=MASS)
    table = report.to_dataframe()
    assert isinstance(table, pandas.DataFrame) and len(table) == report.frames
    assert table.index.name == "time" and table.index[1] == pytest.approx(1.0 / report.rate)
    np.testing.assert_allclose(table["contact_force_y"], MASS * 9.81, rtol=0.01)
    assert np.abs(table[["residual_force_x", "residual_force_y",
                         "residual_force_z"]].to_numpy()).max() < 0.01 * MASS * 9.81
    assert {f"{joint}_torque_z" for joint in report.joint_names} <= set(table.columns)
