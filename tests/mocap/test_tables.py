"""Results as pandas DataFrames equal the files the commands write (read back by pandas)."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.cli import main
from mocap.io import read
from mocap.io.c3d.forceplates import plate_forces
from mocap.pipeline import clinical_angles
from mocap.plugingait.events import gait_events, normalise_cycles
from tests.conftest import realdata_path

pandas = pytest.importorskip("pandas")
WALK = ("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")


def test_angles_and_cycles_frames_equal_the_csv_files(tmp_path, capsys):
    walk = realdata_path(*WALK)
    out, cycles_csv = tmp_path / "walk.csv", tmp_path / "cycles.csv"
    assert main(["angles", str(walk), "-m", "plugingait-lower", "-o", str(out),
                 "--cycles", str(cycles_csv)]) == 0
    capsys.readouterr()
    angles = clinical_angles(walk).angles
    table = angles.to_dataframe()
    written = pandas.read_csv(out, index_col="time")
    assert list(table.columns) == list(written.columns)
    assert table.index.name == "time" and len(table) == angles.frames
    np.testing.assert_allclose(table.to_numpy(), written.to_numpy(), atol=1e-5, equal_nan=True)
    np.testing.assert_allclose(table.index, written.index, atol=1e-6)

    cycles = normalise_cycles(angles, gait_events(read(walk))).to_dataframe()
    written = pandas.read_csv(cycles_csv)
    assert list(cycles.columns) == list(written.columns)
    assert list(cycles["side"]) == list(written["side"])
    assert list(cycles["cycle"]) == list(written["cycle"])
    np.testing.assert_allclose(cycles.iloc[:, 2:].to_numpy(float),
                               written.iloc[:, 2:].to_numpy(float), atol=1e-5, equal_nan=True)


def test_plate_forces_frame_holds_the_samples():
    plates = plate_forces(read(realdata_path(*WALK)))
    first = plates[0]
    table = first.to_dataframe()
    assert len(table) == first.samples and table.index.name == "time"
    np.testing.assert_array_equal(table[["force_x", "force_y", "force_z"]].to_numpy(),
                                  first.force)
    np.testing.assert_array_equal(table[["cop_x", "cop_y", "cop_z"]].to_numpy(), first.cop)
    assert table.index[1] == pytest.approx(1.0 / first.rate)
