"""Write → read round trips for C3D, CSV and TRC, and the suffix dispatcher."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mocap.errors import MocapError
from mocap.io import format_of, read, register_format, write
from mocap.trial import Trial


def synthetic_trial(frames: int = 120, markers: int = 5, rate: float = 100.0,
                    seed: int = 0) -> Trial:
    """Markers on smooth paths (metres) with a few gaps, one at the first frame."""
    rng = np.random.default_rng(seed)
    times = np.arange(frames) / rate
    phase = rng.uniform(0, 2 * np.pi, (1, markers, 3))
    centre = rng.uniform(-1.0, 1.0, (1, markers, 3))
    points = centre + 0.3 * np.sin(2 * np.pi * 1.1 * times[:, None, None] + phase)
    points[0, 0] = np.nan
    points[10:15, 1] = np.nan
    points[-1, markers - 1] = np.nan
    labels = ["LASI", "RASI", "L.Knee", "r_ankle", "Subj:TOE"][:markers]
    return Trial(labels, points, rate)


@pytest.mark.parametrize("suffix", [".c3d", ".csv", ".trc", ".C3D", ".Trc", ".CSV"])
def test_round_trip_keeps_points_labels_rate_and_gaps(tmp_path, suffix):
    trial = synthetic_trial(rate=69.99261474609375)
    path = tmp_path / f"walk{suffix}"
    write(trial, path)
    back = read(path)
    assert back.labels == trial.labels
    # CSV has no rate field: it comes back from the times, written to 1 ps
    assert back.rate == pytest.approx(trial.rate, rel=1e-10 if suffix.lower() == ".csv"
                                      else 1e-12)
    assert back.frames == trial.frames
    np.testing.assert_array_equal(np.isnan(back.points), np.isnan(trial.points))
    # C3D stores 32-bit floats in mm: 1e-7 m; the text formats are exact to their
    # default 1 nm (half a unit of the last decimal: 5e-10 m).
    tolerance = 2e-6 if suffix.lower() == ".c3d" else 5.000001e-10
    np.testing.assert_allclose(back.points, trial.points, atol=tolerance, equal_nan=True)
    assert back.format == suffix.lower()[1:]
    assert list(tmp_path.iterdir()) == [path]          # no temporary files left


@pytest.mark.parametrize("suffix", [".c3d", ".trc"])
@pytest.mark.parametrize("units, factor", [("mm", 1000.0), ("cm", 100.0), ("m", 1.0)])
def test_units_are_stored_as_asked_and_read_back_in_metres(tmp_path, suffix, units, factor):
    trial = synthetic_trial()
    path = tmp_path / f"walk{suffix}"
    write(trial, path, units=units)
    back = read(path)
    assert back.units == units
    np.testing.assert_allclose(back.points, trial.points, atol=2e-6, equal_nan=True)
    if suffix == ".c3d":
        import ezc3d

        raw = ezc3d.c3d(str(path))
        assert raw["parameters"]["POINT"]["UNITS"]["value"] == [units]
        stored = raw["data"]["points"][:3, 2, 3]
        np.testing.assert_allclose(stored, trial.points[3, 2] * factor, rtol=1e-6)
        residuals = raw["data"]["meta_points"]["residuals"][0]
        assert residuals[1, 12] == -1 and residuals[1, 20] >= 0   # NaN → residual -1
    else:
        lines = path.read_text().splitlines()
        assert lines[2].split("\t")[:5] == ["100", "100", "120", "5", units]
        assert lines[6].split("\t")[:2] == ["1", "0.000000000"]
        row = lines[6 + 3].split("\t")
        assert float(row[2 + 3 * 2]) == pytest.approx(trial.points[3, 2, 0] * factor)


def test_csv_layout_is_time_and_label_axis_columns_in_metres(tmp_path):
    trial = synthetic_trial(frames=3, markers=2)
    path = tmp_path / "t.csv"
    write(trial, path)
    lines = path.read_text().splitlines()
    assert lines[0] == "time,LASI_x,LASI_y,LASI_z,RASI_x,RASI_y,RASI_z"
    assert lines[1].split(",")[:4] == ["0.000000000000", "", "", ""]   # NaN: empty cell
    assert float(lines[2].split(",")[0]) == pytest.approx(0.01)


def test_zero_marker_is_missing_in_every_text_format(tmp_path):
    (tmp_path / "a.csv").write_text("time,A_x,A_y,A_z\n0,0,0,0\n0.5,1,2,3\n1.0,,2,3\n")
    trial = read(tmp_path / "a.csv")
    assert trial.rate == 2.0
    assert np.isnan(trial.points[0]).all() and np.isnan(trial.points[2]).all()
    np.testing.assert_array_equal(trial.points[1, 0], [1, 2, 3])


def test_c3d_written_by_us_is_read_identically_by_ezc3d_and_our_decoder(tmp_path):
    from mocap.io.c3d.decode import decode_c3d_data
    from mocap.io.c3d.layout import inspect_c3d

    trial = synthetic_trial()
    path = tmp_path / "t.c3d"
    write(trial, path)
    layout = inspect_c3d(path)
    points, residuals, _ = decode_c3d_data(layout)
    import ezc3d

    raw = ezc3d.c3d(str(path))
    valid = residuals >= 0
    np.testing.assert_array_equal(valid, raw["data"]["meta_points"]["residuals"][0].T >= 0)
    np.testing.assert_array_equal(points[valid],
                                  raw["data"]["points"][:3].transpose(2, 1, 0)[valid])
    from mocap.io.c3d.read import read_c3d

    ours, theirs = read(path), read_c3d(path, engine="ezc3d")
    assert (ours.metadata["reader"], theirs.metadata["reader"]) == ("mocap", "ezc3d")
    np.testing.assert_array_equal(ours.points, theirs.points)


def test_analogs_survive_a_c3d_round_trip(tmp_path):
    trial = synthetic_trial(frames=50)
    trial.analogs = np.arange(50 * 4 * 2, dtype=float).reshape(200, 2)
    trial.analog_labels = ["Fz", "EMG1"]
    trial.analog_rate = 400.0
    write(trial, tmp_path / "a.c3d")
    back = read(tmp_path / "a.c3d")
    assert back.analog_labels == ["Fz", "EMG1"] and back.analog_rate == 400.0
    np.testing.assert_allclose(back.analogs, trial.analogs)


def test_unknown_suffix_and_missing_file_are_clear_errors(tmp_path):
    with pytest.raises(MocapError, match="cannot read files with suffix '.xyz'"):
        read(tmp_path / "walk.xyz")
    with pytest.raises(MocapError, match="no such file"):
        read(tmp_path / "missing.c3d")
    with pytest.raises(MocapError, match="cannot write files with no suffix"):
        write(synthetic_trial(), tmp_path / "noext")
    with pytest.raises(MocapError, match="not a C3D file"):
        (tmp_path / "text.c3d").write_bytes(b"hello" * 300)
        read(tmp_path / "text.c3d")
    with pytest.raises(MocapError, match="not a TRC file"):
        (tmp_path / "x.trc").write_text("time,a\n")
        read(tmp_path / "x.trc")
    with pytest.raises(MocapError, match="first column must be 'time'"):
        (tmp_path / "x.csv").write_text("frame,a_x,a_y,a_z\n1,2,3,4\n")
        read(tmp_path / "x.csv")


def test_writers_refuse_bad_trials_without_leaving_files(tmp_path):
    trial = synthetic_trial()
    trial.labels[1] = trial.labels[0]
    with pytest.raises(MocapError, match="unique"):
        write(trial, tmp_path / "dup.c3d")
    with pytest.raises(MocapError, match="units"):
        write(synthetic_trial(), tmp_path / "x.trc", units="furlong")
    long_label = synthetic_trial(markers=2)
    long_label.labels[0] = "a" * 300
    with pytest.raises(MocapError, match="at most 255 bytes"):
        write(long_label, tmp_path / "long.c3d")
    assert list(tmp_path.iterdir()) == []


def test_other_formats_can_register(tmp_path):
    seen = {}

    def read_fake(path):
        seen["read"] = str(path)
        return "motion"

    def write_fake(obj, path, **options):
        seen["write"] = (obj, options)

    register_format("FAKE", reader=read_fake, writer=write_fake, description="test")
    (tmp_path / "a.fake").write_text("x")
    assert read(tmp_path / "A.FAKE".lower()) == "motion"
    write("obj", tmp_path / "b.Fake", scale=2)
    assert seen["write"] == ("obj", {"scale": 2})
    assert format_of("x.FAKE").name == "fake"


def test_trc_with_empty_cells_short_rows_and_padded_header(tmp_path):
    path = tmp_path / "odd.trc"
    path.write_text(
        "PathFileType\t4\t(X/Y/Z)\todd.trc\n"
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\n"
        "  50.0\t\t  50.0\t\t    3\t\t     2\t\t cm\n"          # padded like OpenSim's Rajagopal data
        "Frame#\tTime\tA\t\t\tB\t\t\n"
        "\t\tX1\tY1\tZ1\tX2\tY2\tZ2\n"
        "\n"
        "1\t0.00\t1\t2\t3\t4\t5\t6\n"
        "2\t0.02\t1\t2\t3\t\t\t\n"                               # B missing
        "3\t0.04\t1\t2\n")                                       # short row: A.z and B missing
    trial = read(path)
    assert trial.rate == 50.0 and trial.units == "cm" and trial.labels == ["A", "B"]
    np.testing.assert_allclose(trial.points[0], [[0.01, 0.02, 0.03], [0.04, 0.05, 0.06]])
    assert np.isnan(trial.points[1, 1]).all() and not np.isnan(trial.points[1, 0]).any()
    assert np.isnan(trial.points[2]).any(axis=1).all()
    # the short row is said (the empty cells of row 2 are cells, and gaps, as written)
    assert trial.metadata["warnings"] == ["1 row has 4 cells where the header names 8 (first "
                                          "at line 9); the missing cells read as gaps"]


def test_trc_without_rate_is_a_clear_error(tmp_path):
    path = tmp_path / "bad.trc"
    path.write_text("PathFileType\t4\n Foo\tBar\n1\t2\nFrame#\tTime\tA\n\t\tX1\tY1\tZ1\n")
    with pytest.raises(MocapError, match="no DataRate"):
        read(path)


def test_c3d_with_more_than_255_markers_round_trips(tmp_path):
    """Labels beyond 255 go to POINT:LABELS2 (C3D strings are 255 per parameter)."""
    trial = synthetic_trial(frames=20, markers=5)
    points = np.repeat(trial.points, 62, axis=1)[:, :300]
    big = Trial([f"M{i:03d}" for i in range(300)], points, 120.0)
    write(big, tmp_path / "big.c3d")
    back = read(tmp_path / "big.c3d")
    assert back.labels == big.labels
    np.testing.assert_allclose(back.points, big.points, atol=2e-6, equal_nan=True)


label_text = st.text(alphabet=st.characters(whitelist_categories=("Lu", "Ll", "Nd"),
                                            whitelist_characters="_.:-"),
                     min_size=1, max_size=12)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(labels=st.lists(label_text, min_size=1, max_size=6, unique=True),
       frames=st.integers(1, 30), rate=st.floats(1.0, 2000.0),
       seed=st.integers(0, 2 ** 31), suffix=st.sampled_from([".c3d", ".trc", ".csv"]))
def test_round_trip_property(tmp_path, labels, frames, rate, seed, suffix):
    rng = np.random.default_rng(seed)
    points = rng.uniform(-3.0, 3.0, (frames, len(labels), 3))
    points[rng.random((frames, len(labels))) < 0.2] = np.nan
    trial = Trial(labels, points, rate)
    path = tmp_path / f"p{seed}{suffix}"
    write(trial, path)
    back = read(path)
    assert back.labels == labels and back.frames == frames
    np.testing.assert_array_equal(np.isnan(back.points), np.isnan(points))
    np.testing.assert_allclose(back.points, points,
                               atol=2e-6 if suffix == ".c3d" else 5.000001e-10, equal_nan=True)
    if frames > 1 or suffix != ".csv":           # one CSV row has no time step
        assert back.rate == pytest.approx(rate, rel={".c3d": 1e-6, ".csv": 1e-8}.get(suffix,
                                                                                    1e-12))


def test_c3d_longer_than_the_16_bit_frame_count(tmp_path):
    """70 000 frames: header and POINT:FRAMES saturate, TRIAL:ACTUAL_*_FIELD carry the count."""
    rng = np.random.default_rng(1)
    trial = Trial(["a", "b"], rng.normal(size=(70000, 2, 3)), 1000.0)
    write(trial, tmp_path / "long.c3d")
    back = read(tmp_path / "long.c3d")
    assert back.frames == 70000 and back.metadata["warnings"] == []
    np.testing.assert_allclose(back.points, trial.points, atol=1e-6)


def test_vicon_nexus_csv_with_devices_before_and_model_outputs_after(tmp_path):
    path = tmp_path / "nexus.csv"
    path.write_text(
        "Devices\n1000\n,,Force Plate:Force,,\nFrame,Sub Frame,Fx,Fy,Fz\n,,N,N,N\n"
        "1,0,0.1,0.2,0.3\n\n"
        "Trajectories\n100\n,,S:LASI,,,S:RASI,,\nFrame,Sub Frame,X,Y,Z,X,Y,Z\n"
        ",,mm,mm,mm,mm,mm,mm\n"
        "1,0,10,20,30,40,50,60\n2,0,11,21,31,,,\n\n"
        "Model Outputs\n100\n,,S:LKneeAngles,,\nFrame,Sub Frame,X,Y,Z\n,,deg,deg,deg\n1,0,5,6,7\n")
    trial = read(path)
    assert trial.labels == ["S:LASI", "S:RASI"] and trial.rate == 100.0 and trial.frames == 2
    np.testing.assert_allclose(trial.points[0], [[0.01, 0.02, 0.03], [0.04, 0.05, 0.06]])
    assert np.isnan(trial.points[1, 1]).all()
