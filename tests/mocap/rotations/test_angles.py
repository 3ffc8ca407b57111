"""Segment frames and joint angles: known answers for all 24 Euler sequences,
continuity (unwrapping, branch switches through gimbal lock), missing data,
the CSV round trip, and the Plug-in Gait preset on real walking trials."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocap.rotations.angles import SEQUENCES, GimbalLockWarning, JointAngles, angles_to_matrices, axis_names, is_proper_euler, joint_angles, matrices_to_angles, relative_rotations, unwrap_angles
from mocap.io.angles_csv import read_angles_csv, write_angles_csv
from mocap.errors import MocapError
from mocap.rotations.frames import segment_frames
from mocap.io import read
from mocap.markersets import load_markerset, markerset_from_dict
from mocap.trial import Trial
from tests.conftest import realdata_path

# a tree: pelvis -> (thigh -> shank -> foot), pelvis -> trunk
TREE = [("pelvis", None), ("thigh", "pelvis"), ("shank", "thigh"), ("foot", "shank"),
        ("trunk", "pelvis")]
FRAMES = 120
RATE = 100.0


def tree_markerset():
    return markerset_from_dict({
        "name": "tree",
        "segment": [{"name": n, **({"parent": p} if p else {}),
                     "markers": [f"{n}_O", f"{n}_A", f"{n}_P"]} for n, p in TREE]})


def smooth_truth(sequence: str, seed: int) -> np.ndarray:
    """Known joint angles (frames, segments, 3) in degrees, continuous.

    Each joint starts at the Euler angles of a Rotation.random (principal
    values, kept away from gimbal lock) and moves smoothly: the first and
    third angles sweep far beyond ±180° (unwrapping), the middle one swings
    by ±15° and stays 20° or more from gimbal lock.
    """
    rng = np.random.default_rng(seed)
    proper = is_proper_euler(sequence)
    starts = []
    candidates = Rotation.random(200, random_state=seed).as_euler(sequence, degrees=True)
    for angles in candidates:
        middle = angles[1]
        far = (25 < middle < 155) if proper else abs(middle) < 65
        if far:
            starts.append(angles)
        if len(starts) == len(TREE):
            break
    starts = np.array(starts)
    t = np.arange(FRAMES) / RATE
    sweep = rng.uniform(150, 400, size=(len(TREE), 2)) * rng.choice([-1, 1], (len(TREE), 2))
    truth = np.empty((FRAMES, len(TREE), 3))
    truth[:, :, 0] = starts[:, 0] + sweep[:, 0] * np.sin(np.pi * t[:, None] / t[-1] / 2)
    truth[:, :, 1] = starts[:, 1] + 15 * np.sin(2 * np.pi * 1.3 * t[:, None])
    truth[:, :, 2] = starts[:, 2] + sweep[:, 1] * (t[:, None] / t[-1]) ** 2
    return truth


def markers_from_joints(joint_rot: np.ndarray, seed: int) -> Trial:
    """A trial whose segment frames have the given joint rotations.

    joint_rot (frames, segments, 3, 3); segment rotation = parent rotation @
    joint rotation; three markers per segment at origin, origin + 0.1 e1 and
    a point in the e1-e2 half plane with positive e2.
    """
    rng = np.random.default_rng(seed)
    names = [n for n, _ in TREE]
    glob = np.empty_like(joint_rot)
    for k, (name, parent) in enumerate(TREE):
        glob[:, k] = joint_rot[:, k] if parent is None else \
            glob[:, names.index(parent)] @ joint_rot[:, k]
    origins = rng.normal(scale=0.5, size=(len(TREE), 3)) + \
        0.01 * np.arange(FRAMES)[:, None, None]
    e1, e2 = glob[..., 0], glob[..., 1]
    p1 = origins
    p2 = origins + 0.12 * e1
    p3 = origins - 0.03 * e1 + 0.08 * e2
    points = np.stack([p1, p2, p3], axis=2).reshape(FRAMES, 3 * len(TREE), 3)
    labels = [f"{n}_{s}" for n in names for s in "OAP"]
    return Trial(labels, points, RATE)


@pytest.mark.parametrize("sequence", SEQUENCES)
def test_known_angles_recovered_for_every_sequence(sequence):
    truth = smooth_truth(sequence, seed=SEQUENCES.index(sequence))
    joint_rot = Rotation.from_euler(sequence, truth.reshape(-1, 3), degrees=True) \
        .as_matrix().reshape(FRAMES, len(TREE), 3, 3)
    trial = markers_from_joints(joint_rot, seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", GimbalLockWarning)  # far from lock: no warning
        angles = joint_angles(trial, tree_markerset(), sequence)
    assert angles.values.shape == (FRAMES, len(TREE), 3)
    assert angles.segments == [n for n, _ in TREE]
    assert angles.parents == [-1, 0, 1, 2, 0]
    np.testing.assert_allclose(angles.values, truth, atol=1e-6, rtol=0)
    # the sweeps really went past ±180°, so unwrapping was exercised
    assert np.abs(angles.values[:, :, [0, 2]]).max() > 200
    np.testing.assert_allclose(angles.times, np.arange(FRAMES) / RATE)


@pytest.mark.parametrize("sequence", SEQUENCES)
def test_closed_form_euler_angles_are_scipys_principal_values(sequence):
    """matrices_to_angles (closed forms, no scipy) gives scipy's as_euler: within 1e-12°
    on uniform random rotations at least 0.5° from gimbal lock, and scipy's own lock
    convention (third angle 0) at and within 1e-7 rad of it; NaN matrices give NaN rows."""
    rotations = Rotation.random(20000, random_state=SEQUENCES.index(sequence) + 7)
    reference = rotations.as_euler(sequence, degrees=True)
    ours = matrices_to_angles(rotations.as_matrix(), sequence)
    step = np.abs(ours - reference)
    step = np.minimum(step, 360.0 - step)                   # ±180 is one angle
    middle = reference[:, 1]
    from_lock = np.minimum(middle, 180.0 - middle) if is_proper_euler(sequence) else \
        90.0 - np.abs(middle)                               # degrees
    far = from_lock >= 0.5
    assert far.mean() > 0.98
    assert step[far].max() <= 1e-12
    middle = [0.0, 1e-6, 180.0, 180 - 1e-6] if is_proper_euler(sequence) else \
        [90.0, 90 - 1e-6, -90.0, -90 + 1e-6]
    locked = np.array([[a, b, c] for a in (-150.0, 20.0) for b in middle for c in (35.0, -170)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                     # scipy's gimbal-lock warning
        matrices = Rotation.from_euler(sequence, locked, degrees=True).as_matrix()
        expected = Rotation.from_matrix(matrices).as_euler(sequence, degrees=True)
    ours = matrices_to_angles(matrices, sequence)
    assert (ours[:, 2] == 0).all()
    np.testing.assert_allclose(ours, expected, atol=1e-9, rtol=0)
    matrices[3] = np.nan
    assert np.isnan(matrices_to_angles(matrices, sequence)[3]).all()


@pytest.mark.parametrize("sequence", ["ZXY", "xyz", "ZYZ", "yxy"])
def test_rotations_reproduced_from_angles(sequence):
    """angles_to_matrices inverts the angles whatever the branch or turn count."""
    rng = np.random.default_rng(3)
    rot = Rotation.random(FRAMES * 2, random_state=4).as_matrix().reshape(FRAMES, 2, 3, 3)
    principal = matrices_to_angles(rot, sequence)
    unwrapped = unwrap_angles(principal, sequence)
    shifted = unwrapped + 360 * rng.integers(-2, 3, size=unwrapped.shape)
    for values in (principal, unwrapped, shifted):
        np.testing.assert_allclose(angles_to_matrices(values, sequence), rot, atol=1e-12)


@pytest.mark.parametrize("sequence", ["ZXY", "zxy", "ZYZ", "xzx"])
@pytest.mark.parametrize("small_blocks", [False, True])
def test_passing_gimbal_lock_stays_continuous_and_warns(sequence, small_blocks, request):
    """A joint whose middle angle crosses the principal range's limit (scipy then
    flips all three angles) comes out continuous and equal to the truth, and a
    GimbalLockWarning names the segment and the first frame near the lock."""
    if small_blocks:
        request.getfixturevalue("tiny_blocks")
    proper = is_proper_euler(sequence)
    frames = 60
    limit = 0.0 if proper else 90.0
    # start in scipy's principal range (proper Euler: middle >= 0), then cross the
    # limit, never landing exactly on it
    direction = -1.0 if proper else 1.0
    middle = limit + direction * (-12 + 24 * np.arange(frames) / (frames - 1) + 0.37)
    truth = np.stack([40 + 30 * np.sin(np.arange(frames) / 9), middle,
                      -20 + 0.8 * np.arange(frames)], axis=1)
    rot = angles_to_matrices(truth, sequence)[:, None]                     # one root segment
    principal = matrices_to_angles(rot, sequence)
    assert np.abs(np.diff(principal[:, 0, 0])).max() > 90                 # scipy flips
    np.testing.assert_allclose(unwrap_angles(principal, sequence)[:, 0], truth, atol=1e-6)

    ms = markerset_from_dict({"segment": [{"name": "arm", "markers": ["O", "A", "P"]}]})
    e1, e2 = rot[:, 0, :, 0], rot[:, 0, :, 1]
    trial = Trial(["O", "A", "P"], np.stack([0 * e1, 0.1 * e1, 0.1 * e2], axis=1), 50.0,
                  path="arm.c3d")
    with pytest.warns(GimbalLockWarning) as record:
        angles = joint_angles(trial, ms, sequence, branch="continuous")
    first = int(np.flatnonzero(np.abs(middle - limit) <= 5)[0])
    message = str(record[0].message)
    assert "'arm'" in message and f"frame {first} " in message and "arm.c3d" in message
    np.testing.assert_allclose(angles.values[:, 0], truth, atol=1e-6)


def test_missing_markers_give_nan_rows_for_segment_and_children():
    sequence = "ZXY"
    truth = smooth_truth(sequence, seed=7)
    joint_rot = angles_to_matrices(truth, sequence)
    trial = markers_from_joints(joint_rot, seed=2)
    points = trial.points.copy()
    gone = slice(40, 55)
    points[gone, trial.labels.index("thigh_A")] = np.nan
    angles = joint_angles(trial.with_points(points), tree_markerset(), sequence)
    # thigh and its child shank are unknown there; foot (relative to shank) is
    # known, as are pelvis and trunk
    for name in ("thigh", "shank"):
        k = angles.segments.index(name)
        assert np.isnan(angles.values[gone, k]).all()
        np.testing.assert_allclose(angles.values[:40, k], truth[:40, k], atol=1e-6)
        # after the gap the angles continue from before it (same turn and branch)
        np.testing.assert_allclose(angles.values[55:, k], truth[55:, k], atol=1e-6)
    for name in ("pelvis", "foot", "trunk"):
        k = angles.segments.index(name)
        np.testing.assert_allclose(angles.values[:, k], truth[:, k], atol=1e-6)


def test_segment_frame_follows_design_rule_and_axes_option():
    p1 = np.array([[1.0, 2.0, 3.0]])
    p2 = p1 + [[0.0, 0.0, -0.4]]                    # e1 down
    p3 = p1 + [[0.05, 0.1, -0.2]]                   # left and a little forward
    trial = Trial(["O", "A", "P"], np.stack([p1, p2, p3], axis=1), 100.0)
    plain = markerset_from_dict({"segment": [{"name": "s", "markers": ["O", "A", "P"]}]})
    rot, origin = segment_frames(trial, plain)
    e1 = np.array([0, 0, -1.0])
    e3 = np.cross(e1, p3[0] - p1[0]); e3 /= np.linalg.norm(e3)
    np.testing.assert_allclose(rot[0, 0], np.stack([e1, np.cross(e3, e1), e3], axis=1),
                               atol=1e-15)
    np.testing.assert_allclose(origin[0, 0], p1[0])
    relabelled = markerset_from_dict({"segment": [{"name": "s", "markers": ["O", "A", "P"],
                                                   "axes": ["e3", "e2", "-e1"],
                                                   "origin": "P"}]})
    rot2, origin2 = segment_frames(trial, relabelled)
    np.testing.assert_allclose(rot2[0, 0], rot[0, 0] @ relabelled.segments[0].axes_matrix)
    np.testing.assert_allclose(rot2[0, 0][:, 2], [0, 0, 1.0], atol=1e-15)  # z = -e1 = up
    assert np.linalg.det(rot2[0, 0]) == pytest.approx(1.0)
    np.testing.assert_allclose(origin2[0, 0], p3[0])


def test_collinear_markers_give_nan_frame():
    p = np.array([[0.0, 0, 0], [0.1, 0, 0], [0.3, 0, 0]])[None]
    trial = Trial(["O", "A", "P"], p, 100.0)
    ms = markerset_from_dict({"segment": [{"name": "s", "markers": ["O", "A", "P"]}]})
    rot, origin = segment_frames(trial, ms)
    assert np.isnan(rot).all() and np.isnan(origin).all()


def test_relative_rotations_root_and_children():
    rot = Rotation.random(6, random_state=0).as_matrix().reshape(2, 3, 3, 3)
    rel = relative_rotations(rot, [-1, 0, 1])
    np.testing.assert_allclose(rel[:, 0], rot[:, 0])
    np.testing.assert_allclose(rot[:, 0] @ rel[:, 1], rot[:, 1], atol=1e-12)
    np.testing.assert_allclose(rot[:, 1] @ rel[:, 2], rot[:, 2], atol=1e-12)


def test_bad_sequence_is_a_clear_error():
    trial = markers_from_joints(np.broadcast_to(np.eye(3), (FRAMES, len(TREE), 3, 3)), 0)
    for bad in ("ZZX", "ZxY", "ABC", "ZX"):
        with pytest.raises(MocapError, match="Euler sequence"):
            joint_angles(trial, tree_markerset(), bad)


@pytest.mark.parametrize("sequence", ["ZXY", "ZYZ", "zxz"])
def test_angles_csv_round_trip(tmp_path, sequence):
    truth = smooth_truth(sequence, seed=11)
    truth[5:9, 2] = np.nan                                  # a gap in one segment
    angles = JointAngles(times=np.arange(FRAMES) / RATE, values=truth,
                         segments=[n for n, _ in TREE], sequence=sequence,
                         parents=[-1, 0, 1, 2, 0])
    path = tmp_path / "angles.csv"
    write_angles_csv(angles, path)
    lines = path.read_text().splitlines()
    names = axis_names(sequence)
    assert lines[0].startswith(f"time,pelvis.{names[0]},pelvis.{names[1]},pelvis.{names[2]},"
                               f"thigh.{names[0]}")
    if sequence == "ZYZ":
        assert lines[0].startswith("time,pelvis.Z,pelvis.Y,pelvis.Z2,")
    assert ",,," in lines[1 + 6] and "nan" not in path.read_text()
    back = read_angles_csv(path, tree_markerset())
    assert back.sequence == sequence and back.segments == angles.segments
    assert back.parents == [-1, 0, 1, 2, 0]
    np.testing.assert_allclose(back.times, angles.times, atol=1e-6)
    np.testing.assert_allclose(back.values, angles.values, atol=5e-7)
    assert np.array_equal(np.isnan(back.values), np.isnan(angles.values))


def test_read_angles_csv_rejects_bad_files(tmp_path):
    cases = {
        "header.csv": "frame,a.Z,a.X,a.Y\n0,1,2,3\n",
        "axes.csv": "time,a.Z,a.X,a.Q\n0,1,2,3\n",
        "ragged.csv": "time,a.Z,a.X,a.Y\n0,1,2\n",
        "text.csv": "time,a.Z,a.X,a.Y\n0,1,two,3\n",
    }
    for name, text in cases.items():
        path = tmp_path / name
        path.write_text(text)
        with pytest.raises(MocapError) as error:
            read_angles_csv(path)
        assert name in str(error.value)
    with pytest.raises(MocapError, match="not found"):
        read_angles_csv(tmp_path / "absent.csv")


# ------------------------------------------------------------------ real data


def vicon_output(trial: Trial, label: str) -> np.ndarray:
    """A Plug-in Gait model output Vicon stored in the file (angles in degrees),
    kept by mocap.io.read in ``Trial.modelled``; shape (frames, 3)."""
    modelled = trial.modelled
    return modelled["values"][:, modelled["labels"].index(label), :]


@pytest.mark.parametrize("relative", ["HC002D/Straight/HC002D06.c3d",
                                      "HC030A/Straight/HC030A05.c3d"])
def test_plugingait_preset_knee_flexion_on_real_walk(relative):
    path = realdata_path("biomechzoo_sample_study", *relative.split("/"))
    trial = read(path)
    ms = load_markerset("plugingait-lower")
    assert "RPSI" not in trial.labels and "SACR" in trial.labels
    angles = joint_angles(trial, ms, "YXZ")
    for side in "LR":
        knee = angles.segment(f"{side.lower()}_shank")[:, 0]          # Y: flexion
        assert np.isfinite(knee).mean() > 0.95
        # walking: the knee flexes to 50-70° in swing and nearly straightens in stance
        assert 40 < np.nanmax(knee) < 80
        assert -15 < np.nanmin(knee) < 15
        # and agrees with Vicon's own Plug-in Gait knee flexion stored in the file
        vicon = vicon_output(trial, f"{side}KneeAngles")[:, 0]
        ok = np.isfinite(knee) & np.isfinite(vicon)
        assert np.corrcoef(knee[ok], vicon[ok])[0, 1] > 0.99
        assert abs(np.nanmax(knee) - np.nanmax(vicon[ok])) < 8
        # hip flexion is negative about +y (left) by the preset's convention
        hip = angles.segment(f"{side.lower()}_thigh")[:, 0]
        vicon_hip = vicon_output(trial, f"{side}HipAngles")[:, 0]
        ok = np.isfinite(hip) & np.isfinite(vicon_hip)
        assert np.corrcoef(hip[ok], vicon_hip[ok])[0, 1] < -0.98
        # our Davis hip joint centre lands near Vicon's, which used a measured
        # leg length and inter-ASIS distance (ours: estimated from the markers)
        ours = ms.apply_virtual(trial).marker(f"{side}HJC")
        theirs = trial.marker(f"{side}HJC")
        assert np.nanmedian(np.linalg.norm(ours - theirs, axis=1)) < 0.02


def test_plugingait_preset_with_psis_instead_of_sacrum():
    path = realdata_path("pycgm", "Test_Files", "Movement_trial.c3d")
    trial = read(path)
    assert "SACR" not in trial.labels and "RPSI" in trial.labels
    ms = load_markerset("plugingait-lower")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        angles = joint_angles(trial, ms, "YXZ")
    for side in "LR":
        knee = angles.segment(f"{side.lower()}_shank")[:, 0]
        vicon = vicon_output(trial, f"{side}KneeAngles")[:, 0]
        ok = np.isfinite(knee) & np.isfinite(vicon)
        assert ok.mean() > 0.9
        assert np.corrcoef(knee[ok], vicon[ok])[0, 1] > 0.99


@pytest.fixture
def tiny_blocks(monkeypatch):
    """Blocks of a few frames, so state must carry across many block edges."""
    import mocap.rotations.angles
    import mocap.rotations.frames
    monkeypatch.setattr(mocap.rotations.frames, "BLOCK_FRAMES", 7)
    monkeypatch.setattr(mocap.rotations.angles, "UNWRAP_BLOCK", 5)


@pytest.mark.parametrize("sequence", ["ZXY", "zyz"])
def test_block_edges_change_nothing(tiny_blocks, sequence):
    truth = smooth_truth(sequence, seed=21)
    trial = markers_from_joints(angles_to_matrices(truth, sequence), seed=3)
    points = trial.points.copy()
    points[33:52, trial.labels.index("shank_P")] = np.nan   # a gap across block edges
    points[:9, trial.labels.index("trunk_O")] = np.nan      # missing from the start
    angles = joint_angles(trial.with_points(points), tree_markerset(), sequence)
    expected = truth.copy()
    expected[33:52, [2, 3]] = np.nan                         # shank and its child foot
    expected[:9, 4] = np.nan
    valid = np.isfinite(expected)
    assert np.array_equal(np.isfinite(angles.values), valid)
    # the trunk starts at frame 9 in scipy's principal range: compare rotations
    # there, values elsewhere
    trunk = angles.values[:, 4]
    np.testing.assert_allclose(angles_to_matrices(trunk[9:], sequence),
                               angles_to_matrices(truth[9:, 4], sequence), atol=1e-9)
    np.testing.assert_allclose(angles.values[:, :4], expected[:, :4], atol=1e-6)
    # and unwrap_angles in small blocks equals one whole-array pass
    principal = matrices_to_angles(angles_to_matrices(truth, sequence), sequence)
    np.testing.assert_allclose(unwrap_angles(principal, sequence), truth, atol=1e-6)
