"""Every real file in ../shared/realdata loads with the catalogue's frames, markers and rate.

``catalogue.json`` records what a reference reader (ezc3d 1.7.2) saw. Where our
reading deliberately differs, ``DEVIATIONS`` says what we read and why; files
the reference reader could not open have their expected figures here too.
"""
from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from mocap.errors import MocapError
from mocap.io import read
from tests.conftest import REALDATA, realdata_path

#: local path → (frames, markers, rate, why we differ from the reference reader)
DEVIATIONS = {
    "c3dorg_via_c3dio/sample_20/phasespace_sample.c3d": (
        701, 40, 30.0, "no POINT group: ezc3d reads nothing, but the header announces "
                       "40 points × 701 frames at 30 Hz and the file holds exactly that "
                       "(the c3d package reads the same)"),
    "ezc3d_testFiles/Kistler.c3d": (
        3969, 0, 60.0, "analog-only file without POINT:RATE: the header's 60 Hz frame rate "
                       "(600 Hz analog / 10 samples per frame) instead of 0; the c3d "
                       "package says 60 Hz too"),
    "c3dorg_via_c3dio/sample_02/sgi_int.c3d": (
        89, 36, 50.0, "ezc3d cannot read SGI/MIPS files; same capture as pc_int.c3d"),
    "c3dorg_via_c3dio/sample_02/sgi_real.c3d": (
        89, 36, 50.0, "ezc3d cannot read SGI/MIPS files; same capture as pc_real.c3d"),
    "c3dorg_via_c3dio/sample_06/MACsample.c3d": (
        180, 33, 60.0, "ezc3d cannot read SGI/MIPS files; the c3d package refuses its "
                       "inconsistent scale factors"),
}
#: Files that are damaged beyond reading: a clear MocapError is the right answer.
BROKEN = {
    "c3dorg_via_c3dio/sample_18/bad_parameter_section.c3d":
        "runs to byte 5771, outside the parameter section",
}


def _catalogue() -> list[dict]:
    path = REALDATA / "catalogue.json"
    if not path.exists():
        return []
    return [entry for entry in json.loads(path.read_text())
            if entry["kind"] in ("c3d", "trc", "csv")]


def _expected(entry: dict) -> tuple[int, int, float]:
    if entry["local"] in DEVIATIONS:
        return DEVIATIONS[entry["local"]][:3]
    frames = entry.get("frames_counted", entry["frames"])
    return int(float(frames)), int(float(entry["n_markers"])), float(entry["point_rate"])


CATALOGUE = _catalogue()


def test_catalogue_is_present():
    realdata_path("catalogue.json")
    assert len(CATALOGUE) > 100


@pytest.mark.parametrize("entry", CATALOGUE, ids=[entry["local"] for entry in CATALOGUE])
def test_real_file_loads_with_catalogue_figures(entry):
    path = realdata_path(entry["local"])
    if entry["local"] in BROKEN:
        with pytest.raises(MocapError, match=BROKEN[entry["local"]]):
            read(path)
        return
    trial = read(path)
    frames, markers, rate = _expected(entry)
    assert (trial.frames, len(trial.labels)) == (frames, markers)
    assert trial.rate == pytest.approx(rate, rel=1e-9)
    assert trial.points.shape == (frames, markers, 3)
    assert len(set(trial.labels)) == len(trial.labels) and all(trial.labels)
    valid = trial.points[np.isfinite(trial.points)]
    # Metres: no lab is 30 m wide, and no marker sits on the origin for a whole trial.
    if valid.size:
        assert np.abs(valid).max() < 30.0
        assert np.percentile(np.abs(valid), 99) > 0.02
    head = entry.get("labels_head") or []
    if head and not entry.get("n_blank_labels") and not entry.get("n_duplicate_labels"):
        assert trial.labels[:len(head)] == head      # the reference reader's first labels


def test_qualisys_zero_coded_gaps_are_missing():
    trial = read(realdata_path("c3dorg_via_c3dio/sample_26/Walking_Hybrid_1_1.c3d"))
    entry = next(e for e in CATALOGUE if e["local"].endswith("Walking_Hybrid_1_1.c3d"))
    missing = np.isnan(trial.points).any(axis=2).mean()
    # The file marks every gap as (0, 0, 0) with a valid residual.
    assert missing == pytest.approx(entry["zero_xyz_frac"], abs=1e-9)
    assert missing > 0.2


def test_truncated_trc_loads_its_rows_and_says_so():
    trial = read(realdata_path("pyomeca/markers.trc"))
    assert trial.frames == 93
    assert any("652 frames" in w and "93 rows" in w for w in trial.metadata["warnings"])


