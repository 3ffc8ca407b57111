"""Hostile BVH files (issue 11): one clear MocapError each, no hang, no giant allocation,
and a seeded, bounded hypothesis fuzz of the reader."""
from __future__ import annotations

import tracemalloc
from datetime import timedelta
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mocap.errors import MocapError
from mocap.io.bvh import MAX_DEPTH, read_bvh

SMALL = """HIERARCHY
ROOT Hips
{
  OFFSET 0.0 0.0 0.0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT LeftUpLeg
  {
    OFFSET 10.0 -5.0 0.0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT LeftLeg
    {
      OFFSET 0.0 -45.0 0.0
      CHANNELS 3 Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0.0 -45.0 0.0
      }
    }
  }
  JOINT Spine
  {
    OFFSET 0.0 10.0 0.0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0.0 70.0 0.0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
1.0 95.0 2.0 0.0 0.0 0.0 0.0 0.0 0.0 10.0 0.0 0.0 0.0 0.0 0.0
1.5 95.0 2.5 5.0 0.0 0.0 1.0 2.0 3.0 12.0 0.0 0.0 1.0 0.0 0.0
2.0 95.0 3.0 9.0 0.0 0.0 2.0 4.0 6.0 14.0 0.0 0.0 2.0 0.0 0.0
"""


def _error(path: Path) -> str:
    with pytest.raises(MocapError) as error:
        read_bvh(path)
    text = str(error.value)
    assert text.startswith(str(path)) and "\n" not in text
    return text


def test_the_small_file_reads(tmp_path):
    path = tmp_path / "ok.bvh"
    path.write_text(SMALL)
    motion = read_bvh(path)
    assert motion.frames == 3 and motion.metadata["units"] == "cm"


@pytest.mark.parametrize("name, edit, message", [
    ("huge_frame_time", ("Frame Time: 0.0333333", "Frame Time: 1e999"), "frame time"),
    ("nan_frame_time", ("Frame Time: 0.0333333", "Frame Time: nan"), "frame time"),
    ("zero_frame_time", ("Frame Time: 0.0333333", "Frame Time: 0"), "frame time"),
    ("nan_channel", ("1.5 95.0 2.5 5.0", "1.5 nan 2.5 5.0"), "nan on frame 2, channel 2"),
    ("inf_channel", ("2.0 95.0 3.0", "2.0 -inf 3.0"), "-inf on frame 3"),
    ("nan_offset", ("OFFSET 10.0 -5.0 0.0", "OFFSET 10.0 nan 0.0"), "finite"),
    ("huge_offset", ("OFFSET 10.0 -5.0 0.0", "OFFSET 1e308 -5.0 0.0"), "within"),
    ("huge_channel", ("2.0 95.0 3.0", "2.0 1e300 3.0"), "within"),
    ("short_line", ("1.5 95.0 2.5 5.0 0.0 0.0 1.0", "1.5 95.0 2.5 5.0 0.0 1.0"),
     "line 2 has 14 values, the hierarchy declares 15 channels"),
    ("truncated", ("2.0 95.0 3.0 9.0 0.0 0.0 2.0 4.0 6.0 14.0 0.0 0.0 2.0 0.0 0.0\n", ""),
     "truncated"),
    ("cut_mid_line", ("6.0 14.0 0.0 0.0 2.0 0.0 0.0\n", ""), "line 3 has 8 values"),
    ("billion_frames", ("Frames: 3", "Frames: 1000000000"), "truncated"),
    ("negative_frames", ("Frames: 3", "Frames: -3"), "nothing to read"),
    ("float_frames", ("Frames: 3", "Frames: 3.5"), "whole number"),
    ("channel_count", ("CHANNELS 3 Zrotation Xrotation Yrotation\n    End",
                       "CHANNELS 9 Zrotation Xrotation Yrotation\n    End"), "channel count"),
    ("repeated_channel", ("CHANNELS 3 Zrotation Xrotation Yrotation\n    End",
                          "CHANNELS 3 Zrotation Zrotation Yrotation\n    End"), "repeats"),
    ("no_motion", ("MOTION", "MOTON"), "no MOTION"),
])
def test_hostile_bvh_gives_one_line(tmp_path, name, edit, message):
    path = tmp_path / f"{name}.bvh"
    assert edit[0] in SMALL
    path.write_text(SMALL.replace(edit[0], edit[1], 1))
    assert message in _error(path)


