"""Knee alignment device (KAD) and wand-rotation offsets of the static calibration.

No static in ../shared/realdata records a KAD with data (sub_labels.c3d has the
labels, empty; the biomechzoo statics' LKAX/RKAX are a virtual marker of
Vicon's, without KD1/KD2), so the device is built onto real statics with known
answers: a KAD whose axis is the thigh frame the static already gives must
change nothing; one turned about the thigh by alpha must turn the hip rotation
by alpha; one built on Vicon's own static knee axis must give back the thigh
rotation Vicon stored.  The shank rotation offset is checked against the
ShankRotation Vicon computed for 7 subjects' statics.
"""
from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest

from mocap.plugingait.calibration import (calibrate, kad_markers, kad_thigh_rotation,
                               kad_virtual_knee, static_markers)
from mocap.plugingait.clinical import plugingait_angles
from mocap.io import read
from mocap.markersets.model import MissingMarkerWarning
from mocap.plugingait.model import (SIDES, Subject, chord, clinical_angles, kinematics,
                              markers_from_trial, rotate_about, subject_from_trial, _unit)
from mocap.trial import Trial
from tests.conftest import realdata_path

ZOO = "biomechzoo_sample_study"
#: HC036A's subject file was re-calibrated after its static was saved (the walks
#: store other wand rotations than the static; see test_clinical.py).
STATICS = ["HC002D/Static/HC002D02.c3d", "HC030A/Static/HC030A01.c3d",
           "HC031A/Static/HC031A01.c3d", "HC032A/Static/HC032A01.c3d",
           "HC033A/Static/HC033A01.c3d", "HC038A/Static/HC038A01.c3d",
           "HC039A/Static/HC039A01.c3d"]