def test_vicon_nexus_csv_export():
    trial = read(realdata_path("pyomeca/markers.csv"))
    assert trial.labels[0] == "boite:gauche_ext" and trial.units == "mm"
    assert np.isnan(trial.points).any(axis=2).mean() == pytest.approx(0.010311, abs=1e-5)
    # The same capture is in the Vicon C3D sample (51 markers, 580 frames, mm).
    c3d = read(realdata_path("ezc3d_testFiles/Vicon.c3d"))
    np.testing.assert_allclose(trial.points[:, 0], c3d.marker(c3d.labels[0]), atol=1e-5,
                               equal_nan=True)


def test_trimmed_c3d_loads_complete_frames_with_a_warning():
    trial = read(realdata_path("ezc3d_testFiles/Optotrak.c3d"))
    assert trial.frames == 29
    assert any("1149 frames" in w for w in trial.metadata["warnings"])


def test_mac_sample_uses_the_header_scale_that_gives_human_proportions():
    trial = read(realdata_path("c3dorg_via_c3dio/sample_06/MACsample.c3d"))
    foot = np.nanmedian(np.linalg.norm(trial.marker("RHEE") - trial.marker("RTOE"), axis=1))
    trunk = np.nanmedian(np.linalg.norm(trial.marker("RSHO") - trial.marker("RHIP"), axis=1))
    assert 0.15 < foot < 0.25 and 0.40 < trunk < 0.55
    assert trial.labels[2:5] == ["RTHI", "RTHI_2", "RTHI_3"]      # repeated labels


def test_modelled_points_are_kept_apart_from_markers():
    trial = read(realdata_path("c3dorg_via_c3dio/sample_04/sub_labels.c3d"))
    modelled = trial.modelled
    assert len(trial.labels) == 86 and len(modelled["labels"]) == 28
    assert "Matt:LKneeAngles" in modelled["labels"]
    assert modelled["values"].shape == (333, 28, 3)


def _c3d_package_points(path, frames: int) -> tuple[np.ndarray, np.ndarray]:
    """First ``frames`` frames decoded by the pure-Python ``c3d`` package (file units)."""
    import c3d

    with open(path, "rb") as handle, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reader = c3d.Reader(handle)
        rows = []
        for _, points, _ in reader.read_frames(check_nan=False):
            rows.append(points)
            if len(rows) == frames:
                break
    stacked = np.stack(rows)
    return stacked[:, :, :3], stacked[:, :, 3]


@pytest.mark.parametrize("local, scale", [
    ("c3dorg_via_c3dio/sample_02/sgi_real.c3d", 1e-3),
    ("c3dorg_via_c3dio/sample_02/sgi_int.c3d", 1e-3),
    ("c3dorg_via_c3dio/sample_22/BKINtechnologies.c3d", 1.0),
    ("c3dorg_via_c3dio/sample_28/type1.C3D", 1e-3),
    ("c3dorg_via_c3dio/sample_20/phasespace_sample.c3d", 1e-3),
])
def test_own_decoder_matches_the_c3d_package_where_ezc3d_cannot_read(local, scale):
    path = realdata_path(local)
    trial = read(path)
    assert trial.metadata["reader"] == "mocap"
    reference, residuals = _c3d_package_points(path, 200)
    reference = np.where(((residuals >= 0) & (reference != 0).any(axis=2))[..., None],
                         reference * scale, np.nan)
    np.testing.assert_allclose(trial.points[:len(reference)], reference, rtol=1e-6, atol=1e-9,
                               equal_nan=True)


def test_bts_file_ezc3d_misreads_is_smooth_with_our_layout():
    """ezc3d skips the 6 analog words per frame it is not told about and scrambles points."""
    import dataclasses

    from mocap.io.c3d.decode import decode_c3d_data
    from mocap.io.c3d.layout import inspect_c3d

    path = realdata_path("c3dorg_via_c3dio/sample_28/type1.C3D")
    trial = read(path)
    steps = np.linalg.norm(np.diff(trial.points, axis=0), axis=2)
    assert np.nanmedian(steps) < 0.03          # < 3 m/s at 100 Hz: a walking marker
    # ezc3d's reading: no analog words between frames.
    layout = inspect_c3d(path)
    assert (layout.analog_channels, layout.analog_samples_per_frame) == (6, 1)
    without_analogs = dataclasses.replace(layout, analog_per_frame=0, analog_channels=0,
                                          analog_samples_per_frame=0)
    points, residuals, _ = decode_c3d_data(without_analogs)
    points = np.where((residuals >= 0)[..., None], points / 1000, np.nan)
    scrambled = np.linalg.norm(np.diff(points, axis=0), axis=2)
    assert np.nanmedian(scrambled) > 0.3


