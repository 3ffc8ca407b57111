"""Every warning a command prints is one line, and only the project's own are worded as its
findings (found by the hostile re-run of issue 11: numpy's RuntimeWarnings printed Python's
two lines with the source line, and a library's UserWarning looked like mocap's)."""
from __future__ import annotations

import warnings

import numpy as np
import scipy.signal

from mocap.rotations.angles import GimbalLockWarning
from mocap.cli import _warning_printer
from mocap.errors import MocapWarning


def _printed(capsys, emit) -> list[str]:
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = _warning_printer("angles")
        emit()
    return capsys.readouterr().err.splitlines()


def test_the_projects_warnings_are_its_findings_once_each(capsys):
    def emit():
        for _ in range(3):
            warnings.warn("w.c3d: header announces 600 frames", MocapWarning)
        warnings.warn("segment 'pelvis' in w.c3d: 3 frame(s) near gimbal lock", GimbalLockWarning)
    assert _printed(capsys, emit) == [
        "mocap angles: warning: w.c3d: header announces 600 frames",
        "mocap angles: warning: segment 'pelvis' in w.c3d: 3 frame(s) near gimbal lock"]


def test_numpy_and_library_warnings_are_one_line_naming_their_class_and_source(capsys):
    def emit():
        np.ones(2) / np.zeros(2)                                    # numpy, from this file
        warnings.warn("Badly conditioned filter coefficients", scipy.signal.BadCoefficients)
        warnings.warn_explicit("a library's note\nover two lines", UserWarning,
                               "/venv/lib/python3.12/site-packages/scipy/signal/_x.py", 12)
    lines = _printed(capsys, emit)
    here = "test_warning_lines.py"
    assert len(lines) == 3, lines
    assert lines[0].startswith(f"mocap angles: warning: RuntimeWarning in {here}:")
    assert lines[0].endswith(": divide by zero encountered in divide")
    assert lines[1].startswith(f"mocap angles: warning: BadCoefficients in {here}:")
    assert lines[2] == ("mocap angles: warning: UserWarning in scipy/signal/_x.py:12: "
                        "a library's note\\nover two lines")


def test_commands_met_by_the_hostile_run_raise_no_numpy_warning(tmp_path, capsys):
    """``forces --threshold 0`` divided by a zero force for the centre of pressure, and a
    low-pass far below every frequency overflowed in its gain: both printed numpy's
    RuntimeWarning. A plate without force has no COP (empty cells); the low-pass of a
    1e-300 Hz cutoff keeps the constant part only."""
    import csv

    from mocap.cli import main
    from mocap.clean.filtering import butterworth_lowpass
    from tests.conftest import realdata_path

    trial = realdata_path("biomechzoo_sample_study", "HC002D", "Straight", "HC002D06.c3d")
    out = tmp_path / "f.csv"
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert main(["forces", str(trial), "-o", str(out), "--threshold", "0"]) == 0
        x = np.sin(np.arange(200) / 7.0)[:, None] + 3.0
        smooth = butterworth_lowpass(x, 1e-300, 100.0)
    assert "Warning" not in capsys.readouterr().err
    rows = list(csv.DictReader(out.read_text().splitlines()))
    zero = [r for r in rows if float(r["plate1_Fz_N"]) == 0]
    assert zero and all(r["plate1_COPx_m"] == "" for r in zero)
    assert np.ptp(smooth) < 1e-9 and abs(smooth.mean() - 3.0) < 0.2
