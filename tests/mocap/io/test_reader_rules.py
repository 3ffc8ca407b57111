"""Readers refuse what has no meaning and say what they had to assume (issue 11): a rate of 0
only where nothing needs timing, a time column that must increase, ASF channel names that
must be known. Each refusal is one line naming the file and, for text files, the line."""
from __future__ import annotations

import json
import struct
import warnings
from pathlib import Path

import numpy as np
import pytest

from mocap.cli import main
from mocap.errors import MocapError, MocapWarning
from mocap.io import read
from mocap.io.asfamc import read_asf
from tests.conftest import realdata_path

DATA = Path(__file__).resolve().parents[2] / "data"


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


# ---------------------------------------------------------------- rates of 0

def test_a_one_row_csv_has_no_rate_but_keeps_its_time_and_is_refused_where_one_is_needed(
        tmp_path, capsys):
    """One row: the rate is not derivable. Reading warns; a CSV written from it keeps the
    row's time (it was an empty cell, the time computed as 0/0); a TRC, whose DataRate the
    project's own reader refuses at 0, is refused (it was written with DataRate 0 and
    time NaN)."""
    one = tmp_path / "one.csv"
    one.write_text("time,A_x,A_y,A_z\n0.5,0.1,0.2,0.3\n")
    with pytest.warns(MocapWarning, match="no rate"):
        trial = read(one)
    assert trial.rate == 0 and trial.times.tolist() == [0.0]
    assert main(["convert", str(one), str(tmp_path / "back.csv")]) == 0
    assert (tmp_path / "back.csv").read_text().splitlines()[1].split(",")[0] == "0.500000000000"
    capsys.readouterr()
    assert main(["convert", str(one), str(tmp_path / "one.trc")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "warning" in err[0] and "no rate" in err[0]
    assert "one.trc" in err[1] and "needs a sampling rate" in err[1]
    assert not (tmp_path / "one.trc").exists()


def _emg_with_rates(tmp_path: Path, point_rate: float, analog_rate: float) -> Path:
    """Cometa's EMG trial (no markers, 24 analog channels, POINT:RATE 10 Hz, ANALOG:RATE
    2000 Hz) with its rates replaced, as ezc3d writes it (and then by byte patching where
    ezc3d refuses: it writes no analog rate of 0)."""
    ezc3d = pytest.importorskip("ezc3d")
    source = realdata_path("c3dorg_via_c3dio", "sample_00", "Cometa_Systems",
                           "EMG_Data_Cometa.c3d")
    c3d = ezc3d.c3d(str(source))
    c3d["parameters"]["POINT"]["RATE"]["value"] = np.array([point_rate])
    path = tmp_path / f"emg_{point_rate:g}_{analog_rate:g}.c3d"
    c3d.write(str(path))
    if analog_rate != 2000.0:
        data = bytearray(path.read_bytes())
        start = (data[0] - 1) * 512
        end = (struct.unpack("<H", data[16:18])[0] - 1) * 512
        section = bytes(data[start:end])
        name = section.find(b"RATE", section.find(b"ANALOG"))
        value = section.find(struct.pack("<f", 2000.0), name, name + 40)
        assert name > 0 and value > 0
        data[start + value:start + value + 4] = struct.pack("<f", analog_rate)
        path.write_bytes(bytes(data))
    return path


def test_a_c3d_without_markers_whose_point_rate_is_0_takes_the_rate_from_its_analogs(tmp_path):
    """POINT:RATE 0 (and the header's 0, as ezc3d writes it): the frame rate is ANALOG:RATE
    / samples per frame, the file's own 10 Hz, with a warning; it read as 0 Hz with
    analogs 'at 0 Hz' and no word."""
    path = _emg_with_rates(tmp_path, 0.0, 2000.0)
    with pytest.warns(MocapWarning, match="ANALOG:RATE"):
        trial = read(path)
    assert trial.rate == 10.0 and trial.analog_rate == 2000.0
    assert trial.duration == pytest.approx(19.8)


def test_a_c3d_with_no_rate_at_all_warns_and_is_refused_where_times_are_needed(
        tmp_path, capsys):
    path = _emg_with_rates(tmp_path, 0.0, 0.0)
    assert main(["info", "--json", str(path)]) == 0
    out, err = capsys.readouterr()
    summary = json.loads(out)
    assert summary["rate"] == 0 and summary["duration"] is None
    assert summary["analog_rate"] is None
    assert [w for w in summary["warnings"] if "no frame rate" in w]
    assert main(["convert", str(path), str(tmp_path / "emg.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "warning" in err[0]
    assert str(path) in err[1] and "no sampling rate" in err[1]
    assert not (tmp_path / "emg.csv").exists()
    with pytest.raises(MocapError, match="times of its 199 frames are unknown"), \
            warnings.catch_warnings():
        warnings.simplefilter("ignore", MocapWarning)
        read(path).times


# ---------------------------------------------------------------- CSV time column

@pytest.mark.parametrize("rows, line, words", [
    (["0,1,2,3", "0.01,1,2,3", "", "0.03,1,2,3", "0.02,1,2,3"], 6, "0.02 s does not come after"),
    (["0,1,2,3", "0.01,1,2,3", "0.01,1,2,3"], 4, "0.01 s does not come after"),
    (["0,1,2,3", ",1,2,3", "0.02,1,2,3"], 3, "missing or not a number"),
    (["0,1,2,3", "nan,1,2,3", "0.02,1,2,3"], 3, "missing or not a number"),
])
def test_a_csv_time_column_must_increase(rows, line, words, tmp_path, capsys):
    """A time column that runs backwards, stalls or has a hole was read with a mean rate
    (or none); now one line names the file and the first offending line."""
    path = tmp_path / "walk.csv"
    path.write_text("time,A_x,A_y,A_z\n" + "\n".join(rows) + "\n")
    with pytest.raises(MocapError, match=f"line {line}: .*{words}"):
        read(path)
    assert main(["info", str(path)]) == 2
    error = _one_error_line(capsys)
    assert str(path) in error and f"line {line}" in error


def test_a_long_csv_running_backwards_names_its_line(tmp_path):
    """Large tables go through the compiled parser: the line is still the file's."""
    times = np.arange(20000) / 100.0
    times[15000] = times[14998]
    path = tmp_path / "long.csv"
    path.write_text("time,A_x,A_y,A_z\n" + "".join(f"{t:.6f},0.1,0.2,0.3\n" for t in times))
    with pytest.raises(MocapError, match="line 15002: time 149.98 s"):
        read(path)


# ---------------------------------------------------------------- ASF channel names

@pytest.mark.parametrize("old, new, message", [
    ("dof rx ry rz", "dof qq ry rz", "unknown dof 'qq'"),
    ("dof rx ry rz", "dof rx rx rz", "dof 'RX' given twice"),
    ("order TX TY TZ RX RY RZ", "order TX TY TZ RX RY RQ", "unknown root order 'RQ'"),
    ("axis 0 0 20  XYZ", "axis 0 0 20  XYQ", "axis order 'XYQ'"),
])
def test_asf_channels_must_be_known(old, new, message, tmp_path, capsys):
    """``dof qq`` was read as a channel and its AMC values silently dropped."""
    text = (DATA / "cmu_lambada.asf").read_text()
    assert old in text
    line = text[:text.index(old)].count("\n") + 1
    asf = tmp_path / "cmu_lambada.asf"
    asf.write_text(text.replace(old, new, 1))
    (tmp_path / "cmu_lambada.amc").write_bytes((DATA / "cmu_lambada.amc").read_bytes())
    with pytest.raises(MocapError, match=f"ASF line {line}: {message}"):
        read_asf(asf)
    assert main(["check", str(tmp_path / "cmu_lambada.amc")]) == 2
    error = _one_error_line(capsys)
    assert str(asf) in error and f"line {line}" in error



def test_file_kind_is_decided_once_by_suffix_and_csv_header(tmp_path):
    """One decision of what a file holds (mocap.io.file_kind), used by every command."""
    from mocap.errors import MocapError
    from mocap.io import file_kind

    angles = tmp_path / "walk.csv"
    angles.write_text("time,pelvis.Z,pelvis.X,pelvis.Y\n0,1,2,3\n")
    markers = tmp_path / "markers.csv"
    markers.write_text("time,LASI_x,LASI_y,LASI_z\n0,1,2,3\n")
    assert file_kind(angles) == "angles"
    assert file_kind(markers) == "markers"
    assert file_kind(tmp_path / "subject.ASF") == "skeleton"
    assert file_kind(tmp_path / "run.amc") == "motion"
    with pytest.raises(MocapError, match=r"notes.txt: cannot read files with suffix '\.txt'"):
        file_kind(tmp_path / "notes.txt")