def test_ten_thousand_nested_joints_give_one_line_not_a_recursion_error(tmp_path):
    depth = 10_000
    lines = ["HIERARCHY", "ROOT j0", "{", "OFFSET 0 1 0", "CHANNELS 3 Zrotation Xrotation "
             "Yrotation"]
    for k in range(1, depth):
        lines += [f"JOINT j{k}", "{", "OFFSET 0 1 0", "CHANNELS 1 Zrotation"]
    lines += ["End Site", "{", "OFFSET 0 1 0", "}"] + ["}"] * depth
    lines += ["MOTION", "Frames: 1", "Frame Time: 0.01", " ".join(["0"] * (depth + 2))]
    path = tmp_path / "deep.bvh"
    path.write_text("\n".join(lines) + "\n")
    assert f"deeper than {MAX_DEPTH}" in _error(path)
    # Below the limit a deep chain reads (and without recursion).
    shallow = MAX_DEPTH - 1
    lines = ["HIERARCHY", "ROOT j0", "{", "OFFSET 0 0 0", "CHANNELS 1 Zrotation"]
    for k in range(1, shallow + 1):
        lines += [f"JOINT j{k}", "{", "OFFSET 0 0.004 0", "CHANNELS 1 Zrotation"]
    lines += ["End Site", "{", "OFFSET 0 0.004 0", "}"] + ["}"] * (shallow + 1)
    lines += ["MOTION", "Frames: 1", "Frame Time: 0.01", " ".join(["0"] * (shallow + 1))]
    path.write_text("\n".join(lines) + "\n")
    motion = read_bvh(path, units="m")
    assert motion.skeleton.count == shallow + 1


def test_a_billion_frames_in_a_small_file_allocates_nothing_big(tmp_path):
    path = tmp_path / "bomb.bvh"
    body = SMALL.replace("Frames: 3", "Frames: 1000000000")
    body += "\n".join([SMALL.splitlines()[-1]] * 60) + "\n"       # a 6 KB file
    path.write_text(body)
    assert path.stat().st_size < 8000
    tracemalloc.start()
    try:
        assert "truncated" in _error(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20e6


def test_many_joints_times_many_frames_is_refused_before_allocation(tmp_path):
    """4000 joints with no channels under a one-channel root, 6000 frames of one value:
    a 300 KB file that would need 2 GB of rotations."""
    lines = ["HIERARCHY", "ROOT r", "{", "OFFSET 0 0 0", "CHANNELS 1 Zrotation"]
    for k in range(4000):
        lines += [f"JOINT j{k}", "{", "OFFSET 0 0.1 0", "CHANNELS 0", "End Site", "{",
                  "OFFSET 0 0.1 0", "}", "}"]
    lines += ["}", "MOTION", "Frames: 6000", "Frame Time: 0.01"] + ["0"] * 6000
    path = tmp_path / "wide.bvh"
    path.write_text("\n".join(lines) + "\n")
    tracemalloc.start()
    try:
        assert "joint-frames" in _error(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 100e6


TOKENS = ["{", "}", "JOINT", "ROOT", "End", "Site", "OFFSET", "CHANNELS", "MOTION", "Frames:",
          "Frame", "Time:", "nan", "inf", "-1e999", "1e308", "0", "3", "6", "7", "-2",
          "Xposition", "Zrotation", "Wrotation", "\n", " ", "\t", "x", "1.5.3", "0x10", "1_0"]


@settings(max_examples=250, derandomize=True, deadline=timedelta(seconds=10),
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(edits=st.lists(st.tuples(st.floats(0, 1), st.integers(0, 40),
                                st.sampled_from(TOKENS)), min_size=1, max_size=6),
       units=st.sampled_from([None, "cm", "m"]))
def test_fuzzed_bvh_reads_or_raises_mocap_error(tmp_path, edits, units):
    """Random cuts and insertions of BVH tokens: a Motion with finite values or a
    MocapError, never another exception (hypothesis, seeded, 250 cases)."""
    text = SMALL
    for where, cut, token in edits:
        at = int(where * len(text))
        text = text[:at] + token + text[at + cut:]
    path = tmp_path / "fuzz.bvh"
    path.write_text(text)
    try:
        motion = read_bvh(path, units=units)
    except MocapError as error:
        assert "\n" not in str(error)
        return
    assert np.isfinite(motion.rotations).all() and np.isfinite(motion.root_translation).all()
    assert np.isfinite(motion.all_points()).all()
