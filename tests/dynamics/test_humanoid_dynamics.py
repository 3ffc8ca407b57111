"""Pinocchio humanoid: known answers of the plausibility check and of the dynamics."""
from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from mocap.errors import MocapError
from mocap.body.segments import BODY_SEGMENTS, default_skeleton
from mocap.skeleton import Motion
from mocap.body.anthropometry import segment_table
from dynamics.humanoid.check import check_motion
from dynamics.humanoid.contact_forces import solve_contact_forces
from dynamics.humanoid.inverse import rnea_batch
from dynamics.humanoid.kinematics import configurations, motion_kinematics
from dynamics.humanoid.model import build_humanoid

MASS = 75.0
WEIGHT = MASS * 9.81


@pytest.fixture(scope="module")
def skeleton():
    return default_skeleton(1.75)


@pytest.fixture(scope="module")
def body(skeleton):
    return build_humanoid(skeleton, MASS)


def _lean(skeleton, degrees: float, frames: int = 40) -> Motion:
    """The whole body tilted forward about the ankle axis, feet flat on the floor."""
    motion = Motion.still(skeleton, frames, 100.0)
    turn = Rotation.from_euler("x", degrees, degrees=True).as_matrix()
    rest = Motion.still(skeleton, 1, 100.0).forward_kinematics()[1][0]
    ankle = rest[BODY_SEGMENTS.index("l_foot")]
    motion.rotations[:, 0] = turn
    for foot in ("l_foot", "r_foot"):
        motion.rotations[:, BODY_SEGMENTS.index(foot)] = turn.T
    motion.root_translation[:] = ankle + turn @ (rest[0] - ankle) - skeleton.offsets[0]
    return motion


def test_de_leva_masses_sum_to_the_body_mass(body):
    table = segment_table("male")
    assert sum(table[k][0] * (2 if k in ("upperarm", "forearm", "hand", "thigh", "shank", "foot")
                              else 1) for k in table) == pytest.approx(1.0, abs=1e-3)
    assert sum(s.mass for s in body.inertias) == pytest.approx(MASS, rel=1e-3)
    assert body.nq == 7 + 4 * 14 and body.nv == 6 + 3 * 14
    thigh = body.inertias[BODY_SEGMENTS.index("l_thigh")]
    assert thigh.mass == pytest.approx(0.1416 * MASS)
    # COM 40.95 % down the thigh, principal moments m (r L)² with r = .329/.329/.149.
    length = thigh.length
    np.testing.assert_allclose(thigh.com, [0, -0.4095 * length, 0], atol=1e-12)
    np.testing.assert_allclose(np.sort(np.linalg.eigvalsh(thigh.inertia)),
                               np.sort(thigh.mass * length ** 2 * np.array([.149, .329, .329]) ** 2))


def test_still_standing_body_has_no_residual(skeleton):
    report = check_motion(Motion.still(skeleton, 60, 100.0), body_mass=MASS)
    summary = report.summary()
    assert summary["residual_force_rms_pct_bw"] < 1.0
    assert summary["residual_force_peak_N"] < 0.01 * WEIGHT
    assert summary["verdict"] == "plausible" and summary["reasons"] == []
    # The feet carry the weight between them; straight legs need no hip or knee torque.
    vertical = report.contact_forces[:, :, 1].sum(axis=1)
    np.testing.assert_allclose(vertical, WEIGHT, rtol=1e-3)
    assert summary["peak_joint_torque_Nm"]["l_thigh"] < 1.0


def test_body_held_above_the_floor_is_floating_with_full_weight_residual(skeleton):
    motion = Motion.still(skeleton, 60, 100.0, root_translation=[0.0, 0.3, 0.0])
    summary = check_motion(motion, body_mass=MASS).summary()
    assert summary["residual_force_rms_pct_bw"] == pytest.approx(100.0, abs=0.5)
    assert summary["floating_mm"] == pytest.approx(300.0, abs=0.5)
    assert summary["verdict"] == "implausible"
    assert any(reason.startswith("floating") for reason in summary["reasons"])


def test_free_fall_needs_no_residual(skeleton):
    motion = Motion.still(skeleton, 50, 100.0)
    t = motion.times
    motion.root_translation[:, 1] = 3.0 - 0.5 * 9.81 * t ** 2
    motion.root_translation[:, 0] = 0.7 * t                        # thrown sideways too
    summary = check_motion(motion, body_mass=MASS).summary()
    assert summary["residual_force_rms_pct_bw"] < 0.5
    assert summary["residual_torque_rms_Nm"] < 0.5
    assert not any(reason.startswith("floating") for reason in summary["reasons"])


