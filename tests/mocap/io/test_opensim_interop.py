"""Files the toolkit writes, read by the real tools: OpenSim 4.6 (TRC, .mot) and ezc3d.

These tests run the tools themselves (the ``interop`` extra); under CI a missing tool
fails instead of skipping (tests/conftest.py's require_module).
"""
from __future__ import annotations

import numpy as np
import pytest

from mocap.errors import MocapError
from mocap.io import read, write
from tests.conftest import REALDATA, realdata_path, require_module


def _real_c3d_files():
    if not REALDATA.exists():
        return []
    return sorted(p for p in REALDATA.rglob("*") if p.suffix.lower() == ".c3d")


@pytest.fixture(scope="module")
def opensim():
    module = require_module("opensim")
    module.Logger.setLevelString("error")
    return module


@pytest.mark.filterwarnings("ignore::mocap.errors.MocapWarning")
def test_every_real_c3d_with_markers_gives_a_trc_that_opensim_reads_identically(
        tmp_path, opensim):
    """C3D → TRC (mm, default precision) → opensim.TimeSeriesTableVec3 (its TRC adapter):
    same frame count, times, marker labels, gaps (NaN) and values to the written 1e-6 mm."""
    realdata_path()
    files = _real_c3d_files()
    checked = 0
    for path in files:
        try:
            trial = read(path)
        except MocapError:
            continue                    # damaged samples, refused with a message elsewhere
        if not trial.labels or trial.frames == 0:
            continue
        target = tmp_path / "out.trc"
        write(trial, target)
        table = opensim.TimeSeriesTableVec3(str(target))
        assert list(table.getColumnLabels()) == trial.labels, path
        assert table.getNumRows() == trial.frames, path
        np.testing.assert_allclose(np.array(table.getIndependentColumn()),
                                   trial.time_base()[1], atol=1e-9, err_msg=str(path))
        flat = table.flatten()          # keep the table alive while numpy copies its matrix
        matrix = flat.getMatrix()
        values = matrix.to_numpy()
        expected = trial.points.reshape(trial.frames, -1) * 1000.0
        np.testing.assert_array_equal(np.isnan(values), np.isnan(expected), err_msg=str(path))
        np.testing.assert_allclose(values, expected, rtol=1e-15, atol=5.0001e-7,
                                   equal_nan=True, err_msg=str(path))
        checked += 1
    # the corpus holds ~100 C3D files, ~95 of them with markers
    assert checked >= 0.9 * len(files) - 10


def _opensim_markers(opensim, path):
    table = opensim.TimeSeriesTableVec3(str(path))
    flat = table.flatten()
    matrix = flat.getMatrix()
    return (list(table.getColumnLabels()), np.array(table.getIndependentColumn()),
            matrix.to_numpy().copy())


@pytest.mark.filterwarnings("ignore::mocap.errors.MocapWarning")
def test_real_trc_written_again_keeps_frames_and_times_for_opensim(tmp_path, opensim):
    """TRC → TRC: OpenSim reads the toolkit's copy with the original's times (a trial
    starting at frame 23 / 0.23 s stays there), labels and values; gaps become NaN."""
    files = sorted(p for p in REALDATA.rglob("*") if p.suffix.lower() == ".trc") \
        if realdata_path().exists() else []
    assert files
    for path in files:
        trial = read(path)
        target = tmp_path / "copy.trc"
        write(trial, target, units=trial.units if trial.units in ("mm", "m") else "mm")
        numbers, times = read(target).time_base()
        np.testing.assert_array_equal(numbers, trial.frame_numbers)
        try:
            labels, original_times, original = _opensim_markers(opensim, path)
        except RuntimeError:
            continue                # OpenSim refuses this original (e.g. a short header)
        copy_labels, copy_times, copy = _opensim_markers(opensim, target)
        assert copy_labels == labels, path
        np.testing.assert_allclose(copy_times, original_times, atol=1e-9, err_msg=str(path))
        scale = 1000.0 if trial.units == "m" else 1.0       # copies of metre files stay m
        # the toolkit reads a marker at exactly (0, 0, 0) as a gap (how many exporters
        # write one); OpenSim takes it as a point at the origin
        triples = original.reshape(len(original), -1, 3)
        triples[(triples == 0).all(axis=2)] = np.nan
        np.testing.assert_allclose(copy * scale, original * scale, atol=5.0001e-7,
                                   rtol=1e-12, equal_nan=True, err_msg=str(path))


# ------------------------------------------------------------------ .mot for OpenSim models

