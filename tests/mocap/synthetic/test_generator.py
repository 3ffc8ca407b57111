"""The synthetic generator: ground truth, planted feet, signatures, corpus files."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.synthetic import (ACTIONS, MARKER_LABELS, SEGMENT_NAMES, generate_corpus,
                             make_people, person_angles, synthesize_trial, truth_angles)


def test_same_seed_same_trial_other_seed_other_trial():
    first, _ = synthesize_trial(1, "walk", seed=3, noise_mm=1.0)
    again, _ = synthesize_trial(1, "walk", seed=3, noise_mm=1.0)
    other, _ = synthesize_trial(1, "walk", seed=4, noise_mm=1.0)
    np.testing.assert_array_equal(first.points, again.points)
    assert first.points.shape != other.points.shape or not np.allclose(first.points, other.points)


@pytest.mark.parametrize("action", ACTIONS)
def test_marker_frames_recover_the_ground_truth(action):
    from mocap.rotations.frames import segment_frames
    from mocap.markersets import load_markerset

    trial, truth = synthesize_trial(2, action)
    rotations, origins = segment_frames(trial, load_markerset("synthetic15"))
    np.testing.assert_allclose(rotations, truth.segment_rotations, atol=1e-9)
    np.testing.assert_allclose(origins, truth.origins, atol=1e-12)


def test_extracted_angles_equal_ground_truth_csv(tmp_path):
    from mocap.rotations.angles import joint_angles
    from mocap.io.angles_csv import read_angles_csv
    from mocap.markersets import load_markerset

    files = generate_corpus(tmp_path, people=2, actions=["walk", "run"], seed=5, sequence="YXZ")
    assert [f.name for f in files] == [
        f"{p.name}_{a}.c3d" for p in make_people(2, 5) for a in ("walk", "run")]
    from mocap import io
    trial = io.read(files[1])
    assert trial.labels == list(MARKER_LABELS)
    measured = joint_angles(trial, load_markerset("synthetic15"), sequence="YXZ")
    truth = read_angles_csv(tmp_path / "truth" / files[1].name.replace(".c3d", "_angles.csv"))
    assert measured.segments == truth.segments == list(SEGMENT_NAMES)
    # C3D stores single-precision floats: 1e-7 m on 0.1 m marker spacing ~ 1e-4 degrees
    np.testing.assert_allclose(measured.values, truth.values, atol=2e-3)
    assert (tmp_path / "truth" / "people.csv").read_text().startswith("person,height_m")


def _feet(truth):
    """Contact points per foot, (frames, 2 points, 3), right then left."""
    return [np.stack([truth.contact_points[f"{side}_heel"], truth.contact_points[f"{side}_toe"]],
                     axis=1) for side in "rl"]


@pytest.mark.parametrize("action", ["walk", "run"])
@pytest.mark.parametrize("person", [0, 2, 4])
def test_stance_foot_is_planted_on_the_floor(action, person):
    _, truth = synthesize_trial(person, action, cycles=2)
    points = np.concatenate(_feet(truth), axis=1)                        # (frames, 4, 3)
    on_floor = np.abs(points[:, :, 2]) < 1e-9
    assert points[:, :, 2].min() > -1e-4                                  # never below it
    # a point on the floor in two consecutive frames has not moved
    held = on_floor[1:] & on_floor[:-1]
    slide = np.linalg.norm(points[1:] - points[:-1], axis=2)[held]
    assert held.sum() > 0.5 * len(points)
    np.testing.assert_allclose(slide, 0.0, atol=1e-6)                    # micrometres
    supported = on_floor.any(axis=1)
    if action == "walk":
        assert supported.all()                                            # always a foot down
    else:                                                                 # short flight phases
        assert 0.1 < 1 - supported.mean() < 0.35
        assert points[~supported, :, 2].min(axis=1).max() > 0.01
    forward = truth.origins[-1, 0, 0] - truth.origins[0, 0, 0]
    assert forward > (2.0 if action == "walk" else 3.0)                   # metres in two cycles


def test_walks_have_double_support_steady_speed_and_clear_swings():
    """Both feet down after each landing, the stance foot flat in mid-stance while the
    other clears the floor, and a centre of mass whose speed varies as in real walking
    (about ±10-20 %, the pelvis a little more as the legs swing under it)."""
    from mocap.synthetic.balance import _centre_of_mass

    for person in make_people(6):
        _, truth = synthesize_trial(person, "walk", cycles=3)
        phase = (np.arange(len(truth.origins)) / truth.rate / truth.cycle_seconds) % 1.0
        right, left = _feet(truth)
        lowest = [foot[:, :, 2].min(axis=1) for foot in (right, left)]
        double = ((phase > 0.02) & (phase < 0.08)) | ((phase > 0.52) & (phase < 0.58))
        assert max(lowest[0][double].max(), lowest[1][double].max()) < 1e-6
        middle = (phase > 0.15) & (phase < 0.22)                          # right mid-stance
        np.testing.assert_allclose(right[middle, :, 2], 0.0, atol=1e-9)   # flat on the floor
        swing = (phase > 0.22) & (phase < 0.32)                           # left mid-swing
        assert lowest[1][swing].min() > 0.005                             # clears the floor
        centre = _centre_of_mass(truth.segment_rotations, truth.origins, person)
        for path, limit in ((centre, 0.25), (truth.origins[:, 0], 0.30)):
            speed = np.gradient(path[:, 0]) * truth.rate
            assert np.abs(speed / speed.mean() - 1.0).max() < limit
        bob = np.ptp(centre[:, 2])
        assert 0.015 < bob < 0.13                                         # metres


@pytest.mark.parametrize("action, limit", [("walk", 2.0), ("run", 15.0)])
def test_walk_and_run_pass_the_dynamics_check(action, limit):
    """Pinocchio inverse dynamics: the floor can supply (almost) all the forces.  Captured
    walks need 5-10 % body weight; the run's short flight phase falls inside the check's
    0.1 s smoothing window, which costs it some."""
    from dynamics.humanoid.check import check_motion
    from mocap.markersets import load_markerset
    from mocap.body.retarget import motion_from_trial

    trial, _ = synthesize_trial(0, action, cycles=3)
    report = check_motion(motion_from_trial(trial, load_markerset("synthetic15")),
                          lowpass=None).summary()           # the 0.1 s smoothing alone
    assert report["residual_force_rms_pct_bw"] < limit
    assert report["foot_skate_mm"] < 1.0
    assert report["penetration_mm"] < 1.0


@pytest.mark.parametrize("action", ["ascend", "descend"])
def test_stair_feet_are_planted_on_the_treads(action):
    from mocap.synthetic import STEP_RISE

    _, truth = synthesize_trial(1, action, cycles=2)
    for foot in _feet(truth):
        height = foot[:, :, 2]
        on_tread = np.abs(height / STEP_RISE - np.round(height / STEP_RISE)) < 1e-9
        lowest = on_tread.any(axis=1)
        assert 0.45 < lowest.mean() < 0.8                                 # stance fraction
        held = on_tread[1:] & on_tread[:-1]
        slide = np.linalg.norm(foot[1:] - foot[:-1], axis=2)[held]
        np.testing.assert_allclose(slide, 0.0, atol=1e-9)
    climbed = truth.origins[-1, 0, 2] - truth.origins[0, 0, 2]
    sign = 1.0 if action == "ascend" else -1.0
    assert climbed * sign == pytest.approx(4 * STEP_RISE, abs=0.08)      # two cycles


@pytest.mark.parametrize("side", ["r", "l"])
def test_leg_inverse_kinematics_puts_ankle_and_foot_exactly_where_asked(side):
    from scipy.spatial.transform import Rotation

    from mocap.synthetic.legs import _leg_rotations

    person = make_people(1)[0]
    thigh, shank = person.lengths["thigh"], person.lengths["shank"]
    rng = np.random.default_rng(7)
    frames = 200
    pelvis = Rotation.from_euler("YXZ", rng.uniform(-12, 12, (frames, 3)), degrees=True)
    hip = rng.normal(0.0, 0.3, (frames, 3))
    down = Rotation.from_euler("YX", rng.uniform(-1, 1, (frames, 2)) * [45, 20], degrees=True)
    ankle = hip + down.apply([0.0, 0.0, -1.0]) * rng.uniform(0.6, 0.99, (frames, 1)) * (
        thigh + shank)                                                   # knee 16-120 deg
    foot = Rotation.from_euler("ZYX", rng.uniform(-20, 20, (frames, 3)), degrees=True)
    clinical = np.zeros((frames, len(SEGMENT_NAMES), 3))
    twist = rng.uniform(-6, 6, frames)
    clinical[:, SEGMENT_NAMES.index(f"{side}_foot"), 2] = twist
    clinical[:, SEGMENT_NAMES.index(f"{side}_shank"), 2] = rng.uniform(-6, 6, frames)
    hip_joint, knee_joint, ankle_joint = _leg_rotations(
        person, side, pelvis.as_matrix(), hip, ankle, foot.as_matrix(), clinical)
    thigh_frame = pelvis.as_matrix() @ hip_joint
    shank_frame = thigh_frame @ knee_joint
    reached = hip + thigh_frame @ [0.0, 0.0, -thigh] + shank_frame @ [0.0, 0.0, -shank]
    np.testing.assert_allclose(reached, ankle, atol=1e-9)
    np.testing.assert_allclose(shank_frame @ ankle_joint, foot.as_matrix(), atol=1e-9)
    # the knee is a hinge about the thigh's left axis (plus the template's axial twist)
    knee = Rotation.from_matrix(knee_joint).as_euler("YXZ", degrees=True)
    assert (knee[:, 0] > 0).all() and np.abs(knee[:, 1]).max() < 1e-9
    # the hip's axial rotation leaves the ankle the template's axial rotation
    axial = Rotation.from_matrix(ankle_joint).as_euler("YXZ", degrees=True)[:, 2]
    sign = 1.0 if side == "r" else -1.0
    np.testing.assert_allclose(axial, sign * twist, atol=1e-6)


def test_people_have_signatures_that_carry_across_actions():
    people = make_people(6, seed=0)
    phase = np.linspace(0, 1, 100, endpoint=False)
    cells = np.array([[person_angles(p, a, phase) for a in ACTIONS] for p in people])
    deviation = cells - cells.mean(axis=0, keepdims=True)                # person effect
    pairwise = np.sqrt(((cells[:, None] - cells[None]) ** 2).mean(axis=(2, 3, 4, 5)))
    assert pairwise[~np.eye(6, dtype=bool)].min() > 1.0                   # everyone is distinct
    # a person's deviation in one action predicts the sign pattern in another
    flat = deviation.reshape(6, len(ACTIONS), -1)
    correlations = [np.corrcoef(flat[p, 0], flat[p, a])[0, 1] for p in range(6) for a in (1, 2, 3)]
    assert np.median(correlations) > 0.3
    assert len({round(p.lengths["thigh"], 5) for p in people}) == 6


def test_noise_and_gaps():
    clean, _ = synthesize_trial(0, "walk", cycles=3)
    noisy, _ = synthesize_trial(0, "walk", cycles=3, noise_mm=2.0, gap_fraction=0.05)
    missing = np.isnan(noisy.points[..., 0])
    assert 0.05 <= missing.mean() < 0.07
    error = (noisy.points - clean.points)[~missing]
    assert 1.5e-3 < error.std() < 2.5e-3


def test_generate_command_writes_corpus_and_rejects_bad_options(tmp_path, capsys):
    from mocap.cli import main

    assert main(["generate", str(tmp_path / "c"), "--people", "2", "--actions", "walk,descend",
                 "--format", "trc"]) == 0
    assert sorted(p.name for p in (tmp_path / "c").glob("*.trc")) == sorted(
        f"{p.name}_{a}.trc" for p in make_people(2) for a in ("walk", "descend"))
    assert main(["generate", str(tmp_path / "d"), "--actions", "walk,swim"]) == 2
    assert "swim" in capsys.readouterr().err
    assert not (tmp_path / "d").exists() or not any((tmp_path / "d").glob("*.c3d"))


@pytest.mark.parametrize("action", ["ascend", "descend"])
@pytest.mark.parametrize("noise", [0.0, 0.5])
def test_one_cycle_stair_trials_stand_on_their_steps(action, noise):
    """A one-cycle stair trial: each foot stands on one step (the right on the floor, the
    left a step up or down), pushes off from the step before as the trial starts and
    reaches for the next one as it ends. The check finds those steps: nothing penetrates
    or floats, and the ascent is plausible (it was called "penetrating by 335 mm")."""
    from dynamics.humanoid.check import check_motion
    from mocap.body.retarget import motion_from_trial
    from mocap.markersets import load_markerset
    from mocap.synthetic import STEP_RISE

    trial, _ = synthesize_trial(0, action, noise_mm=noise)
    report = check_motion(motion_from_trial(trial, load_markerset("synthetic15")),
                          lowpass=6.0)
    sign = 1.0 if action == "ascend" else -1.0
    levels = report.calibration.levels
    assert min(abs(h) for h in levels) < 0.01                             # the floor
    assert min(abs(h - sign * STEP_RISE) for h in levels) < 0.01          # the next step
    assert report.penetration_mm < 10.0
    assert not any(r.startswith(("penetrates", "floating")) for r in report.reasons)
    if action == "ascend":
        assert report.verdict == "plausible"


def _checked(trial):
    from dynamics.humanoid.check import check_motion
    from mocap.body.retarget import motion_from_trial
    from mocap.markersets import load_markerset

    return check_motion(motion_from_trial(trial, load_markerset("synthetic15")), lowpass=6.0)


@pytest.mark.parametrize("noise", [0.0, 0.5])
def test_generated_corpus_is_dynamically_consistent(noise):
    """Two people of the README's corpus (seed 0, one cycle, 100 Hz, clean and with
    0.5 mm marker noise) under the check as ``mocap batch --check`` runs it: walks and
    stairs plausible with a small residual; runs without floating (their flights are
    ballistic), penetration or skating, the residual force of the 6 Hz low-passed bounce
    under 10 % body weight, and their residual torque within the check's limit now that
    the trunk turns against the legs in flight (it was 59-78 N m, over the 50 N m limit:
    test fails on the old code). The low-pass's ends keep their acceleration
    (``ends="fitted"``) without passing the end samples' noise through, and a toe
    rolling off its step as a stair trial ends stays on it: with cubic end fits about
    the end sample the first and last tenth read 3-12 % (0.5 mm noise) and runs 15-37 %
    (RMS up to 5.5 % and 17 %, over these bounds); now at most 3.4 % and 11 %."""
    for person in (0, 1):
        for action in ACTIONS:
            trial, _ = synthesize_trial(person, action, noise_mm=noise)
            report = _checked(trial)
            summary = report.summary()
            if action == "run":
                assert summary["residual_force_rms_pct_bw"] < 10.0
                assert not any(r.startswith("residual torque") for r in report.reasons)
                assert not any(r.startswith(("floating", "penetrates", "feet skate"))
                               for r in report.reasons)
            else:
                assert report.verdict == "plausible", (action, report.reasons)
                assert summary["residual_force_rms_pct_bw"] < (1.5 if noise == 0 else 3.0)


def test_generated_walk_held_up_is_still_flagged():
    """A generated walk's markers held 0.3 m up: the check calls it implausible (the
    weight it needs is not supplied). (Marker trials are sole-calibrated onto the floor,
    so a uniform lift is partly taken as the soles' offset; the skeleton faults — held up
    and floating, sliding, sunk — are tested in tests/dynamics.)"""
    import copy

    trial, _ = synthesize_trial(0, "walk")
    held = copy.deepcopy(trial)
    held.points[..., 2] += 0.3
    report = _checked(held)
    assert report.verdict == "implausible"
    assert report.summary()["residual_force_rms_pct_bw"] > 20.0
    assert _checked(trial).verdict == "plausible"


def _run_flights(person: int, rate: float):
    """A generated run (2 cycles) on the check's Pinocchio humanoid: centre of mass (F, 3)
    and angular momentum about it (F, 3) N m s from ``pin.computeCentroidalMomentum``
    (world Y up), and the flights as (first, last) frames with both feet off the floor."""
    import pinocchio as pin

    from dynamics.humanoid.kinematics import motion_kinematics
    from dynamics.humanoid.model import build_humanoid
    from mocap.body.retarget import motion_from_trial, reduce_to_segments
    from mocap.markersets import load_markerset

    trial, truth = synthesize_trial(person, "run", cycles=2, rate=rate)
    body = reduce_to_segments(motion_from_trial(trial, load_markerset("synthetic15")))
    humanoid = build_humanoid(body.skeleton, 75.0)
    kin = motion_kinematics(body, smoothing=0.0)           # central differences, no filter
    data = humanoid.model.createData()
    com, momentum = [], []
    for q, v in zip(kin.q, kin.v):
        pin.computeCentroidalMomentum(humanoid.model, data, q, v)
        com.append(data.com[0].copy())
        momentum.append(data.hg.angular.copy())
    low = np.min([p[:, 2] for p in truth.contact_points.values()], axis=0)
    air = low > 1e-3
    edges = np.flatnonzero(np.diff(air.astype(int))) + 1
    flights = [(a, b - 1) for a, b in zip(edges[:-1], edges[1:]) if air[a] and b - a > 20]
    return np.array(com), np.array(momentum), flights, 1.0 / rate


@pytest.mark.parametrize("person", [0, 2])
def test_run_flights_are_ballistic_and_keep_their_angular_momentum(person):
    """Known answers of free flight, on the check's own body model (Pinocchio, de Leva,
    the skeleton rebuilt from the markers), not the generator's: the centre of mass falls
    at g and the angular momentum about it stays constant.  Bound by hand: the check
    allows 50 N m RMS of residual torque for 75 kg; a drift of 1 N m s over a flight of
    80-95 ms is a mean torque of 11-13 N m, a quarter of that.  Before the trunk turned
    against the legs, the legs' swing changed it by 13-14 N m s per flight (test fails on
    the old code)."""
    com, momentum, flights, dt = _run_flights(person, 1000.0)
    assert len(flights) >= 3
    for first, last in flights:
        inner = slice(first + 5, last - 5)               # clear of the contact's edges
        acceleration = np.gradient(np.gradient(com, dt, axis=0), dt, axis=0)[inner]
        assert np.abs(acceleration[:, 1] + 9.81).max() < 0.35           # m/s², Y up
        assert np.abs(acceleration[:, [0, 2]]).max() < 0.35
        drift = np.abs(momentum[last - 5] - momentum[first + 5]).max()
        assert drift < 1.0, (first, drift)


def test_run_with_frozen_flights_is_flagged():
    """A generated run whose markers are held at their take-off height through each
    flight (no ballistic arc: the body neither rises nor falls in the air, which only a
    hand from above could do) is implausible, where the generated run is not."""
    import copy

    trial, truth = synthesize_trial(3, "run", cycles=3)
    low = np.min([p[:, 2] for p in truth.contact_points.values()], axis=0)
    air = low > 1e-3
    report = _checked(trial)
    assert report.verdict == "plausible", report.reasons
    frozen = copy.deepcopy(trial)
    edges = np.flatnonzero(np.diff(air.astype(int))) + 1
    for a, b in zip(edges[:-1], edges[1:]):
        if air[a]:
            frozen.points[a:b, :, 2] = frozen.points[a - 1, :, 2]
    broken = _checked(frozen)
    assert broken.verdict == "implausible"
    assert broken.summary()["residual_force_rms_pct_bw"] > 2 * report.summary()[
        "residual_force_rms_pct_bw"]