def test_sliding_planted_feet_are_flagged_for_skating(skeleton):
    motion = Motion.still(skeleton, 60, 100.0)
    motion.root_translation[:, 2] = 0.5 * motion.times            # glides at 0.5 m/s
    summary = check_motion(motion, body_mass=MASS).summary()
    assert summary["foot_skate_mm"] == pytest.approx(5.0, rel=1e-6)   # 0.5 m/s at 100 Hz
    assert summary["residual_force_rms_pct_bw"] < 1.0                # no force is needed
    assert any("skate" in reason for reason in summary["reasons"])


def test_static_forward_lean_leaves_the_support(skeleton):
    """A 10° lean keeps the centre of mass over the feet; 20° does not (about 7 % BW)."""
    assert check_motion(_lean(skeleton, 10.0)).summary()["residual_force_rms_pct_bw"] < 0.5
    leaning = check_motion(_lean(skeleton, 20.0)).summary()
    assert 4.0 < leaning["residual_force_rms_pct_bw"] < 10.0
    assert leaning["verdict"] == "implausible"


def test_rnea_then_aba_returns_the_accelerations(body):
    rng = np.random.default_rng(4)
    frames = 20
    q = np.stack([pin.randomConfiguration(body.model, -np.ones(body.nq), np.ones(body.nq))
                  for _ in range(frames)])
    v = rng.normal(size=(frames, body.nv))
    a = rng.normal(size=(frames, body.nv))
    tau = rnea_batch(body, q, v, a)
    data = body.model.createData()
    for k in range(frames):
        np.testing.assert_allclose(tau[k], pin.rnea(body.model, data, q[k], v[k], a[k]),
                                   atol=1e-9)
        np.testing.assert_allclose(pin.aba(body.model, data, q[k], v[k], tau[k]), a[k],
                                   atol=1e-8)


def test_manifold_velocities_match_pinocchio_difference(skeleton, body):
    frames, rate = 200, 200.0
    t = np.arange(frames) / rate
    rng = np.random.default_rng(2)
    amplitude = rng.normal(scale=0.6, size=(15, 3))
    frequency = rng.uniform(0.3, 1.2, size=(15, 3))
    rotvec = amplitude * np.sin(2 * np.pi * frequency * t[:, None, None])
    rotations = Rotation.from_rotvec(rotvec.reshape(-1, 3)).as_matrix().reshape(frames, 15, 3, 3)
    root = np.stack([0.5 * t, 0.9 + 0.05 * np.sin(4 * t), 0.2 * t ** 2], axis=1)
    motion = Motion(skeleton, root, rotations, rate)
    kin = motion_kinematics(motion, smoothing=0.0)
    q = configurations(motion)
    dt = 1.0 / rate
    for k in (50, 120):
        central = pin.difference(body.model, q[k - 1], q[k + 1]) / (2 * dt)
        np.testing.assert_allclose(kin.v[k], central, atol=2e-3 * np.abs(central).max())
        second = (pin.difference(body.model, q[k], q[k + 1])
                  - pin.difference(body.model, q[k - 1], q[k])) / dt ** 2
        np.testing.assert_allclose(kin.a[k], second, atol=2e-3 * np.abs(second).max())
        np.testing.assert_allclose(pin.integrate(body.model, q[k - 1], kin.v[k] * 2 * dt), q[k + 1],
                                   atol=1e-4)


def test_contact_solve_respects_the_friction_pyramid():
    levers = np.array([[[0.1, -1.0, 0.0], [-0.1, -1.0, 0.0]]] * 2)
    active = np.ones((2, 2), bool)
    # Frame 0: pure support; frame 1: asks for a sideways push of 0.5 weight with μ = 0.3.
    wrench = np.array([[0, 700.0, 0, 0, 0, 0], [350.0, 700.0, 0, 0, 0, 350.0]])
    forces, residual = solve_contact_forces(wrench, levers, active, mu=0.3)
    np.testing.assert_allclose(residual[0], 0.0, atol=1e-3)
    np.testing.assert_allclose(forces[0].sum(axis=0), [0, 700, 0], atol=1e-3)
    tangential = np.linalg.norm(forces[..., [0, 2]], axis=-1)
    assert np.all(tangential <= 0.3 * forces[..., 1] + 1e-6)        # inside the pyramid
    # The push exceeds what friction allows: the least-squares compromise leaves
    # part of it (and some vertical excess bought for more friction) as residual.
    assert np.linalg.norm(residual[1, :3]) > 0.15 * 700.0
    supplied = forces[1].sum(axis=0)
    assert supplied[0] <= 0.3 * supplied[1] + 1e-6