def _custom_joint(name, parent, child, rotations, translations=(None, None, None)):
    """XML of an OpenSim CustomJoint: three rotations (coordinate, axis) then translations."""
    def axis(label, coordinate, vector):
        function = ('<LinearFunction name="function"><coefficients>1 0</coefficients>'
                    '</LinearFunction>' if coordinate else
                    '<Constant name="function"><value>0</value></Constant>')
        return (f'<TransformAxis name="{label}"><coordinates>{coordinate or ""}</coordinates>'
                f'<axis>{vector}</axis>{function}</TransformAxis>')

    coordinates = [c for c, _ in rotations if c] + [c for c in translations if c]
    frames = "".join(
        f'<PhysicalOffsetFrame name="{body}_offset"><socket_parent>{path}</socket_parent>'
        f'<translation>0 0 0</translation><orientation>0 0 0</orientation>'
        f'</PhysicalOffsetFrame>'
        for body, path in ((parent, "/ground" if parent == "ground" else f"/bodyset/{parent}"),
                           (child, f"/bodyset/{child}")))
    return (f'<CustomJoint name="{name}"><socket_parent_frame>{parent}_offset'
            f'</socket_parent_frame><socket_child_frame>{child}_offset</socket_child_frame>'
            '<coordinates>' + "".join(f'<Coordinate name="{c}"><range>-10 10</range>'
                                      f'</Coordinate>' for c in coordinates)
            + f'</coordinates><frames>{frames}</frames><SpatialTransform>'
            + "".join(axis(f"rotation{k + 1}", c, v) for k, (c, v) in enumerate(rotations))
            + "".join(axis(f"translation{k + 1}", c, v) for k, (c, v) in
                      enumerate(zip(translations, ("1 0 0", "0 1 0", "0 0 1"))))
            + '</SpatialTransform></CustomJoint>')


def gait2392_kinematics(folder):
    """The joints of gait2392_simbody.osim (opensim-models) that carry the pelvis, hip,
    knee and lumbar coordinates, as OpenSim CustomJoints: the rotation axes and their
    order as in the model (left hip −X, −Y), zero offsets. The full model is not in the
    corpus; OpenSim itself composes the rotations of this stand-in."""
    zxy = ("0 0 1", "1 0 0", "0 1 0")
    joints = [
        _custom_joint("ground_pelvis", "ground", "pelvis",
                      list(zip(("pelvis_tilt", "pelvis_list", "pelvis_rotation"), zxy)),
                      ("pelvis_tx", "pelvis_ty", "pelvis_tz")),
        _custom_joint("hip_r", "pelvis", "femur_r",
                      list(zip(("hip_flexion_r", "hip_adduction_r", "hip_rotation_r"), zxy))),
        _custom_joint("hip_l", "pelvis", "femur_l",
                      list(zip(("hip_flexion_l", "hip_adduction_l", "hip_rotation_l"),
                               ("0 0 1", "-1 0 0", "0 -1 0")))),
        _custom_joint("back", "pelvis", "torso",
                      list(zip(("lumbar_extension", "lumbar_bending", "lumbar_rotation"), zxy))),
    ]
    for side in "rl":
        for joint, parent, child, coordinate in (
                ("knee", f"femur_{side}", f"tibia_{side}", f"knee_angle_{side}"),
                ("ankle", f"tibia_{side}", f"talus_{side}", f"ankle_angle_{side}")):
            joints.append(_custom_joint(f"{joint}_{side}", parent, child,
                                        [(coordinate, "0 0 1"), (None, "1 0 0"),
                                         (None, "0 1 0")]))
    bodies = ["pelvis", "torso"] + [f"{b}_{s}" for s in "rl" for b in ("femur", "tibia", "talus")]
    document = ('<?xml version="1.0" encoding="UTF-8" ?><OpenSimDocument Version="40000">'
                '<Model name="gait2392_kinematics"><BodySet><objects>'
                + "".join(f'<Body name="{b}"><mass>1</mass><mass_center>0 0 0</mass_center>'
                          f'<inertia>1 1 1 0 0 0</inertia></Body>' for b in bodies)
                + '</objects></BodySet><JointSet><objects>' + "".join(joints)
                + '</objects></JointSet></Model></OpenSimDocument>')
    path = folder / "gait2392_kinematics.osim"
    path.write_text(document)
    return path


def _rotation(transform) -> np.ndarray:
    rotation = transform.R()
    return np.array([[rotation.get(i, j) for j in range(3)] for i in range(3)])