#: One file per vendor/source that ezc3d reads correctly.
EZC3D_READABLE = [
    "ezc3d_testFiles/Vicon.c3d", "ezc3d_testFiles/BTS.c3d", "ezc3d_testFiles/FP_Type1.c3d",
    "c3dorg_via_c3dio/sample_02/dec_real.c3d", "c3dorg_via_c3dio/sample_02/pc_int.c3d",
    "c3dorg_via_c3dio/sample_04/sub_labels.c3d", "c3dorg_via_c3dio/sample_26/Capture0002.c3d",
    "c3dorg_via_c3dio/sample_30/admarche2.c3d",
    "c3dorg_via_c3dio/sample_00/Codamotion/codamotion_gaitwands_19970212.c3d",
    "kineticstoolkit/kinematics/walkingOptiTrack.c3d", "pycgm/ROM/Sample_Static.c3d",
    "biomechzoo_sample_study/HC002D/Static/HC002D02.c3d",
]


@pytest.mark.parametrize("local", EZC3D_READABLE)
def test_own_decoder_agrees_with_ezc3d(local):
    from mocap.io.c3d.read import ezc3d_refusal, read_c3d
    from mocap.io.c3d.layout import inspect_c3d

    path = realdata_path(local)
    assert ezc3d_refusal(inspect_c3d(path)) == ""
    ours, theirs = read_c3d(path), read_c3d(path, engine="ezc3d")
    assert ours.labels == theirs.labels and ours.rate == theirs.rate
    np.testing.assert_allclose(ours.points, theirs.points, rtol=1e-6, atol=1e-7)
    if ours.analogs is not None:
        np.testing.assert_allclose(ours.analogs, theirs.analogs, rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("local", ["c3dorg_via_c3dio/sample_28/type1.C3D",
                                   "c3dorg_via_c3dio/sample_02/sgi_int.c3d",
                                   "c3dorg_via_c3dio/sample_10/TYPE-2.C3D"])
def test_ezc3d_engine_refuses_files_it_would_misread(local):
    from mocap.io.c3d.read import read_c3d

    with pytest.raises(MocapError, match="not read with ezc3d"):
        read_c3d(realdata_path(local), engine="ezc3d")


def test_the_six_processor_and_number_formats_of_one_capture_agree():
    """c3d.org sample 02: one capture stored as Intel, DEC and SGI, integer and float."""
    folder = "c3dorg_via_c3dio/sample_02/"
    trials = {name: read(realdata_path(folder + name + ".c3d"))
              for name in ("pc_real", "pc_int", "dec_real", "dec_int", "sgi_real", "sgi_int")}
    reference = trials["pc_real"]
    scale = 0.28118187189102173e-3            # POINT:SCALE of the integer files, metres
    for name, trial in trials.items():
        assert trial.labels == reference.labels, name
        np.testing.assert_array_equal(np.isnan(trial.points), np.isnan(reference.points))
        tolerance = scale * 1.0001 if name.endswith("int") else 1e-6
        np.testing.assert_allclose(trial.points, reference.points, atol=tolerance,
                                   equal_nan=True, err_msg=name)
        assert trial.analog_labels == reference.analog_labels
        np.testing.assert_array_equal(trial.analogs, reference.analogs)


def test_gait_events_are_indexed_from_the_trial_start():
    trial = read(realdata_path("biomechzoo_sample_study/HC002D/Straight/HC002D06.c3d"))
    events = trial.events
    # EVENT:TIMES 2.28 s (Left Foot Strike) at 100 Hz is capture frame 229; the
    # trial starts at capture frame 125, so it is points[104], 1.04 s in.
    strike = next(e for e in events if e["context"] == "Left" and e["label"] == "Foot Strike")
    assert strike["frame"] == 104 and strike["time"] == pytest.approx(1.04)
    assert [e["frame"] for e in events] == sorted(e["frame"] for e in events)


def test_events_survive_a_c3d_rewrite(tmp_path):
    from mocap.io import write

    trial = read(realdata_path("biomechzoo_sample_study/HC002D/Straight/HC002D06.c3d"))
    write(trial, tmp_path / "copy.c3d")
    copy = read(tmp_path / "copy.c3d")
    assert [(e["label"], e["context"], e["frame"]) for e in copy.events] == \
        [(e["label"], e["context"], e["frame"]) for e in trial.events]


@pytest.mark.parametrize("local", ["c3dorg_via_c3dio/sample_06/MACsample.c3d",
                                   "c3dorg_via_c3dio/sample_28/type1.C3D",
                                   "c3dorg_via_c3dio/sample_02/sgi_int.c3d",
                                   "ezc3d_testFiles/Vicon.c3d"])
def test_odd_real_files_rewritten_as_c3d_read_back_the_same(tmp_path, local):
    from mocap.io import write

    trial = read(realdata_path(local))
    write(trial, tmp_path / "copy.c3d")
    copy = read(tmp_path / "copy.c3d")
    assert copy.labels == trial.labels and copy.analog_labels == trial.analog_labels
    assert copy.metadata["warnings"] == []
    np.testing.assert_allclose(copy.points, trial.points, atol=1e-6, equal_nan=True)
    np.testing.assert_allclose(copy.analogs, trial.analogs, rtol=1e-6, atol=1e-6)