def test_model_needs_the_body_segments():
    from mocap.skeleton import Skeleton

    with pytest.raises(MocapError, match="15 body segments"):
        build_humanoid(Skeleton(["a", "b"], [-1, 0], np.eye(2, 3)))


def test_vertical_ground_reaction_matches_force_plates():
    """Real walk (Vicon Plug-in Gait, two force plates): the ground reaction the check
    finds from the markers alone follows the plates' vertical force while the feet are on
    them, with the body mass the plates give."""
    from mocap.io import read
    from mocap.markersets import load_markerset
    from mocap.body.retarget import motion_from_trial
    from tests.conftest import realdata_path

    trial = read(realdata_path("biomechzoo_sample_study", "HC002D", "Straight",
                               "HC002D06.c3d"))
    labels = trial.analog_labels
    per_frame = int(round(trial.analog_rate / trial.rate))
    plates = -trial.analogs[:, [labels.index("Fz1"), labels.index("Fz2")]]
    measured = plates[: trial.frames * per_frame].reshape(trial.frames, per_frame, 2) \
        .mean(axis=1).sum(axis=1)
    on_plates = np.flatnonzero(measured > 20.0)[5:-5]         # feet on the plates
    mass = measured[on_plates].mean() / 9.81
    report = check_motion(motion_from_trial(trial, load_markerset("plugingait-lower")), mass)
    estimated = report.contact_forces[:, :, 1].sum(axis=1)
    correlation = np.corrcoef(estimated[on_plates], measured[on_plates])[0, 1]
    error = np.sqrt(np.mean((estimated - measured)[on_plates] ** 2)) / measured[on_plates].mean()
    assert correlation > 0.8
    assert error < 0.15


def test_floor_can_be_found_where_the_feet_stand_still(skeleton):
    raised = Motion.still(skeleton, 40, 100.0, root_translation=[0.0, 0.3, 0.0])
    report = check_motion(raised, body_mass=MASS, floor="auto")
    assert report.floor_m == pytest.approx(0.3, abs=1e-9)
    assert report.summary()["residual_force_rms_pct_bw"] < 1.0
    assert report.verdict == "plausible"
    stated = check_motion(raised, body_mass=MASS, floor=0.3)
    assert stated.summary()["floating_mm"] == 0.0


def test_shoulder_holds_a_horizontal_arm_with_its_gravity_moment(skeleton, body):
    """Arm abducted 90° and held still: the shoulder torque is Σ m_i g d_i (d_i the
    horizontal distance of each arm segment's centre of mass from the shoulder)."""
    motion = Motion.still(skeleton, 30, 100.0)
    arm = BODY_SEGMENTS.index("l_upperarm")
    motion.rotations[:, arm] = Rotation.from_euler("z", 90, degrees=True).as_matrix()
    report = check_motion(motion, body_mass=MASS, humanoid=body)
    _, positions = motion.forward_kinematics()
    world_r = motion.forward_kinematics()[0]
    shoulder = positions[0, arm]
    moment = 0.0
    for name in ("l_upperarm", "l_forearm", "l_hand"):
        k = BODY_SEGMENTS.index(name)
        com = positions[0, k] + world_r[0, k] @ body.inertias[k].com
        moment += body.inertias[k].mass * 9.81 * np.hypot(*(com - shoulder)[[0, 2]])
    torque = report.joint_torques[:, report.joint_names.index("l_upperarm")]
    np.testing.assert_allclose(np.linalg.norm(torque, axis=1), moment, rtol=1e-6)
    # About the anterior axis (z): the arm hangs out to the left (+x) and gravity pulls down.
    local = world_r[0, arm].T @ np.array([0.0, 0.0, 1.0])
    assert torque[0] @ local == pytest.approx(moment, rel=1e-6)
    assert report.summary()["residual_force_rms_pct_bw"] < 1.0
