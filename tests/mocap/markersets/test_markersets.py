"""Marker sets: TOML loading and validation, presets, virtual markers."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocap.errors import MocapError
from mocap.markersets import (frame_from_markers, hip_joint_centre_offset, load_markerset,
                              pelvis_frame, preset_names)
from mocap.markersets.model import MissingMarkerWarning
from mocap.trial import Trial

GOOD = """
name = "legs"
[[segment]]
name = "pelvis"
markers = ["RASI", "LASI", "SACR"]
[[segment]]
name = "l_thigh"
parent = "pelvis"
markers = ["LHJC", "LKNE", "LTHI"]
[[virtual]]
name = "LHJC"
type = "hip_joint_centre"
method = "bell"
side = "left"
markers = ["RASI", "LASI", "SACR"]
"""


def write(tmp_path, text, name="set.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_load_file_and_properties(tmp_path):
    ms = load_markerset(write(tmp_path, GOOD))
    assert ms.name == "legs"
    assert ms.segment_names == ["pelvis", "l_thigh"]
    assert ms.parent_index == [-1, 0]
    assert ms.segments[1].markers == ("LHJC", "LKNE", "LTHI")
    assert ms.virtual_names == ["LHJC"]
    assert ms.missing_markers(["RASI", "LASI", "SACR", "LKNE", "LTHI"]) == []
    assert ms.missing_markers(["RASI", "LKNE"]) == ["LASI", "LTHI", "SACR"]


def test_presets_ship_and_load():
    assert {"plugingait-lower", "synthetic15"} <= set(preset_names())
    pig = load_markerset("plugingait-lower")
    assert pig.segment_names == ["pelvis", "l_thigh", "l_shank", "l_foot",
                                 "r_thigh", "r_shank", "r_foot"]
    assert pig.parent_index == [-1, 0, 1, 2, 0, 4, 5]
    assert len(load_markerset("synthetic15").segments) == 15
    with pytest.raises(MocapError, match="no marker set preset 'nope'.*plugingait-lower"):
        load_markerset("nope")
    with pytest.raises(MocapError, match="not found"):
        load_markerset("missing/file.toml")
    assert load_markerset("plugingait-lower.toml").name == "plugingait-lower"


@pytest.mark.parametrize("text, problem", [
    ("[[segment]]\nname='a'\nmarkers=['A','B']\n", "has 2 markers; exactly 3"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C','D']\n", "has 4 markers"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','A']\n", "uses a marker twice"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\n[[segment]]\nname='a'\n"
     "markers=['D','E','F']\n", "duplicate segment name 'a'"),
    ("[[segment]]\nname='a'\nparent='ghost'\nmarkers=['A','B','C']\n",
     "unknown parent 'ghost'"),
    ("[[segment]]\nname='a'\nparent='b'\nmarkers=['A','B','C']\n[[segment]]\nname='b'\n"
     "parent='a'\nmarkers=['D','E','F']\n", "cycle: a -> b -> a"),
    ("[[segment]]\nname='a'\nparent='a'\nmarkers=['A','B','C']\n", "its own parent"),
    ("name='x'\n", "no \\[\\[segment\\]\\]"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\naxes=['e1','e3','e2']\n",
     "left-handed"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\naxes=['e1','e1','e2']\n", "'axes'"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\ncolour='red'\n", "unknown key"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\n[[virtual]]\nname='V'\ntype='midpoint'\n"
     "markers=['A']\n", "2 or more"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\n[[virtual]]\nname='V'\ntype='blend'\n"
     "markers=['A','B']\n", "'type' must be one of"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\n[[virtual]]\nname='V'\ntype='midpoint'\n"
     "markers=['A','W']\n[[virtual]]\nname='W'\ntype='midpoint'\nmarkers=['V','B']\n",
     "cycle: V -> W -> V"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\n[[virtual]]\nname='V'\ntype='midpoint'\n"
     "markers=['A','B']\n[[virtual]]\nname='V'\ntype='midpoint'\nmarkers=['A','C']\n",
     "duplicate virtual marker name 'V'"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\n[[virtual]]\nname='V'\ntype='offset'\n"
     "markers=['A','B','C']\noffset=[1,2]\n", "'offset' must be 3 numbers"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\n[[virtual]]\nname='H'\n"
     "type='hip_joint_centre'\nside='left'\nmarkers=['A','B','C']\n",
     "davis regression needs 'leg_length'"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\n[[virtual]]\nname='H'\n"
     "type='hip_joint_centre'\nside='left'\nleg_length=870\nmarkers=['A','B','C']\n",
     "millimetres"),
    ("[[segment]]\nname='a'\nmarkers=['A','B','C']\n[[virtual]]\nname='H'\n"
     "type='hip_joint_centre'\nside='up'\nmethod='bell'\nmarkers=['A','B','C']\n",
     "'side'"),
    ("[[segment]\nname='a'\n", "not valid TOML"),
])
def test_invalid_sets_name_the_file_and_problem(tmp_path, text, problem):
    path = write(tmp_path, text, "broken.toml")
    with pytest.raises(MocapError, match=problem) as error:
        load_markerset(path)
    assert error.value.path == str(path)
    assert str(path) in str(error.value)


def test_segments_are_ordered_parents_first(tmp_path):
    text = ("[[segment]]\nname='shank'\nparent='thigh'\nmarkers=['D','E','F']\n"
            "[[segment]]\nname='thigh'\nmarkers=['A','B','C']\n")
    ms = load_markerset(write(tmp_path, text))
    assert ms.segment_names == ["thigh", "shank"] and ms.parent_index == [-1, 0]


def test_missing_markers_error_lists_all(tmp_path):
    ms = load_markerset("plugingait-lower")
    trial = Trial(["RASI", "LASI", "LKNE"], np.zeros((3, 3, 3)), 100.0, path="trial.c3d")
    with pytest.raises(MocapError) as error:
        ms.apply_virtual(trial)
    text = str(error.value)
    assert text.startswith("trial.c3d: marker set 'plugingait-lower' needs")
    # no SACR: the PSIS fallback's inputs are what is missing
    for name in ("LPSI", "RPSI", "LTHI", "LTIB", "LANK", "LHEE", "LTOE", "RKNE"):
        assert name in text
    assert "SACR" not in text.split("lacks:")[1].split("(")[0]


def test_midpoint_fallback_and_subject_prefix(tmp_path):
    text = ("[[segment]]\nname='a'\nmarkers=['SACR','B','C']\n[[virtual]]\nname='SACR'\n"
            "type='midpoint'\nmarkers=['RPSI','LPSI']\nfallback=true\n")
    ms = load_markerset(write(tmp_path, text))
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(4, 4, 3))
    psis = Trial(["S:RPSI", "S:LPSI", "S:B", "S:C"], pts, 100.0)
    assert ms.used_labels(psis.labels + ["S:EXTRA"]) == ["S:RPSI", "S:LPSI", "S:B", "S:C"]
    out = ms.apply_virtual(psis)
    assert out.labels[-1] == "SACR"
    np.testing.assert_allclose(out.marker("SACR"), (pts[:, 0] + pts[:, 1]) / 2)
    # a recorded SACR wins over the fallback
    sacrum = Trial(["SACR", "B", "C"], pts[:, :3], 100.0)
    assert ms.missing_markers(sacrum.labels) == []
    # the fallback's inputs are kept too, in case the recorded SACR has no data
    assert ms.used_labels(["RPSI", "LPSI"] + sacrum.labels) == ["RPSI", "LPSI", "SACR", "B", "C"]
    out = ms.apply_virtual(sacrum)
    assert out.labels == ["SACR", "B", "C"]
    np.testing.assert_array_equal(out.points, pts[:, :3])
    # keyed on data, not on the label: an empty SACR falls back, with a warning
    empty = pts.copy()
    empty[:, 2] = np.nan
    both = Trial(["RPSI", "LPSI", "SACR", "B", "C"], np.concatenate(
        [pts[:, :2], empty[:, 2:3], pts[:, 1:3]], axis=1), 100.0)
    with pytest.warns(MissingMarkerWarning, match="SACR has no data"):
        out = ms.apply_virtual(both)
    np.testing.assert_allclose(out.marker("SACR"), (pts[:, 0] + pts[:, 1]) / 2)


def test_offset_marker_rides_with_its_frame(tmp_path):
    text = ("[[segment]]\nname='a'\nmarkers=['O','A','P']\n[[virtual]]\nname='V'\n"
            "type='offset'\nmarkers=['O','A','P']\noffset=[0.01, 0.02, 0.03]\n")
    ms = load_markerset(write(tmp_path, text))
    rot = Rotation.random(5, random_state=2).as_matrix()
    origin = np.random.default_rng(1).normal(size=(5, 3))
    pts = np.stack([origin, origin + 0.2 * rot[..., 0],
                    origin + 0.1 * rot[..., 0] + 0.3 * rot[..., 1]], axis=1)
    pts[2, 1] = np.nan
    out = ms.apply_virtual(Trial(["O", "A", "P"], pts, 100.0))
    expected = origin + rot @ np.array([0.01, 0.02, 0.03])
    expected[2] = np.nan
    np.testing.assert_allclose(out.marker("V"), expected, atol=1e-12)


def test_pelvis_frame_and_hip_regressions_known_values():
    # a pelvis facing +x in a Z-up lab: ASIS 0.24 m apart, sacrum 0.16 m behind
    rasi, lasi, sacr = np.array([[0.0, -0.12, 1.0]]), np.array([[0.0, 0.12, 1.0]]), \
        np.array([[-0.16, 0.0, 1.0]])
    rot, origin = pelvis_frame(rasi, lasi, sacr)
    np.testing.assert_allclose(rot[0], np.eye(3), atol=1e-15)
    np.testing.assert_allclose(origin[0], [0, 0, 1.0])
    # Bell 1990: 19 % posterior, 36 % lateral, 30 % inferior of pelvis width
    np.testing.assert_allclose(hip_joint_centre_offset("bell", "right", 0.24),
                               [-0.0456, -0.0864, -0.072])
    # Harrington 2007 (mm): x = -0.24 PD - 9.9, y = 0.33 PW + 7.3, z = -0.30 PW - 10.9
    np.testing.assert_allclose(hip_joint_centre_offset("harrington", "left", 0.24, 0.16),
                               [-0.0483, 0.0865, -0.0829], atol=1e-12)
    # Davis 1991 / Plug-in Gait, leg length 0.9 m, 14 mm markers, by hand:
    # C = 88.2, AT = 67.36, r = 7
    c, at, r = 0.115 * 900 - 15.3, 0.1288 * 900 - 48.56, 7.0
    # theta = 0.5, beta = 0.314 rad as Plug-in Gait stores them (single precision)
    theta, beta = 0.500000178813934, 0.314000427722931
    x = c * np.cos(theta) * np.sin(beta) - (at + r) * np.cos(beta)
    y = -(c * np.sin(theta) - 120.0)
    z = -c * np.cos(theta) * np.cos(beta) - (at + r) * np.sin(beta)
    davis = hip_joint_centre_offset("davis", "left", 0.24, leg_length=0.9,
                                    marker_diameter=0.014)
    np.testing.assert_allclose(davis * 1000, [x, y, z])
    assert -0.06 < davis[0] < -0.03 and 0.07 < davis[1] < 0.09 and -0.11 < davis[2] < -0.08


def test_hip_joint_centre_virtual_marker_in_a_moving_pelvis(tmp_path):
    text = GOOD.replace('method = "bell"', 'method = "davis"\nleg_length = 0.9')
    ms = load_markerset(write(tmp_path, text))
    rot = Rotation.random(6, random_state=5).as_matrix()
    origin = np.random.default_rng(3).normal(size=(6, 3))
    local = {"RASI": [0, -0.12, 0], "LASI": [0, 0.12, 0], "SACR": [-0.16, 0, 0.05]}
    pts = np.stack([origin + rot @ np.array(v) for v in local.values()], axis=1)
    trial = Trial(list(local) + ["LKNE", "LTHI"], np.concatenate([pts, pts[:, :2]], axis=1),
                  100.0)
    hjc = ms.apply_virtual(trial).marker("LHJC")
    # the PiG frame's x is the sacrum-to-ASIS direction made orthogonal to y:
    # here tilted down by atan(0.05 / 0.16) about y, as the sacrum sits higher
    tilt = np.arctan2(0.05, 0.16)
    pelvis = np.array([[np.cos(tilt), 0, np.sin(tilt)], [0, 1, 0],
                       [-np.sin(tilt), 0, np.cos(tilt)]])
    offset = hip_joint_centre_offset("davis", "left", 0.24, np.hypot(0.16, 0.05),
                                     leg_length=0.9)
    np.testing.assert_allclose(hjc, origin + rot @ pelvis @ offset, atol=1e-12)


def test_frame_from_markers_is_orthonormal_and_right_handed():
    rng = np.random.default_rng(0)
    p = rng.normal(size=(3, 1000, 3))
    rot = frame_from_markers(*p)
    np.testing.assert_allclose(rot.swapaxes(-1, -2) @ rot, np.broadcast_to(np.eye(3),
                               rot.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(rot), 1.0, atol=1e-12)


#: Vicon Plug-in Gait walks whose files store the femur and tibia origins (LFEO = knee
#: joint centre, LTIO = ankle joint centre) and the subject's widths and rotation offsets.
PIG_WALKS = [f"biomechzoo_sample_study/{s}.c3d" for s in (
    "HC002D/Straight/HC002D06", "HC030A/Straight/HC030A05", "HC031A/Straight/HC031A06",
    "HC032A/Straight/HC032A03", "HC033A/Straight/HC033A10", "HC036A/Straight/HC036A10",
    "HC038A/Straight/HC038A11", "HC039A/Straight/HC039A17")]


def test_knee_and_ankle_joint_centres_are_vicons():
    """The presets' knee and ankle joint centres (Plug-in Gait's chord with the widths and
    rotation offsets stored in the trial) against the femur and tibia origins Vicon's own
    Plug-in Gait wrote into the same files: a median 2 mm apart, where the lateral
    knee and ankle markers are 50-70 and 35-45 mm away."""
    from mocap.io import read
    from tests.conftest import realdata_path

    markerset = load_markerset("plugingait-lower")
    for local in PIG_WALKS:
        trial = markerset.apply_virtual(read(realdata_path(local)))
        for side in "LR":
            for ours, vicon, marker in ((f"{side}KJC", f"{side}FEO", f"{side}KNE"),
                                        (f"{side}AJC", f"{side}TIO", f"{side}ANK")):
                gap = np.nanmedian(np.linalg.norm(trial.marker(ours) - trial.marker(vicon),
                                                  axis=1))
                far = np.nanmedian(np.linalg.norm(trial.marker(marker) - trial.marker(vicon),
                                                  axis=1))
                assert gap < 0.005 and far > 0.03, (local, ours, gap, far)


def test_joint_centre_without_the_subjects_width_is_the_marker(tmp_path):
    """A trial without PROCESSING widths keeps the marker on the joint (width 0)."""
    text = GOOD + """
[[virtual]]
name = "LKJC"
type = "joint_centre"
joint = "knee"
side = "left"
markers = ["LTHI", "LHJC", "LKNE"]
"""
    ms = load_markerset(write(tmp_path, text))
    rng = np.random.default_rng(1)
    names = ["RASI", "LASI", "SACR", "LKNE", "LTHI"]
    trial = Trial(names, rng.normal(size=(4, 5, 3)), 100.0)
    out = ms.apply_virtual(trial)
    np.testing.assert_allclose(out.marker("LKJC"), trial.marker("LKNE"))
    with pytest.raises(MocapError, match="'joint' must be one of knee, ankle"):
        load_markerset(write(tmp_path, text.replace('"knee"', '"hip"'), "bad.toml"))
