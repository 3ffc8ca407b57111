"""The OpenSim hand-off of a walk with force plates (issue 26), run through OpenSim 4.6.

A real Plug-in Gait walk (biomechzoo HC030A05, two plates) and its static give, through
the command line, the TRC (``convert --up y``), the coordinates ``.mot`` (``export --model
gait2392 --static``), the ground-reaction ``.mot`` and its ExternalLoads XML (``forces``).
OpenSim's InverseKinematicsTool then fits a leg model to the TRC, and its
InverseDynamicsTool applies the external loads to the IK result. The corpus holds no
``.osim`` file, so the model is built here from the static: gait2392's topology (a free
pelvis carrying head, arms and trunk, ball hips, pin knees and ankles, bodies ``calcn_r``
and ``calcn_l``), Plug-in Gait's joint centres, the static's markers, and Dempster's
segment masses for the subject's recorded 45.8 kg.
"""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocap.cli import main
from mocap.io.mot import read_mot
from tests.conftest import realdata_path, require_module

SUBJECT = ("biomechzoo_sample_study", "HC030A")
#: IK and ID window (s on the trial's clock, which starts at 2.85 s): right stance on
#: plate 2 and left stance on plate 1 both fall in it.
WINDOW = (3.0, 4.3)


@pytest.fixture(scope="module")
def opensim():
    module = require_module("opensim")
    module.Logger.setLevelString("error")
    module.Logger.removeFileSink()          # no opensim.log in the working directory
    return module


@pytest.fixture(scope="module")
def walk():
    return (realdata_path(*SUBJECT, "Straight", "HC030A05.c3d"),
            realdata_path(*SUBJECT, "Static", "HC030A01.c3d"))


# ------------------------------------------------------------------ the files, mocap only

def test_ground_reaction_mot_is_per_foot_y_up_on_the_trials_clock(tmp_path, walk):
    """forces -o grf.mot: each plate's reaction under the foot standing on it, turned to
    Y up (the vertical force is +Y), on the trial's clock like its TRC; the sum of both
    feet is the plates' total, and the XML names calcn_r / calcn_l and the file."""
    from mocap.io import read
    from mocap.io.c3d.forceplates import plate_forces, total_forces

    trial_path, _ = walk
    grf, xml = tmp_path / "grf.mot", tmp_path / "loads.xml"
    assert main(["forces", str(trial_path), "-o", str(grf), "--external-loads",
                 str(xml)]) == 0
    storage = read_mot(grf)
    trial = read(trial_path)
    assert storage.times[0] == pytest.approx(trial.time_base()[1][0]) == 2.85
    np.testing.assert_allclose(np.diff(storage.times), 1 / trial.analog_rate, atol=1e-9)
    plates = plate_forces(trial)
    # each plate's force while loaded (under 20 N it is written 0)
    expected = sum(np.where(np.isfinite(p.cop).all(axis=1)[:, None], p.force, 0.0)
                   for p in plates)
    vertical = storage.column("r_ground_force_vy") + storage.column("l_ground_force_vy")
    np.testing.assert_allclose(vertical, expected[:, 2], atol=1e-6)
    lateral = storage.column("r_ground_force_vz") + storage.column("l_ground_force_vz")
    np.testing.assert_allclose(lateral, -expected[:, 1], atol=1e-6)
    assert np.abs(total_forces(plates).force[:, 2] - expected[:, 2]).max() < 25
    for side in "rl":                   # each foot loaded once, 0.6 s, 400-520 N at peak
        fy = storage.column(f"{side}_ground_force_vy")
        assert 0.5 < (fy > 20).sum() / trial.analog_rate < 0.75
        assert 400 < fy.max() < 520
    # the right foot's point lies under the right heel-toe line, the left's under the left
    for side, heel, toe in (("r", "RHEE", "RTOE"), ("l", "LHEE", "LTOE")):
        frames = np.flatnonzero(storage.column(f"{side}_ground_force_vy")[::10] > 200)
        point = np.stack([storage.column(f"{side}_ground_force_p{a}")[::10][frames]
                          for a in "xz"], axis=1)
        foot = 0.5 * (trial.marker(heel) + trial.marker(toe))[frames]
        np.testing.assert_array_less(np.linalg.norm(point - foot[:, [0, 1]] * [1, -1],
                                                    axis=1), 0.15)
    text = xml.read_text()
    assert "<applied_to_body>calcn_r</applied_to_body>" in text
    assert "<datafile>grf.mot</datafile>" in text


