"""BVH read/write, ASF/AMC read and the OpenSim .mot writer: round trips and real files."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocap.errors import MocapError
from mocap.io.asfamc import read_asf_amc
from mocap.io.bvh import detect_units, read_bvh, write_bvh
from mocap.io.mot import write_mot, write_motion_mot
from mocap.body.retarget import reduce_to_segments
from mocap.body.segments import BODY_SEGMENTS, default_skeleton
from mocap.skeleton import Motion

DATA = Path(__file__).resolve().parents[2] / "data"

CMU_STYLE = """HIERARCHY
ROOT Hips
{
\tOFFSET 0.00000 0.00000 0.00000
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
\tJOINT LeftUpLeg
\t{
\t\tOFFSET 10.0 -5.0 0.0
\t\tCHANNELS 3 Zrotation Yrotation Xrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0.0 -40.0 0.0
\t\t}
\t}
\tJOINT Spine
\t{
\t\tOFFSET 0.0 10.0 0.0
\t\tCHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0.0 120.0 0.0
\t\t}
\t}
}
MOTION
Frames: 2
Frame Time: 0.0083333
1.0 90.0 2.0 90.0 0.0 0.0 0.0 0.0 30.0 0.0 0.0 0.0 0.0 0.0 0.0
1.0 90.0 2.0 0.0 90.0 0.0 0.0 0.0 0.0 0.0 0.0 0.0 0.0 0.0 0.0
"""


def _random_motion(frames: int = 30, seed: int = 1) -> Motion:
    sk = default_skeleton(1.7)
    rng = np.random.default_rng(seed)
    rotvec = np.cumsum(rng.normal(scale=0.2, size=(frames, sk.count, 3)), axis=0)
    rotations = Rotation.from_rotvec(rotvec.reshape(-1, 3)).as_matrix()
    return Motion(sk, rng.normal(size=(frames, 3)), rotations.reshape(frames, sk.count, 3, 3),
                  100.0)


def test_hand_written_cmu_style_bvh_reads_with_channel_orders_and_units(tmp_path):
    path = tmp_path / "cmu.bvh"
    path.write_text(CMU_STYLE)
    motion = read_bvh(path)
    assert motion.names == ["Hips", "LeftUpLeg", "Spine"]
    assert motion.metadata["units"] == "cm" and motion.rate == 120.0
    np.testing.assert_allclose(motion.root_translation[0], [0.01, 0.9, 0.02])
    # Frame 0: root Zrotation 90 → the leg's offset (10, -5, 0) cm turns to (5, 10, 0) cm.
    world_r, world_p = motion.forward_kinematics()
    np.testing.assert_allclose(world_p[0, 1], [0.01 + 0.05, 0.9 + 0.1, 0.02], atol=1e-12)
    # Frame 1: root Yrotation 90 (channel order Z Y X) → x goes to -z.
    np.testing.assert_allclose(world_p[1, 1], [0.01, 0.9 - 0.05, 0.02 - 0.1], atol=1e-12)
    # The leg's Xrotation of 30° on frame 0 (ZYX order: R = Rz Ry Rx).
    expected = Rotation.from_euler("ZYX", [0, 0, 30], degrees=True).as_matrix()
    np.testing.assert_allclose(motion.rotations[0, 1], expected, atol=1e-12)
    np.testing.assert_allclose(motion.skeleton.end_sites[1], [0, -0.4, 0])
    assert motion.metadata["bvh_channels"]["Spine"][:3] == ["Xposition", "Yposition",
                                                            "Zposition"]


def test_bvh_write_read_is_exact_to_file_precision(tmp_path):
    motion = _random_motion()
    first, second = tmp_path / "a.bvh", tmp_path / "b.bvh"
    write_bvh(motion, first, units="cm", precision=6)
    again = read_bvh(first, units="cm")
    np.testing.assert_allclose(again.skeleton.offsets, motion.skeleton.offsets, atol=1e-8)
    np.testing.assert_allclose(again.root_translation, motion.root_translation, atol=1e-8)
    # Angles written with 6 decimals (degrees): rotations agree to ~1e-8.
    np.testing.assert_allclose(again.rotations, motion.rotations, atol=2e-8)
    assert again.rate == 100.0 and again.names == motion.names
    write_bvh(again, second, units="cm", precision=6)
    assert first.read_text() == second.read_text()


def test_bvh_units_are_detected_or_stated(tmp_path):
    motion = _random_motion(5)
    for unit in ("m", "cm", "mm", "in", "cmu"):
        path = tmp_path / f"{unit}.bvh"
        write_bvh(motion, path, units=unit, precision=7)
        again = read_bvh(path)
        assert again.metadata["units"] == unit and again.metadata["units_detected"]
        np.testing.assert_allclose(again.skeleton.offsets, motion.skeleton.offsets, atol=1e-6)
    stated = read_bvh(tmp_path / "cm.bvh", units="m")
    np.testing.assert_allclose(stated.skeleton.offsets, motion.skeleton.offsets * 100, atol=1e-4)
    assert detect_units(70.0) == "in" and detect_units(35.0) == "cmu"
    with pytest.raises(ValueError):
        detect_units(9000.0)


def test_real_bvh_reads_maps_and_plays(tmp_path):
    from dynamics.viz.animate import animate_motion

    motion = read_bvh(DATA / "mocapbank_walk.bvh")
    assert motion.frames == 10 and motion.rate == 30.0
    assert motion.metadata["units"] == "cm"
    points = motion.all_points()
    height = np.ptp(points[0, :, 1])
    assert 1.5 < height < 1.9
    assert 0.0 <= points[:, :, 1].min() < 0.05                  # feet at the floor
    body = reduce_to_segments(motion)
    assert body.names == BODY_SEGMENTS
    mapped = body.metadata["segment_map"]
    assert mapped["l_upperarm"] == "LeftShoulder" and mapped["l_thigh"] == "LeftHip"
    assert mapped["thorax"] == "Chest2" and mapped["l_hand"] == "LeftWrist"
    # The body keeps the positions of the mapped joints.
    world = motion.forward_kinematics()[1]
    reduced = body.forward_kinematics()[1]
    index = [motion.names.index(mapped[s]) for s in BODY_SEGMENTS]
    np.testing.assert_allclose(reduced[:, [0, 9, 12]], world[:, [index[0], index[9], index[12]]],
                               atol=1e-9)
    gif = tmp_path / "walk.gif"
    assert animate_motion(motion, gif, max_frames=3, dpi=30, size=(2, 2)) == 3
    assert gif.stat().st_size > 0


def test_bad_bvh_files_give_one_clear_error(tmp_path):
    cases = {
        "nohierarchy.bvh": "MOTION\nFrames: 1\nFrame Time: 0.01\n0\n",
        "truncated.bvh": CMU_STYLE.rsplit("\n", 2)[0][:-10] + "\n",
        "badchannel.bvh": CMU_STYLE.replace("Zrotation Yrotation Xrotation\n\t\tEnd",
                                            "Zrotation Yrotation Wrotation\n\t\tEnd"),
        "text.bvh": CMU_STYLE.replace("1.0 90.0 2.0 0.0", "1.0 abc 2.0 0.0"),
    }
    for name, text in cases.items():
        path = tmp_path / name
        path.write_text(text)
        with pytest.raises(MocapError) as error:
            read_bvh(path)
        assert name in str(error.value)


def test_cmu_asf_amc_reads_into_a_standing_figure():
    motion = read_asf_amc(DATA / "cmu_lambada.asf", DATA / "cmu_lambada.amc")
    assert motion.frames == 4 and motion.rate == 120.0
    assert motion.names[0] == "root" and len(motion.names) == 31
    points = motion.all_points()
    assert 1.6 < np.ptp(points[0, :, 1]) < 1.85                 # a person, in metres
    assert 0.0 < points[:, :, 1].min() < 0.03                   # a foot on the floor
    femur = motion.skeleton.offsets[motion.names.index("ltibia")]
    assert np.linalg.norm(femur) == pytest.approx(7.06802 / 0.45 * 0.0254)
    body = reduce_to_segments(motion)
    assert body.metadata["segment_map"]["l_hand"] == "lhand"
    assert body.metadata["segment_map"]["thorax"] == "thorax"


ASF = """:version 1.10
:name test
:units
  mass 1.0
  length 0.45
  angle deg
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name lfemur
     direction 0 -1 0
     length 9
     axis 0 0 20  XYZ
    dof rx ry rz
  end
  begin
     id 2
     name ltibia
     direction 0 -1 0
     length 9
     axis 0 0 20  XYZ
    dof rx
  end
