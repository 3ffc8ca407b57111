"""Motion container, builders from marker trials and joint angles, joint-name mapping."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocap.errors import MocapError
from mocap.body.angles import motion_from_angles
from mocap.body.retarget import Z_UP_TO_Y_UP, motion_from_frames, motion_to_lab, reduce_to_segments
from mocap.body.segments import BODY_SEGMENTS, canonical_segment, default_skeleton, map_segments
from mocap.skeleton import Motion, Skeleton, frame_rate


def _random_motion(frames: int = 50, seed: int = 0) -> Motion:
    rng = np.random.default_rng(seed)
    sk = default_skeleton(1.8)
    rotations = Rotation.random(frames * sk.count, random_state=seed).as_matrix()
    translation = rng.normal(size=(frames, 3))
    return Motion(sk, translation, rotations.reshape(frames, sk.count, 3, 3), 60.0)


def test_forward_kinematics_of_a_two_link_chain_is_exact():
    sk = Skeleton(["a", "b", "c"], [-1, 0, 1], [[0, 1, 0], [0, 0, 2], [1, 0, 0]],
                  [[np.nan] * 3, [np.nan] * 3, [0, 3, 0]])
    quarter = Rotation.from_euler("x", 90, degrees=True).as_matrix()    # y → z, z → -y
    rotations = np.stack([np.eye(3), quarter, np.eye(3)])[None]
    motion = Motion(sk, [[0.0, 0.0, 5.0]], rotations, 100.0)
    world_r, world_p = motion.forward_kinematics()
    np.testing.assert_allclose(world_p[0], [[0, 1, 5], [0, 1, 7], [1, 1, 7]], atol=1e-12)
    which, ends = motion.end_site_positions()
    assert which == [2]
    np.testing.assert_allclose(ends[0, 0], [1, 1, 10], atol=1e-12)   # (0,3,0) turned to +z


def test_default_skeleton_stands_on_the_floor_and_has_the_body_segments():
    sk = default_skeleton(1.75)
    assert sk.names == BODY_SEGMENTS
    points = Motion.still(sk, 1, 100.0).all_points()[0]
    assert points[:, 1].min() == pytest.approx(0.0, abs=1e-12)
    assert points[:, 1].max() == pytest.approx(1.75, abs=1e-9)
    with pytest.raises(ValueError):
        Skeleton(["a", "b"], [1, -1], np.zeros((2, 3)))


def test_motion_from_synthetic_trial_reproduces_the_generator_exactly():
    from mocap.markersets import load_markerset
    from mocap.body.retarget import motion_from_trial
    from mocap.synthetic import synthesize_trial

    trial, truth = synthesize_trial(1, "run", seed=3)
    motion = motion_from_trial(trial, load_markerset("synthetic15"))
    assert motion.names == list(truth.segments)
    np.testing.assert_allclose(motion.skeleton.offsets, truth.offsets @ Z_UP_TO_Y_UP.T,
                               atol=1e-9)
    _, positions = motion.forward_kinematics()
    np.testing.assert_allclose(positions, truth.origins @ Z_UP_TO_Y_UP.T, atol=1e-9)
    rotations, root = motion_to_lab(motion)
    np.testing.assert_allclose(rotations, truth.rotations, atol=1e-9)
    np.testing.assert_allclose(root, truth.origins[:, 0], atol=1e-9)


def test_motion_from_frames_fills_missing_frames_by_slerp():
    frames = 11
    angles = np.linspace(0, 100, frames)
    world = Rotation.from_euler("z", angles[:, None], degrees=True).as_matrix()
    rotations = np.stack([world, world], axis=1)
    origins = np.zeros((frames, 2, 3))
    origins[:, 1] = np.einsum("fij,j->fi", world, [1.0, 0.0, 0.0])
    rotations[4:7, 1] = np.nan
    origins[4:7, 1] = np.nan
    motion = motion_from_frames(rotations, origins, ["a", "b"], [-1, 0], 100.0, up="y")
    np.testing.assert_allclose(motion.skeleton.offsets[1], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(motion.rotations[:, 1], np.broadcast_to(np.eye(3), (frames, 3, 3)),
                               atol=1e-9)
    assert motion.metadata["filled_fraction"] == pytest.approx(3 / 22)


def test_motion_from_angles_round_trips_through_the_lab_frame():
    from mocap.rotations.angles import JointAngles

    motion = _random_motion(20)
    lab, root = motion_to_lab(motion)
    values = Rotation.from_matrix(lab.reshape(-1, 3, 3)).as_euler("ZXY", degrees=True)
    angles = JointAngles(motion.times, values.reshape(20, 15, 3), list(BODY_SEGMENTS), "ZXY",
                         list(motion.skeleton.parents))
    again = motion_from_angles(angles, motion.skeleton, root_translation=root)
    np.testing.assert_allclose(again.rotations, motion.rotations, atol=1e-9)
    np.testing.assert_allclose(again.root_translation, motion.root_translation, atol=1e-9)
    assert again.rate == 60.0
    standing = motion_from_angles(
        JointAngles(np.arange(3) / 100, np.zeros((3, 1, 3)), ["l_thigh"], "ZXY", [-1]))
    assert standing.all_points()[:, :, 1].min() == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(MocapError, match="lacks"):
        motion_from_angles(JointAngles(np.arange(2) / 100, np.zeros((2, 1, 3)), ["tail"],
                                       "ZXY", [-1]))


CMU_BVH = ["Hips", "LHipJoint", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase",
           "RHipJoint", "RightUpLeg", "RightLeg", "RightFoot", "LowerBack", "Spine", "Spine1",
           "Neck", "Neck1", "Head", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand",
           "RightShoulder", "RightArm", "RightForeArm", "RightHand"]
CMU_PARENTS = [-1, 0, 1, 2, 3, 4, 0, 6, 7, 8, 0, 10, 11, 12, 13, 14, 12, 16, 17, 18, 12, 20,
               21, 22]
MIXAMO = ["mixamorig:" + n for n in (
    "Hips", "Spine", "Spine1", "Spine2", "Neck", "Head", "LeftShoulder", "LeftArm",
    "LeftForeArm", "LeftHand", "RightShoulder", "RightArm", "RightForeArm", "RightHand",
    "LeftUpLeg", "LeftLeg", "LeftFoot", "RightUpLeg", "RightLeg", "RightFoot")]
MIXAMO_PARENTS = [-1, 0, 1, 2, 3, 4, 3, 6, 7, 8, 3, 10, 11, 12, 0, 14, 15, 0, 17, 18]


@pytest.mark.parametrize("names, parents, expected", [
    (CMU_BVH, CMU_PARENTS,
     {"pelvis": "Hips", "thorax": "Spine1", "head": "Head", "l_upperarm": "LeftArm",
      "l_forearm": "LeftForeArm", "l_hand": "LeftHand", "l_thigh": "LeftUpLeg",
      "l_shank": "LeftLeg", "l_foot": "LeftFoot", "r_upperarm": "RightArm"}),
    (MIXAMO, MIXAMO_PARENTS,
     {"pelvis": "mixamorig:Hips", "thorax": "mixamorig:Spine2",
      "l_upperarm": "mixamorig:LeftArm", "r_hand": "mixamorig:RightHand",
      "r_thigh": "mixamorig:RightUpLeg", "r_shank": "mixamorig:RightLeg"}),
])
def test_common_joint_names_map_onto_body_segments(names, parents, expected):
    found = map_segments(names, parents)
    assert sorted(found) == sorted(BODY_SEGMENTS)
    for segment, joint in expected.items():
        assert names[found[segment]] == joint


def test_canonical_names():
    assert canonical_segment("LeftThigh") == "l_thigh"
    assert canonical_segment("RightShin") == "r_shank"
    assert canonical_segment("lfemur") == "l_thigh"
    assert canonical_segment("rradius") == "r_forearm"
    assert canonical_segment("LeftToeBase") is None
    assert canonical_segment("lowerback") is None


def test_reduce_refuses_a_skeleton_without_legs():
    sk = Skeleton(["Hips", "Spine", "Head"], [-1, 0, 1], np.eye(3))
    with pytest.raises(MocapError, match="l_thigh"):
        reduce_to_segments(Motion.still(sk, 2, 30.0))


def test_frame_rate_snaps_rounded_frame_times():
    assert frame_rate(0.033333) == 30.0
    assert frame_rate(0.008333) == 120.0
    assert frame_rate(0.0417) == pytest.approx(23.98, abs=0.01)


def test_read_motion_reads_every_kind_and_gives_corpus_angles(tmp_path):
    from pathlib import Path

    from mocap.body.angles import motion_joint_angles
    from mocap.io.motion import read_motion

    data = Path(__file__).resolve().parents[1] / "data"
    bvh = read_motion(data / "mocapbank_walk.bvh")
    amc = read_motion(data / "cmu_lambada.amc")            # finds cmu_lambada.asf beside it
    assert bvh.frames == 10 and amc.frames == 4
    angles = motion_joint_angles(amc, "ZXY")
    assert angles.segments == BODY_SEGMENTS and angles.values.shape == (4, 15, 3)
    assert np.isfinite(angles.values).all()
    lonely = tmp_path / "02_01.amc"
    lonely.write_text((data / "cmu_lambada.amc").read_text())
    with pytest.raises(MocapError, match="asf="):
        read_motion(lonely)
    with pytest.raises(MocapError, match="markerset"):
        (tmp_path / "trial.trc").write_text("x")
        read_motion(tmp_path / "trial.trc")