def test_the_set_shares_one_clock_and_the_static_calibrates_the_coordinates(tmp_path, walk,
                                                                            capsys):
    """TRC, coordinates .mot and GRF .mot all start at the C3D's first frame (2.85 s);
    with --static the hip, knee and ankle columns are Plug-in Gait's calibrated angles
    (Vicon's own stored angles to 0.5°), without it a one-line warning."""
    from mocap.io import read

    trial_path, static = walk
    trc, plain, calibrated, grf = (tmp_path / n for n in ("w.trc", "a.mot", "b.mot", "g.mot"))
    assert main(["convert", str(trial_path), str(trc), "--up", "y"]) == 0
    assert main(["export", str(trial_path), "-m", "plugingait-lower", "--model", "gait2392",
                 "-o", str(plain)]) == 0
    warned = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(warned) == 1 and "--static" in warned[0]
    assert main(["export", str(trial_path), "-m", "plugingait-lower", "--model", "gait2392",
                 "--static", str(static), "-o", str(calibrated)]) == 0
    assert "warning" not in capsys.readouterr().err
    assert main(["forces", str(trial_path), "-o", str(grf)]) == 0
    trial = read(trial_path)
    times = trial.time_base()[1]
    assert read(trc).time_base()[1][0] == pytest.approx(times[0])
    for path in (plain, calibrated):
        np.testing.assert_allclose(read_mot(path).times, times, atol=1e-9)
    assert read_mot(grf).times[0] == pytest.approx(times[0])
    generic = tmp_path / "generic.mot"            # the generic joint-angle .mot
    assert main(["export", str(trial_path), "-m", "plugingait-lower",
                 "-o", str(generic)]) == 0
    np.testing.assert_allclose(read_mot(generic).times, times, atol=1e-9)
    # Vicon's angles stored in the C3D: the calibrated export matches them, the plain one
    # is off by degrees in hip adduction and ankle flexion
    labels = list(trial.modelled["labels"])
    vicon = trial.modelled["values"]
    for column, label, plane, sign in (("hip_adduction_r", "RHipAngles", 1, 1),
                                       ("hip_flexion_l", "LHipAngles", 0, 1),
                                       ("knee_angle_r", "RKneeAngles", 0, -1),
                                       ("ankle_angle_r", "RAnkleAngles", 0, 1)):
        expected = sign * vicon[:, labels.index(label), plane]
        assert np.nanmax(np.abs(read_mot(calibrated).column(column) - expected)) < 0.5
    off = np.nanmean(np.abs(read_mot(plain).column("hip_adduction_r")
                            - vicon[:, labels.index("RHipAngles"), 1]))
    assert off > 3


