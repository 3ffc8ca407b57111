"""A BVH hierarchy that repeats a joint name (found by the hostile re-run of issue 11): the
joints were read under the same name, so the channel layout kept per name lost all but one
of them, a map by name was ambiguous, and the file was exported again without a word. The
repeated names now get a numbered suffix (as repeated C3D labels do) and a warning."""
from __future__ import annotations

import re

import numpy as np

from mocap.io.bvh import read_bvh, write_bvh
from tests.conftest import realdata_path


def test_repeated_joint_names_are_numbered_with_a_warning_and_survive_a_round_trip(tmp_path):
    source = realdata_path("bandai2", "dataset-2_run_active_001.bvh")
    text = source.read_text()
    motion_at = text.index("MOTION")
    joints = re.findall(r"JOINT (\S+)", text[:motion_at])
    edited = re.sub(r"JOINT (\S+)", "JOINT Same", text[:motion_at], count=3) + text[motion_at:]
    path = tmp_path / "dup.bvh"
    path.write_text(edited)

    original, motion = read_bvh(source), read_bvh(path)
    names = motion.skeleton.names
    assert len(set(names)) == len(names) == len(original.skeleton.names)
    assert names[1:4] == ["Same", "Same_2", "Same_3"] and names[4:] == original.skeleton.names[4:]
    assert joints[3] == original.skeleton.names[4]
    assert motion.metadata["warnings"] == [
        "joint names: 2 repeated label(s) renamed with a numbered suffix: Same_2, Same_3"]
    # every joint keeps its own channels: written and read again, the same motion
    assert len(motion.metadata["bvh_channels"]) == len(names)
    out = tmp_path / "out.bvh"
    write_bvh(motion, out)
    again = read_bvh(out, units=motion.metadata["units"])
    assert again.skeleton.names == names and again.metadata["warnings"] == []
    np.testing.assert_allclose(again.all_points(), original.all_points(), atol=1e-6)
