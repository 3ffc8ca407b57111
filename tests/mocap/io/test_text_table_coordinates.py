"""Absurd coordinates in TRC and CSV files (found by the hostile re-run of issue 11): a value
such as 1e300 was read as a position without a word, and a CSV (metres) holding 1e308
converted to a TRC (millimetres) wrote 'inf'. Samples beyond ±1e9 are now read as missing,
with a warning."""
from __future__ import annotations

import numpy as np

from mocap.io import read, write
from mocap.io.text_table import MAX_COORDINATE
from tests.conftest import REALDATA, realdata_path

SHORT = ("opensim_models", "Pipelines", "Leg39", "leg39_swing_short.trc")


def test_a_trc_coordinate_beyond_the_limit_is_missing_with_a_warning(tmp_path):
    source = realdata_path(*SHORT)
    lines = source.read_text().splitlines(keepends=True)
    row = next(i for i, line in enumerate(lines) if line.startswith("4\t"))    # Frame# 4
    cells = lines[row].split("\t")
    cells[5] = "1e300"                           # the second marker's x
    lines[row] = "\t".join(cells)
    path = tmp_path / "huge.trc"
    path.write_text("".join(lines))
    trial, reference = read(path), read(source)
    assert trial.metadata["warnings"] == [
        "1 sample(s) with a coordinate beyond ±1e+09 read as missing"]
    assert np.isnan(trial.points[3, 1]).all()
    same = np.ones(trial.points.shape[:2], bool)
    same[3, 1] = False
    np.testing.assert_array_equal(trial.points[same], reference.points[same])


def test_a_csv_in_metres_with_1e308_converts_to_a_trc_without_inf(tmp_path):
    rows = ["time,A_x,A_y,A_z,B_x,B_y,B_z"]
    rows += [f"{i / 100:.2f},0.1,0.2,{0.3 + i / 1000:.3f},0.4,0.5,0.6" for i in range(10)]
    rows[5] = "0.04,0.1,0.2,1e308,0.4,0.5,0.6"
    path = tmp_path / "huge.csv"
    path.write_text("\n".join(rows) + "\n")
    trial = read(path)
    assert any("beyond ±1e+09" in w for w in trial.metadata["warnings"])
    write(trial, tmp_path / "out.trc")
    text = (tmp_path / "out.trc").read_text()
    assert "inf" not in text.lower()
    assert np.isnan(read(tmp_path / "out.trc").points[4, 0]).all()


def test_no_real_text_file_has_a_coordinate_near_the_limit():
    files = sorted(realdata_path("opensim_models").rglob("*.trc")) + \
        [REALDATA / "pyomeca" / "markers.trc", REALDATA / "pyomeca" / "markers.csv"]
    for path in files:
        trial = read(path)
        assert not any("beyond" in w for w in trial.metadata["warnings"]), path
        assert not (np.abs(trial.points[np.isfinite(trial.points)]) > MAX_COORDINATE / 1e6).any()