:hierarchy
  begin
    root lfemur
    lfemur ltibia
  end
"""


def test_asf_amc_rotation_convention(tmp_path):
    """G = G_parent C M C⁻¹: a knee flexion rx = 90° about the tibia's axis frame C = Rz(20°)."""
    (tmp_path / "t.asf").write_text(ASF)
    (tmp_path / "t.amc").write_text(":FULLY-SPECIFIED\n:DEGREES\n1\nroot 0 20 0 0 0 0\n"
                                    "lfemur 0 0 0\nltibia 90\n")
    motion = read_asf_amc(tmp_path / "t.asf", tmp_path / "t.amc")
    unit = 0.0254 / 0.45
    c = Rotation.from_euler("z", 20, degrees=True).as_matrix()
    m = Rotation.from_euler("x", 90, degrees=True).as_matrix()
    knee = np.array([0, 20 - 9, 0]) * unit
    shank = c @ m @ c.T @ np.array([0, -9, 0]) * unit
    _, ends = motion.end_site_positions()
    np.testing.assert_allclose(ends[0, 0], knee + shank, atol=1e-12)
    (tmp_path / "bad.amc").write_text("1\nroot 0 0 0 0 0 0\nltibia 1 2\n")
    with pytest.raises(MocapError, match="degrees of freedom"):
        read_asf_amc(tmp_path / "t.asf", tmp_path / "bad.amc")


def test_mot_writer_uses_the_opensim_header(tmp_path):
    path = tmp_path / "knee.mot"
    write_mot(path, np.array([0.0, 0.01]), ["knee_angle_r", "hip_flexion_r"],
              np.array([[10.0, 20.0], [11.0, 21.0]]), name="knee")
    lines = path.read_text().splitlines()
    assert lines[:7] == ["knee", "version=1", "nRows=2", "nColumns=3", "inDegrees=yes",
                         "endheader", "time\tknee_angle_r\thip_flexion_r"]
    assert [float(v) for v in lines[8].split("\t")] == [0.01, 11.0, 21.0]
    motion = _random_motion(4)
    write_motion_mot(motion, tmp_path / "m.mot")
    header = (tmp_path / "m.mot").read_text().splitlines()
    assert header[3] == f"nColumns={1 + 3 + 3 * 15}"
    assert header[6].split("\t")[:5] == ["time", "pelvis_tx", "pelvis_ty", "pelvis_tz",
                                         "pelvis_Z"]