@pytest.mark.filterwarnings("ignore::mocap.errors.MocapWarning")
def test_mot_of_a_plugingait_trial_is_gait2392_coordinates_for_opensim(tmp_path, opensim):
    """mocap export --format mot --model gait2392 of a Plug-in Gait trial: OpenSim reads
    the file, every column is a coordinate of the model, and setting them moves the
    pelvis and thighs exactly as the toolkit's segment frames (OpenSim's own CustomJoint
    kinematics, compared with the toolkit's rotations in OpenSim's Y-up axes)."""
    from mocap.cli import main
    from mocap.io.lab import Z_TO_Y_UP
    from mocap.io.mot import read_mot
    from mocap.body.retarget import motion_to_lab, reduce_to_segments
    from mocap.io.motion import read_motion

    trial = realdata_path("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")
    out = tmp_path / "walk.mot"
    assert main(["export", str(trial), "-m", "plugingait-lower", "--format", "mot",
                 "--model", "gait2392", "-o", str(out)]) == 0
    table = opensim.TimeSeriesTable(str(out))
    labels = list(table.getColumnLabels())
    model = opensim.Model(str(gait2392_kinematics(tmp_path)))
    state = model.initSystem()
    coordinates = model.getCoordinateSet()
    assert labels and all(coordinates.contains(label) for label in labels), labels
    for needed in ("pelvis_tilt", "pelvis_list", "pelvis_rotation", "pelvis_tx", "pelvis_ty",
                   "pelvis_tz", "hip_flexion_r", "hip_adduction_r", "hip_rotation_r",
                   "knee_angle_r", "ankle_angle_r", "knee_angle_l"):
        assert needed in labels
    storage = read_mot(out)
    assert storage.labels == labels and table.getNumRows() == len(storage.times)
    column = table.getDependentColumn("knee_angle_r").to_numpy()
    np.testing.assert_allclose(storage.column("knee_angle_r"), column, atol=1e-12)
    assert storage.column("knee_angle_r").min() < -45        # flexion is negative in OpenSim

    body = reduce_to_segments(read_motion(trial, markerset="plugingait-lower"), partial=True)
    relative, root = motion_to_lab(body)
    turn = Z_TO_Y_UP
    bodies = model.getBodySet()
    pelvis, ground = bodies.get("pelvis"), model.getGround()
    for frame in range(0, len(storage.times), 37):
        for k, label in enumerate(labels):
            value = storage.values[frame, k]
            coordinate = coordinates.get(label)
            coordinate.setValue(state, value if label.endswith(("_tx", "_ty", "_tz"))
                                else np.radians(value), False)
        model.realizePosition(state)
        expected = turn @ relative[frame, body.names.index("pelvis")] @ turn.T
        np.testing.assert_allclose(_rotation(pelvis.findTransformBetween(state, ground)),
                                   expected, atol=1e-6)
        position = pelvis.findStationLocationInGround(state, opensim.Vec3(0, 0, 0))
        np.testing.assert_allclose([position.get(i) for i in range(3)],
                                   turn @ root[frame], atol=1e-6)
        for side in "rl":
            thigh = bodies.get(f"femur_{side}")
            expected = turn @ relative[frame, body.names.index(f"{side}_thigh")] @ turn.T
            np.testing.assert_allclose(_rotation(thigh.findTransformBetween(state, pelvis)),
                                       expected, atol=1e-6)


@pytest.mark.filterwarnings("ignore::mocap.errors.MocapWarning")
@pytest.mark.parametrize("model, pattern", [("gait2392", "gait2392*.osim"),
                                            ("rajagopal", "Rajagopal*.osim")])
def test_mot_columns_are_coordinates_of_the_real_model_files(tmp_path, opensim, model, pattern):
    """Where the corpus holds the OpenSim model files themselves (opensim-models'
    gait2392_simbody.osim, Rajagopal2015.osim), every column of the export is one of the
    model's coordinates, as OpenSim loads the model."""
    from mocap.cli import main

    realdata_path()
    files = sorted(REALDATA.rglob(pattern))
    if not files:
        pytest.skip(f"no {pattern} in the corpus (the kinematic stand-in above checks the "
                    f"joint definitions)")
    trial = realdata_path("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")
    out = tmp_path / "walk.mot"
    assert main(["export", str(trial), "-m", "plugingait-lower", "--format", "mot",
                 "--model", model, "-o", str(out)]) == 0
    labels = list(opensim.TimeSeriesTable(str(out)).getColumnLabels())
    osim = opensim.Model(str(files[0]))
    osim.initSystem()
    coordinates = osim.getCoordinateSet()
    assert [label for label in labels if not coordinates.contains(label)] == []
