"""BVH and ASF/AMC on real files: positions against readers written from the specifications
and against bvhio, units detected, write → read exact for every channel layout."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocap.io.asfamc import read_asf_amc
from mocap.io.bvh import UNIT_SCALES, read_bvh, write_bvh
from mocap.body.retarget import reduce_to_segments
from mocap.body.segments import BODY_SEGMENTS
from tests.conftest import realdata_path, require_module
from tests.mocap.io.spec_fk import (acclaim_positions, bvh_world_positions, parse_amc, parse_asf,
                                 parse_bvh)

DATA = Path(__file__).resolve().parents[2] / "data"
#: 0.01 mm, in metres.
TOLERANCE = 1e-5


def bandai_files() -> list[Path]:
    files = sorted(realdata_path("bandai2").glob("*.bvh"))
    assert len(files) >= 100
    return files


def _frames(count: int) -> np.ndarray:
    return np.unique(np.r_[np.arange(0, count, 7), count - 1])


def _spec_difference(path: Path, motion) -> float:
    """Largest distance (m) between our joint and end-site positions and the spec's."""
    spec = parse_bvh(path.read_text())
    frames = _frames(motion.frames)
    names, joints, ends = bvh_world_positions(spec, frames)
    assert names == motion.names
    scale = UNIT_SCALES[motion.metadata["units"]]
    ours = motion.slice(0, None).forward_kinematics()[1][frames]
    _, our_ends = motion.end_site_positions()
    return max(float(np.abs(ours - joints * scale).max()),
               float(np.abs(our_ends[frames] - ends * scale).max()))


def _bvhio_difference(path: Path, motion, frames) -> float:
    bvhio = require_module("bvhio")
    root = bvhio.readAsHierarchy(str(path))
    layout = [joint for joint, _, _ in root.layout()]
    index = [motion.names.index(j.Name) for j in layout]
    ours = motion.forward_kinematics()[1]
    scale = UNIT_SCALES[motion.metadata["units"]]
    worst = 0.0
    for frame in frames:
        root.loadPose(int(frame))
        theirs = np.array([list(j.PositionWorld) for j in layout]) * scale
        worst = max(worst, float(np.abs(theirs - ours[frame, index]).max()))
    return worst