def _quiet(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return function(*args, **kwargs)


def with_kad(static: Trial, knee: dict, axis: dict, up: dict, arm: float = 0.1,
             drop_knee: bool = False) -> Trial:
    """The static with a KAD per side: its corner at ``knee[side]``, KAX along
    ``axis[side]`` (lateral), KD1 along ``up[side]`` and KD2 anterior (the
    order pyCGM2's KAD formula expects).  Arrays (frames, 3), metres."""
    labels, points = list(static.labels), static.points.copy()
    for side in SIDES:
        S = side.upper()
        u = _unit(axis[side])
        z = _unit(up[side] - np.sum(up[side] * u, axis=-1, keepdims=True) * u)
        anterior = np.cross(u, z) if side == "l" else np.cross(z, u)
        for name, direction in (("KAX", u), ("KD1", z), ("KD2", anterior)):
            values = knee[side] + arm * direction
            label = f"{S}{name}"
            if label in labels:                # biomechzoo's virtual LKAX/RKAX replaced
                points[:, labels.index(label)] = values
            else:
                labels.append(label)
                points = np.concatenate([points, values[:, None]], axis=1)
        if drop_knee:
            points[:, labels.index(f"{S}KNE")] = np.nan
    return Trial(labels, points, static.rate, static.units, static.path, static.format,
                 metadata=dict(static.metadata))


@pytest.fixture(scope="module")
def hc030a():
    static = read(realdata_path(ZOO, "HC030A/Static/HC030A01.c3d"))
    walk = read(realdata_path(ZOO, "HC030A/Straight/HC030A05.c3d"))
    given = subject_from_trial(walk)                 # thigh rotations -6 and -13 degrees
    today = _quiet(calibrate, static, given)
    markers = static_markers(static)
    kin = kinematics(markers, today)
    return static, walk, given, today, markers, kin


def _aligned(static, markers, kin, alpha: float = 0.0, **kwargs) -> Trial:
    """A KAD whose axis is the static's own knee flexion axis (KJC -> KNE),
    turned by ``alpha`` (radians) about the thigh's long axis through the corner."""
    axis, up = {}, {}
    for side in SIDES:
        S = side.upper()
        z = kin.frames[f"{side}_thigh"][..., 2]
        axis[side] = rotate_about(markers[f"{S}KNE"] - kin.centres[f"{side}_knee"], z, alpha)
        up[side] = z
    return with_kad(static, {s: markers[f"{s.upper()}KNE"] for s in SIDES}, axis, up,
                    **kwargs)


def test_a_kad_along_the_statics_own_knee_axis_changes_nothing(hc030a):
    static, walk, given, today, markers, kin = hc030a
    kad = _aligned(static, markers, kin, drop_knee=True)     # KNE replaced by the KAD
    devices, unusable = kad_markers(kad)
    assert set(devices) == {"l", "r"} and not unusable
    ours = _quiet(calibrate, kad, given)
    for side in SIDES:
        assert abs(ours.thigh_rotation[side] - today.thigh_rotation[side]) < 1e-10
    # the KAD also re-derives the shank rotation (Plug-in Gait does); with that
    # one given, the calibration without the KAD is the same to the last bits
    same = _quiet(calibrate, static, replace(given, shank_rotation=dict(ours.shank_rotation)))
    before = _quiet(plugingait_angles, walk, subject=same).values
    after = _quiet(plugingait_angles, walk, subject=ours).values
    assert np.isfinite(after).any(axis=(0, 2)).all()
    np.testing.assert_allclose(after, before, rtol=0, atol=1e-8)      # degrees
    for key in ("static_plantar_flexion", "static_rotation_offset"):
        for side in SIDES:
            assert abs(getattr(ours, key)[side] - getattr(same, key)[side]) < 1e-12


@pytest.mark.parametrize("alpha", [10.0, -10.0])
def test_b_a_kad_turned_about_the_thigh_turns_the_hip_rotation(hc030a, alpha):
    """Hand calculation: the KAD turned by alpha about the thigh's long axis
    (through its corner, the knee marker) turns the thigh's frame by about
    alpha about its z: the left hip's internal rotation falls by alpha (a turn
    about "up" is external on the left leg), the right's rises; flexion hardly
    moves.  Plug-in Gait sets the shank's rotation from the same axis (the
    tibial torsion apart), so the knee rotation stays and the foot's rotation
    relative to the tibia (ankle rotation) takes the turn instead."""
    static, walk, given, today, markers, kin = hc030a
    a = np.radians(alpha)
    base = _quiet(calibrate, _aligned(static, markers, kin), given)
    turned = _quiet(calibrate, _aligned(static, markers, kin, a), given)
    # in the static itself the thigh frame turns by alpha about its z
    kin_b, kin_t = kinematics(markers, base), kinematics(markers, turned)
    for side, sign in (("l", -1.0), ("r", 1.0)):
        hip = [clinical_angles(k.frames["pelvis"], k.frames[f"{side}_thigh"], "hip", side)
               for k in (kin_b, kin_t)]
        assert abs(np.median(hip[1][:, 2] - hip[0][:, 2]) - sign * alpha) < 0.3
    before = _quiet(plugingait_angles, walk, subject=base)
    after = _quiet(plugingait_angles, walk, subject=turned)
    for side, sign in (("l", -1.0), ("r", 1.0)):
        d = {j: np.nanmedian(after.segment(f"{side}_{j}") - before.segment(f"{side}_{j}"),
                             axis=0) for j in ("hip", "knee", "ankle")}
        assert abs(d["hip"][2] - sign * alpha) < 0.3, (side, d)
        assert abs(d["hip"][0]) < 2.0 and abs(d["hip"][1]) < 1.0, (side, d)
        assert abs(d["knee"][0]) < 2.5 and abs(d["knee"][2]) < 1.0, (side, d)
        assert abs(d["ankle"][2] + sign * alpha) < 0.5, (side, d)


def test_c_kad_corner_and_knee_centre_match_pycgm2s_formulas(hc030a):
    """pyCGM2's Kad decorator: n = unit((KD2 - KD1) x (KAX - KD1)), negated on
    the right; corner = centroid - n * sqrt(3) * mean(side / sqrt(2)) / 3; knee
    centre = chord((knee width + marker diameter) / 2, corner, HJC, KAX)."""
    static, walk, given, today, markers, kin = hc030a
    kad = _aligned(static, markers, kin, np.radians(7.0))
    found, _ = markers_from_trial(kad, ("LKAX", "LKD1", "LKD2", "RKAX", "RKD1", "RKD2"))
    for side in SIDES:
        S = side.upper()
        kax, kd1, kd2 = (found[f"{S}{n}"] for n in ("KAX", "KD1", "KD2"))
        sides = np.stack([np.linalg.norm(kax - kd1, axis=1), np.linalg.norm(kax - kd2, axis=1),
                          np.linalg.norm(kd1 - kd2, axis=1)]) / np.sqrt(2)
        n = _unit(np.cross(kd2 - kd1, kax - kd1)) * (1.0 if side == "l" else -1.0)
        centroid = 2.0 / 3.0 * ((kd1 + kax) / 2 - kd2) + kd2
        theirs = centroid - n * (np.sqrt(3) * sides.mean(axis=0) / 3.0)[:, None]
        hjc = kin.centres[f"{side}_hip"]
        corner = kad_virtual_knee(kax, kd1, kd2, hjc, markers[f"{S}ANK"])
        np.testing.assert_allclose(corner, theirs, rtol=0, atol=1e-12)     # metres
        delta = (today.knee_width[side] + today.marker_diameter) / 2.0
        kjc, _ = kad_thigh_rotation(markers[f"{S}THI"], hjc, corner, kax, delta, side)
        np.testing.assert_allclose(kjc, chord(kax, hjc, theirs, delta), rtol=0, atol=1e-12)
        # the knee centre sees the hip and the corner at a right angle, delta away
        np.testing.assert_allclose(np.linalg.norm(kjc - corner, axis=1), delta, atol=1e-12)


def test_kad_on_vicons_static_knee_axis_gives_back_vicons_thigh_rotation():
    """Vicon's static output places the femur (LFEO = knee centre, LFEP up the
    thigh) with the thigh rotation of the subject file; a KAD built on that
    knee axis at the knee marker must give that rotation back (sign and size,
    -13 to +13 degrees), with the stored one withheld."""
    checked = []
    for name in STATICS:
        static = read(realdata_path(ZOO, name))
        given = subject_from_trial(static)
        found, _ = markers_from_trial(static, tuple(f"{S}{n}" for S in "LR"
                                                    for n in ("FEO", "FEP", "KNE")))
        knee = {s: found[f"{s.upper()}KNE"] for s in SIDES}
        axis = {s: found[f"{s.upper()}KNE"] - found[f"{s.upper()}FEO"] for s in SIDES}
        up = {s: found[f"{s.upper()}FEP"] - found[f"{s.upper()}FEO"] for s in SIDES}
        kad = with_kad(static, knee, axis, up)
        ours = _quiet(calibrate, kad, replace(given, thigh_rotation={"l": 0.0, "r": 0.0}))
        for side in SIDES:
            error = np.degrees(ours.thigh_rotation[side] - given.thigh_rotation[side])
            checked.append((name, side, np.degrees(given.thigh_rotation[side]), error))
    assert max(abs(e) for *_, e in checked) < 0.5, checked
    assert max(abs(v) for _, _, v, _ in checked) > 10.0       # offsets of both signs, large
    assert min(v for _, _, v, _ in checked) < -10.0


def test_shank_rotation_from_the_tibial_torsion_matches_vicons():
    """Plug-in Gait's static puts the ankle axis at the tibial torsion from the
    knee axis and stores the TIB wand's angle to it as ShankRotation: ours,
    with the stored one withheld, matches it within 0.2 degrees (-12 to +12)."""
    errors = []
    for name in STATICS:
        static = read(realdata_path(ZOO, name))
        given = subject_from_trial(static)
        ours = _quiet(calibrate, static, replace(given, shank_rotation={"l": 0.0, "r": 0.0}))
        for side in SIDES:
            errors.append(np.degrees(ours.shank_rotation[side] - given.shank_rotation[side]))
    assert len(errors) == 14 and max(map(abs, errors)) < 0.2, errors


def test_empty_kad_labels_warn_once_and_calibrate_without_them():
    """sub_labels.c3d has Matt:LKAX … Matt:RKD2 with no sample at all."""
    static = read(realdata_path("c3dorg_via_c3dio/sample_04/sub_labels.c3d"))
    devices, unusable = kad_markers(static)
    assert devices == {} and sorted(unusable) == sorted(
        f"{S}{n}" for S in "LR" for n in ("KAX", "KD1", "KD2"))
    subject = Subject(marker_diameter=0.014, knee_width={"l": 0.1, "r": 0.1},
                      ankle_width={"l": 0.07, "r": 0.07})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ours = calibrate(static, subject)
        angles = plugingait_angles(static, subject=ours)
    kad = [w for w in caught if "knee alignment device" in str(w.message)]
    assert len(kad) == 1 and issubclass(kad[0].category, MissingMarkerWarning)
    assert "LKD1" in str(kad[0].message)
    assert all(ours.thigh_rotation[s] == 0.0 for s in SIDES)
    for segment in ("l_hip", "l_knee", "r_hip", "r_knee", "l_ankle", "r_ankle"):
        assert np.isfinite(angles.segment(segment)).all(axis=1).mean() > 0.3, segment


def test_mocap_angles_uses_a_kad_static_automatically(hc030a, tmp_path, capsys):
    """End to end: a C3D static whose knees carry only a KAD (KNE removed),
    turned 10 degrees about the thigh: ``mocap angles --static`` uses it
    without being asked, says nothing about it, and gives the library's angles;
    the left hip's rotation is 10 degrees lower than with the plain static."""
    from mocap.cli import main
    from mocap.io import write
    from mocap.io.angles_csv import read_angles_csv

    static, walk, given, today, markers, kin = hc030a
    path = tmp_path / "kad_static.c3d"
    write(_aligned(static, markers, kin, np.radians(10.0), drop_knee=True), path)
    outputs = {}
    for name, standing in (("kad", path), ("plain", realdata_path(ZOO, "HC030A/Static/HC030A01.c3d"))):
        outputs[name] = tmp_path / f"{name}.csv"
        status = main(["angles", str(realdata_path(ZOO, "HC030A/Straight/HC030A05.c3d")),
                       "-m", "plugingait-lower", "--static", str(standing),
                       "-o", str(outputs[name])])
        err = capsys.readouterr().err
        assert status == 0, err
        assert "knee alignment" not in err and "KNE" not in err, err
    kad, plain = (read_angles_csv(outputs[n]) for n in ("kad", "plain"))
    library = _quiet(plugingait_angles, walk, static=read(path), flat_foot="auto")
    np.testing.assert_allclose(kad.values, library.values, atol=1e-5)
    shift = np.nanmedian(kad.segment("l_hip")[:, 2] - plain.segment("l_hip")[:, 2])
    assert abs(shift + 10.0) < 0.5, shift