def test_external_loads_and_static_misuse_is_one_line(tmp_path, walk, capsys):
    trial_path, static = walk
    assert main(["forces", str(trial_path), "-o", str(tmp_path / "g.csv"),
                 "--external-loads", str(tmp_path / "l.xml")]) == 2
    assert main(["export", str(trial_path), "-m", "plugingait-lower", "--format", "mot",
                 "--static", str(static), "-o", str(tmp_path / "a.mot")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "--external-loads" in err[0] and "--static" in err[1]
    assert not list(tmp_path.iterdir())


def test_without_foot_markers_the_plates_are_written_one_by_one(tmp_path, walk):
    """No heel or toe markers: one force per plate (plate1_, plate2_ columns, the same
    numbers as the plates), and no ExternalLoads file (no body to apply them to)."""
    from mocap.errors import MocapError
    from mocap.io import read
    from mocap.io.c3d.forceplates import plate_forces
    from mocap.io.external_loads import (foot_reactions, write_external_loads,
                                         write_grf_mot)

    trial = read(walk[0])
    feetless = trial.select([label for label in trial.labels
                             if label not in ("RHEE", "RTOE", "LHEE", "LTOE")])
    plates = plate_forces(trial)
    parts, bodies = foot_reactions(feetless, plates)
    assert list(parts) == ["plate1_", "plate2_"] and bodies == {}
    write_grf_mot(tmp_path / "g.mot", parts, start_time=2.85)
    storage = read_mot(tmp_path / "g.mot")
    loaded = np.isfinite(plates[1].cop).all(axis=1)
    np.testing.assert_allclose(storage.column("plate2_ground_force_vy")[loaded],
                               plates[1].force[loaded, 2], atol=1e-6)
    np.testing.assert_allclose(storage.column("plate2_ground_force_pz")[loaded],
                               -plates[1].cop[loaded, 1], atol=1e-6)
    with pytest.raises(MocapError, match="not assigned to feet"):
        write_external_loads(tmp_path / "l.xml", tmp_path / "g.mot", bodies)
    assert not (tmp_path / "l.xml").exists()


# ------------------------------------------------------------------ OpenSim IK and ID

#: Dempster's segment mass fractions and centre of mass (fraction from the proximal
#: joint to the distal point); the pelvis carries head, arms and trunk (0.678).
SEGMENTS = {"femur": (0.100, 0.433), "tibia": (0.0465, 0.433), "calcn": (0.0145, 0.5)}
MARKERS = {"pelvis": ("LASI", "RASI", "SACR"), "femur": ("THI", "KNE"),
           "tibia": ("TIB", "ANK"), "calcn": ("HEE", "TOE")}


def _numbers(values) -> str:
    return " ".join(f"{float(v):.9g}" for v in np.ravel(values))


def _offset(name, parent, position, rotation):
    angles = Rotation.from_matrix(rotation).as_euler("XYZ")
    return (f'<PhysicalOffsetFrame name="{name}"><socket_parent>{parent}</socket_parent>'
            f'<translation>{_numbers(position)}</translation>'
            f'<orientation>{_numbers(angles)}</orientation></PhysicalOffsetFrame>')


def _joint(name, parent, child, at_parent, at_child, rotation, coordinates, free=False):
    """A CustomJoint (rotations about Z, X, Y of a joint frame turned by ``rotation``)
    whose coordinates are zero in the static pose."""
    axes = ("0 0 1", "1 0 0", "0 1 0")
    def transform(label, coordinate, axis):
        function = ('<LinearFunction name="function"><coefficients>1 0</coefficients>'
                    '</LinearFunction>' if coordinate else
                    '<Constant name="function"><value>0</value></Constant>')
        return (f'<TransformAxis name="{label}"><coordinates>{coordinate or ""}</coordinates>'
                f'<axis>{axis}</axis>{function}</TransformAxis>')
    rotations = list(coordinates[:3]) + [None] * (3 - len(coordinates[:3]))
    translations = list(coordinates[3:]) if free else [None] * 3
    used = [c for c in rotations + translations if c]
    parent_path = "/ground" if parent == "ground" else f"/bodyset/{parent}"
    return (f'<CustomJoint name="{name}"><socket_parent_frame>{name}_p</socket_parent_frame>'
            f'<socket_child_frame>{name}_c</socket_child_frame><coordinates>'
            + "".join(f'<Coordinate name="{c}"><range>-10 10</range></Coordinate>'
                      for c in used)
            + "</coordinates><frames>"
            + _offset(f"{name}_p", parent_path, at_parent, rotation)
            + _offset(f"{name}_c", f"/bodyset/{child}", at_child, rotation)
            + "</frames><SpatialTransform>"
            + "".join(transform(f"rotation{k + 1}", c, a)
                      for k, (c, a) in enumerate(zip(rotations, axes)))
            + "".join(transform(f"translation{k + 1}", c, a)
                      for k, (c, a) in enumerate(zip(translations, ("1 0 0", "0 1 0",
                                                                   "0 0 1"))))
            + "</SpatialTransform></CustomJoint>")


def leg_model(folder, static_path, walk_path, mass):
    """An OpenSim model of the subject standing as in the static (every coordinate 0 but
    the pelvis's): bodies with ground-parallel axes at Plug-in Gait's joint centres, the
    static's mean markers fixed on them, gait2392's coordinate names."""
    from mocap.io import read
    from mocap.io.lab import Z_TO_Y_UP
    from mocap.plugingait.clinical import prepare_subject
    from mocap.plugingait.model import MARKERS as PIG, kinematics, markers_from_trial

    static, walk = read(static_path), read(walk_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        subject = prepare_subject(walk, static=static)
    markers, _ = markers_from_trial(static, PIG)
    mean = {k: np.nanmean(v, axis=0)[None] for k, v in markers.items()}       # m, Z up
    kin = kinematics(mean, subject)

    def y_up(point):                                   # the Z-up lab -> Y up, metres
        return Z_TO_Y_UP @ np.asarray(point, float).reshape(3)

    def axes(frame):                                   # Plug-in Gait axes -> OpenSim's
        return Z_TO_Y_UP @ np.asarray(frame).reshape(3, 3) @ Z_TO_Y_UP.T

    pelvis = y_up(kin.centres["pelvis"])
    origin = {"pelvis": pelvis}
    bodies = [("pelvis", 0.678 * mass, pelvis + [0, 0.25, 0])]    # trunk above the pelvis
    joints = [_joint("ground_pelvis", "ground", "pelvis", pelvis, [0, 0, 0], np.eye(3),
                     ("pelvis_tilt", "pelvis_list", "pelvis_rotation", "pelvis_tx",
                      "pelvis_ty", "pelvis_tz"), free=True)]
    for s in "rl":
        S = s.upper()
        hip, knee, ankle = (y_up(kin.centres[f"{s}_{j}"]) for j in ("hip", "knee", "ankle"))
        toe = y_up(mean[f"{S}TOE"])
        for body, start, end in (("femur", hip, knee), ("tibia", knee, ankle),
                                 ("calcn", ankle, toe)):
            fraction, com = SEGMENTS[body]
            origin[f"{body}_{s}"] = start
            bodies.append((f"{body}_{s}", fraction * mass, start + com * (end - start)))
        joints += [
            _joint(f"hip_{s}", "pelvis", f"femur_{s}", hip - pelvis, [0, 0, 0],
                   axes(kin.frames["pelvis"]),
                   (f"hip_flexion_{s}", f"hip_adduction_{s}", f"hip_rotation_{s}")),
            _joint(f"knee_{s}", f"femur_{s}", f"tibia_{s}", knee - hip, [0, 0, 0],
                   axes(kin.frames[f"{s}_thigh"]), (f"knee_angle_{s}",)),
            _joint(f"ankle_{s}", f"tibia_{s}", f"calcn_{s}", ankle - knee, [0, 0, 0],
                   axes(kin.frames[f"{s}_shank"]), (f"ankle_angle_{s}",))]
    body_xml = "".join(
        f'<Body name="{name}"><mass>{m:.9g}</mass><mass_center>'
        f'{_numbers(com - origin[name])}</mass_center>'
        f'<inertia>{_numbers(np.array([0.02, 0.005, 0.02]) * m)} 0 0 0</inertia></Body>'
        for name, m, com in bodies)
    marker_xml = ""
    for name in origin:
        segment = name.split("_")[0]
        side = name[-1].upper() if "_" in name else ""
        for label in MARKERS[segment]:
            label = side + label
            local = y_up(mean[label]) - origin[name]
            marker_xml += (f'<Marker name="{label}"><socket_parent_frame>/bodyset/{name}'
                           f'</socket_parent_frame><location>{_numbers(local)}'
                           f'</location><fixed>true</fixed></Marker>')
    path = folder / "leg.osim"
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8" ?><OpenSimDocument Version="40000">'
        '<Model name="leg"><gravity>0 -9.8066 0</gravity><BodySet><objects>' + body_xml
        + "</objects></BodySet><JointSet><objects>" + "".join(joints)
        + "</objects></JointSet><MarkerSet><objects>" + marker_xml
        + "</objects></MarkerSet></Model></OpenSimDocument>")
    return path


def test_opensim_ik_and_id_run_on_the_handed_off_files(tmp_path, walk, opensim):
    """IK on the TRC, ID with the external loads on the IK result: both run on the
    trial's clock, the markers fit to a few centimetres, the pelvis residual force in
    single stance is a small fraction of body weight (without the loads it is the whole
    weight), and the joint moments are finite and of walking size."""
    trial_path, static = walk
    mass = 45.8                                         # PROCESSING:BODYMASS of both files
    trc, grf, xml = tmp_path / "walk.trc", tmp_path / "grf.mot", tmp_path / "loads.xml"
    assert main(["convert", str(trial_path), str(trc), "--up", "y"]) == 0
    assert main(["forces", str(trial_path), "-o", str(grf), "--external-loads",
                 str(xml)]) == 0
    model_path = leg_model(tmp_path, static, trial_path, mass)

    model = opensim.Model(str(model_path))
    ik = opensim.InverseKinematicsTool()
    ik.setModel(model)
    ik.setMarkerDataFileName(str(trc))
    ik.setStartTime(WINDOW[0])
    ik.setEndTime(WINDOW[1])
    ik.setOutputMotionFileName(str(tmp_path / "ik.mot"))
    ik.set_report_errors(True)
    ik.setResultsDir(str(tmp_path))
    tasks = ik.getIKTaskSet()
    for k in range(model.getMarkerSet().getSize()):
        task = opensim.IKMarkerTask()
        task.setName(model.getMarkerSet().get(k).getName())
        task.setWeight(1.0)
        tasks.cloneAndAppend(task)
    assert ik.run()
    motion = read_mot(tmp_path / "ik.mot")
    assert motion.times[0] == pytest.approx(WINDOW[0]) and \
        motion.times[-1] == pytest.approx(WINDOW[1])
    errors = read_mot(tmp_path / "_ik_marker_errors.sto", rotational=set())
    assert np.max(errors.column("marker_error_RMS")) < 0.03          # metres
    knee = motion.column("knee_angle_r")
    assert np.ptp(knee) > 40                     # a walking knee swings through > 40°

    def inverse_dynamics(loads, name):
        tool = opensim.InverseDynamicsTool()
        body = opensim.Model(str(model_path))       # referenced until the tool has run
        tool.setModel(body)
        tool.setCoordinatesFileName(str(tmp_path / "ik.mot"))
        tool.setLowpassCutoffFrequency(6.0)
        if loads:
            tool.setExternalLoadsFileName(str(loads))
        tool.setStartTime(WINDOW[0])
        tool.setEndTime(WINDOW[1])
        tool.setResultsDir(str(tmp_path))
        tool.setOutputGenForceFileName(name)
        assert tool.run()
        return read_mot(tmp_path / name)

    dynamics = inverse_dynamics(xml, "id.sto")
    unloaded = inverse_dynamics(None, "id_free.sto")
    assert dynamics.times[0] == pytest.approx(WINDOW[0])
    assert dynamics.times[-1] == pytest.approx(WINDOW[1])
    assert np.isfinite(dynamics.values).all()
    weight = mass * 9.8066
    forces = read_mot(grf)
    right = np.interp(dynamics.times, forces.times, forces.column("r_ground_force_vy"))
    left = np.interp(dynamics.times, forces.times, forces.column("l_ground_force_vy"))
    single = (right > 20) != (left > 20)                 # one foot on a plate, other off
    assert single.sum() > 40
    residual = np.abs(dynamics.column("pelvis_ty_force")[single])
    free = np.abs(unloaded.column("pelvis_ty_force")[single])
    assert np.median(free) > 0.8 * weight                # no loads: the pelvis holds it all
    assert np.median(residual) < 0.1 * weight          # 3 % BW (HC030A05, 2026)
    for axis in "xz":                                     # horizontal: 10 % and 4 % BW
        assert np.median(np.abs(dynamics.column(f"pelvis_t{axis}_force")[single])) \
            < 0.15 * weight
    for side in "rl":
        for joint in ("hip_flexion", "knee_angle", "ankle_angle"):
            moment = dynamics.column(f"{joint}_{side}_moment")
            assert 5 < np.abs(moment).max() < 3.0 * mass, (joint, side)
        # push-off: the plantar flexors' moment (negative in gait2392's sign) peaks at
        # 1-1.5 N·m/kg in walking (here 1.2 and 1.3): the forces act at the right foot
        ankle = dynamics.column(f"ankle_angle_{side}_moment")
        assert -2.0 * mass < ankle.min() < -0.8 * mass and ankle.max() < 0.3 * mass