def test_bandai2_positions_equal_the_specification_and_bvhio_units_are_cm():
    """Every file once: units, spec FK on every 7th frame; bvhio on every 9th file."""
    worst_spec, worst_bvhio = 0.0, 0.0
    for k, path in enumerate(bandai_files()):
        motion = read_bvh(path)
        assert motion.metadata["units"] == "cm" and motion.metadata["units_detected"], path
        assert motion.rate == 30.0
        worst_spec = max(worst_spec, _spec_difference(path, motion))
        if k % 9 == 0:
            frames = [0, motion.frames // 2, motion.frames - 1]
            worst_bvhio = max(worst_bvhio, _bvhio_difference(path, motion, frames))
    assert worst_spec < 1e-9          # the same arithmetic: float rounding only
    assert worst_bvhio < TOLERANCE    # bvhio computes in float32


def test_bandai2_bones_keep_their_length_and_the_hips_travel():
    """The position channels replace OFFSET: thigh = |LowerLeg_L channels|, hips move."""
    path = realdata_path("bandai2", "dataset-2_walk_normal_001.bvh")
    motion = read_bvh(path)
    spec = parse_bvh(path.read_text())
    columns = {}
    column = 0
    for joint in spec["joints"]:
        columns[joint["name"]] = column
        column += len(joint["channels"])
    knee = columns["LowerLeg_L"]
    channel_length = np.linalg.norm(spec["table"][:, knee:knee + 3], axis=1) * 0.01
    world = motion.forward_kinematics()[1]
    thigh = np.linalg.norm(world[:, motion.names.index("LowerLeg_L")]
                           - world[:, motion.names.index("UpperLeg_L")], axis=1)
    np.testing.assert_allclose(thigh, channel_length, atol=1e-12)
    hips = columns["Hips"]
    travelled = np.linalg.norm(np.ptp(spec["table"][:, [hips, hips + 2]], axis=0)) * 0.01
    ours = np.linalg.norm(np.ptp(world[:, motion.names.index("Hips")][:, [0, 2]], axis=0))
    assert travelled > 1.0 and ours == pytest.approx(travelled, abs=1e-12)


def test_bandai2_maps_onto_the_body():
    motion = read_bvh(realdata_path("bandai2", "dataset-2_run_active_001.bvh"))
    body = reduce_to_segments(motion)
    assert body.names == BODY_SEGMENTS
    mapped = body.metadata["segment_map"]
    assert (mapped["pelvis"], mapped["thorax"], mapped["l_thigh"], mapped["r_forearm"]) == \
        ("Hips", "Chest", "UpperLeg_L", "LowerArm_R")
    world = motion.forward_kinematics()[1]
    np.testing.assert_allclose(body.forward_kinematics()[1][:, 0],
                               world[:, motion.names.index("Hips")], atol=1e-9)
    # The rig's head and hands end at their joints (End Site OFFSET 0): the body gives them
    # lengths in proportion to their parents; the feet reach the toe joints.
    ends = np.linalg.norm(body.skeleton.end_sites, axis=1)
    for leaf in ("head", "l_hand", "r_hand", "l_foot", "r_foot"):
        assert ends[BODY_SEGMENTS.index(leaf)] > 0.05, leaf
    toe = world[:, motion.names.index("Toes_L")]
    _, body_ends = body.end_site_positions()
    np.testing.assert_allclose(body_ends[:, 3].mean(axis=0), toe.mean(axis=0), atol=0.01)


def test_tests_data_bvh_equals_the_specification_and_bvhio():
    path = DATA / "mocapbank_walk.bvh"
    motion = read_bvh(path)
    assert motion.metadata["units"] == "cm"
    assert _spec_difference(path, motion) < 1e-9
    assert _bvhio_difference(path, motion, range(motion.frames)) < TOLERANCE


def test_cmu_asf_amc_equals_the_acclaim_specification():
    asf_path, amc_path = DATA / "cmu_lambada.asf", DATA / "cmu_lambada.amc"
    motion = read_asf_amc(asf_path, amc_path)
    assert motion.metadata["units"] == "in"
    asf = parse_asf(asf_path.read_text())
    reference = acclaim_positions(asf, parse_amc(amc_path.read_text()))
    scale = 0.0254 / asf["length"]
    world = motion.forward_kinematics()[1]
    leaves, ends = motion.end_site_positions()
    worst = 0.0
    for j, name in enumerate(motion.names):
        worst = max(worst, float(np.abs(world[:, j] - reference[name] * scale).max()))
    for k, j in enumerate(leaves):
        end = reference[motion.names[j] + ".end"] * scale
        worst = max(worst, float(np.abs(ends[:, k] - end).max()))
    assert worst < 1e-9
    assert 1.5 < np.ptp(motion.all_points()[0, :, 1]) < 1.9


# ----------------------------------------------------------------------------------------
# Write → read
# ----------------------------------------------------------------------------------------
def _same_motion(a, b, tolerance: float = 1e-7) -> None:
    assert a.names == b.names and a.skeleton.parents == b.skeleton.parents
    assert a.rate == b.rate and a.frames == b.frames
    assert a.metadata["bvh_channels"] == b.metadata["bvh_channels"]
    np.testing.assert_allclose(b.rotations, a.rotations, atol=1e-9)
    np.testing.assert_allclose(b.local_translations(), a.local_translations(), atol=tolerance)
    np.testing.assert_allclose(b.forward_kinematics()[1], a.forward_kinematics()[1],
                               atol=tolerance)
    np.testing.assert_allclose(b.skeleton.offsets, a.skeleton.offsets, atol=tolerance)


def test_bandai2_write_read_is_exact_one_take_per_style(tmp_path):
    files = [p for p in bandai_files() if "_walk_" in p.name and p.stem.endswith("001")]
    assert len(files) == 7
    for path in files + [DATA / "mocapbank_walk.bvh"]:
        original = read_bvh(path)
        copy = tmp_path / path.name
        write_bvh(original, copy, units="cm")
        again = read_bvh(copy)
        assert again.metadata["units"] == "cm"
        assert again.metadata["frame_time_text"] == original.metadata["frame_time_text"]
        _same_motion(original, again)
        second = tmp_path / ("2" + path.name)
        write_bvh(again, second, units="cm")
        assert second.read_text() == copy.read_text()


LAYOUTS = """HIERARCHY
ROOT Hips
{
  OFFSET 12.5 95.0 -3.0
  CHANNELS 3 Yrotation Xrotation Zrotation
  JOINT Spine
  {
    OFFSET 0.0 10.0 0.0
    CHANNELS 6 Zrotation Xposition Yrotation Yposition Xrotation Zposition
    JOINT Head
    {
      OFFSET 0.0 60.0 0.0
      CHANNELS 1 Yposition
      End Site
      {
        OFFSET 0.0 20.0 0.0
      }
    }
  }
  JOINT LeftUpLeg
  {
    OFFSET 9.0 -5.0 0.0
    CHANNELS 2 Xrotation Zrotation
    JOINT LeftLeg
    {
      OFFSET 0.0 -45.0 0.0
      CHANNELS 0
      End Site
      {
        OFFSET 0.0 -45.0 0.0
      }
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0111111
10.0 20.0 30.0 5.0 1.0 -4.0 11.0 7.0 -2.0 61.0 30.0 -20.0
-170.0 80.0 175.0 -95.0 2.0 100.0 9.0 -60.0 3.0 59.0 -120.0 45.0
0.0 0.0 0.0 0.0 0.0 0.0 10.0 0.0 0.0 60.0 0.0 0.0
"""


def test_every_channel_layout_writes_and_reads_back_exactly(tmp_path):
    """Rotation-only root with an OFFSET, mixed 6-channel order, a lone position channel,
    two rotation channels, no channels: the layout and the motion survive."""
    path = tmp_path / "layouts.bvh"
    path.write_text(LAYOUTS)
    motion = read_bvh(path, units="cm")
    assert _spec_difference(path, motion) < 1e-12
    assert _bvhio_difference(path, motion, range(3)) < TOLERANCE
    for units in ("cm", "m", "mm", "in"):
        copy = tmp_path / f"copy_{units}.bvh"
        write_bvh(motion, copy, units=units, precision=9)
        again = read_bvh(copy, units=units)
        _same_motion(motion, again, tolerance=1e-8)
    # The root OFFSET is its place when it has no position channels (bvhio, Blender).
    np.testing.assert_allclose(motion.forward_kinematics()[1][:, 0], [[0.125, 0.95, -0.03]] * 3)


def test_units_are_detected_from_the_standing_height_of_written_files(tmp_path):
    motion = read_bvh(realdata_path("bandai2", "dataset-2_walk_youthful_002.bvh"))
    body = reduce_to_segments(motion)
    for source in (motion, body):
        for units in ("m", "cm", "mm", "in", "cmu"):
            path = tmp_path / f"{units}.bvh"
            write_bvh(source, path, units=units, precision=8)
            again = read_bvh(path)
            assert again.metadata["units"] == units
            np.testing.assert_allclose(again.forward_kinematics()[1],
                                       source.forward_kinematics()[1], atol=2e-6)


def test_toolkit_bvh_reads_in_bvhio_at_the_toolkit_positions(tmp_path):
    """Interop (issue 14): a BVH the toolkit writes → bvhio's joint positions (< 0.01 mm);
    the root sits where the toolkit put it (its OFFSET is not added)."""
    motion = read_bvh(realdata_path("bandai2", "dataset-2_walk-turn-left_feminine_003.bvh"))
    body = reduce_to_segments(motion)
    # A root OFFSET far from 0 (its rest place), the channels moving it from there.
    start = body.forward_kinematics()[1][0, 0]
    body.skeleton.offsets[0] = start
    body.root_translation = body.root_translation - start
    assert np.abs(body.skeleton.offsets[0]).max() > 0.5
    for source, units in ((motion, "m"), (body, "m"), (body, "cm")):
        path = tmp_path / f"{len(source.names)}_{units}.bvh"
        write_bvh(source, path, units=units, precision=9)
        again = read_bvh(path, units=units)
        frames = [0, source.frames // 3, source.frames - 1]
        assert _bvhio_difference(path, again, frames) < TOLERANCE
        world = source.forward_kinematics()[1]
        np.testing.assert_allclose(again.forward_kinematics()[1], world, atol=1e-8)


def test_frame_rates_are_kept_exactly_or_rounded_on_request(tmp_path):
    motion = read_bvh(DATA / "mocapbank_walk.bvh")
    odd = motion.resampled(90.7858)
    path = tmp_path / "odd.bvh"
    write_bvh(odd, path)
    again = read_bvh(path)
    assert again.rate == pytest.approx(90.7858, rel=1e-14)
    write_bvh(odd, path, round_rate=True)
    rounded = read_bvh(path)
    assert rounded.rate == 91.0
    assert rounded.frames == int(np.floor(odd.duration * 91.0 + 1e-9)) + 1
    # Resampling keeps the poses at the frames it hits (t = 0) and the path in between.
    np.testing.assert_allclose(rounded.forward_kinematics()[1][0],
                               odd.forward_kinematics()[1][0], atol=1e-7)
