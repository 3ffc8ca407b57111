"""Markerless C3D (Theia3D ROTATION group): poses, info, angles, rewriting, truncation."""
from __future__ import annotations

import json

import numpy as np
import pytest

from mocap.cli import main
from mocap.errors import MocapError
from mocap.io import read, write
from tests.conftest import realdata_path


@pytest.fixture(scope="module")
def theia():
    return realdata_path("ezc3d_testFiles", "C3DRotationExample.c3d")


@pytest.fixture(scope="module")
def ezc3d_poses(theia):
    import ezc3d

    return np.asarray(ezc3d.c3d(str(theia))["data"]["rotations"])   # (4, 4, segments, frames)


def test_segment_poses_equal_ezc3d(theia, ezc3d_poses):
    trial = read(theia)
    poses = trial.poses
    assert trial.labels == [] and poses.frames == trial.frames == 340
    assert len(poses.labels) == 21 and poses.labels[:3] == ["worldbody", "pelvis", "l_thigh"]
    assert poses.rate == 85.0
    rotations = ezc3d_poses[:3, :3].transpose(3, 2, 0, 1)
    np.testing.assert_array_equal(np.isnan(poses.rotations), np.isnan(rotations))
    np.testing.assert_allclose(poses.rotations, rotations, atol=1e-12, equal_nan=True)
    np.testing.assert_allclose(poses.positions * 1000.0,                 # file in mm
                               ezc3d_poses[:3, 3].transpose(2, 1, 0), atol=1e-9, equal_nan=True)
    assert np.isnan(poses.rotations).any()        # untracked frames are NaN, not identity


def test_truncated_rotation_block_is_refused(theia, tmp_path):
    data = theia.read_bytes()
    cut = tmp_path / "cut.c3d"
    cut.write_bytes(data[:2 * len(data) // 3])
    with pytest.raises(MocapError, match="truncated: the ROTATION block"):
        read(cut)
    assert main(["info", str(cut)]) == 2


def test_info_lists_the_segments(theia, capsys):
    assert main(["info", str(theia), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["rotations"][:2] == ["worldbody", "pelvis"] and len(summary["rotations"]) == 21
    assert main(["info", str(theia)]) == 0
    assert "rotations: 21 segment poses at 85 Hz" in capsys.readouterr().out


def _relative_angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation angle (degrees) of aᵀb per frame, by the trace formula."""
    cos = (np.einsum("fji,fji->f", a, b) - 1.0) / 2.0
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def test_angles_from_rotations_match_a_hand_calculation(theia, ezc3d_poses, tmp_path):
    """Knee angle: the rotation between thigh and shank poses as ezc3d decodes them
    (trace formula) equals the rotation of the written Euler angles."""
    from scipy.spatial.transform import Rotation

    from mocap.io.angles_csv import read_angles_csv

    out = tmp_path / "angles.csv"
    assert main(["angles", str(theia), "--from-rotations", "-o", str(out)]) == 0
    angles = read_angles_csv(out)
    labels = read(theia).poses.labels
    assert "worldbody" not in angles.segments and angles.segments[0] == "pelvis"
    for child, parent in (("l_shank", "l_thigh"), ("r_shank", "r_thigh"),
                          ("l_thigh", "pelvis"), ("head", "neck")):
        a = ezc3d_poses[:3, :3, labels.index(parent)].transpose(2, 0, 1)
        b = ezc3d_poses[:3, :3, labels.index(child)].transpose(2, 0, 1)
        expected = _relative_angle(a, b)
        values = angles.values[:, angles.segments.index(child)]
        seen = np.isfinite(values).all(axis=1)
        np.testing.assert_array_equal(seen, np.isfinite(expected))
        ours = Rotation.from_euler("ZXY", values[seen], degrees=True).magnitude()
        np.testing.assert_allclose(np.degrees(ours), expected[seen], atol=1e-3)
    knee = angles.values[:, angles.segments.index("l_shank")]
    assert 50 < np.nanmax(np.abs(knee)) < 90          # walking: peak knee flexion ~60-70°


def test_a_given_hierarchy_and_refusals(theia, tmp_path):
    toml = tmp_path / "legs.toml"
    toml.write_text('[parents]\npelvis = ""\nl_thigh = "pelvis"\nl_shank = "l_thigh"\n')
    out = tmp_path / "legs.csv"
    assert main(["angles", str(theia), "--from-rotations", "--segments", str(toml),
                 "-o", str(out)]) == 0
    assert out.read_text().splitlines()[0].startswith("time,pelvis.Z")
    toml.write_text('[parents]\npelvis = ""\nknee = "pelvis"\n')
    assert main(["angles", str(theia), "--from-rotations", "--segments", str(toml),
                 "-o", str(tmp_path / "x.csv")]) == 2
    assert main(["angles", str(theia), "-o", str(tmp_path / "y.csv")]) == 2
    assert not (tmp_path / "x.csv").exists() and not (tmp_path / "y.csv").exists()


def test_c3d_writing_keeps_the_rotation_group(theia, ezc3d_poses, tmp_path):
    import ezc3d

    trial = read(theia)
    copy = tmp_path / "copy.c3d"
    assert write(trial, copy) == []
    back = read(copy)
    assert back.poses.labels == trial.poses.labels
    np.testing.assert_array_equal(back.poses.rotations, trial.poses.rotations)
    np.testing.assert_array_equal(back.poses.positions, trial.poses.positions)
    theirs = np.asarray(ezc3d.c3d(str(copy))["data"]["rotations"])
    # the 3 × 4 pose (ezc3d leaves the homogeneous row of an untracked pose as NaN when
    # it wrote the file itself, as 0 0 0 1 in Theia's)
    np.testing.assert_allclose(theirs[:3], ezc3d_poses[:3], atol=1e-9, equal_nan=True)
    # turned to OpenSim's Y-up lab, the poses turn with the lab
    from mocap.io.lab import Z_TO_Y_UP, rotate_trial

    turned = rotate_trial(trial, "y").poses
    np.testing.assert_allclose(turned.positions, trial.poses.positions @ Z_TO_Y_UP.T)
