"""TRC and CSV rows of fewer or more cells than the header names are read with a warning
naming the first such line (found by the hostile re-run of issue 11: such rows were padded
with gaps or cut without a word). Blank cells at the end of a row (a trailing tab, as
OpenSim's Rajagopal and Hamner files end every row) are not cells: no real file warns."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocap.cli import main
from mocap.io import read
from mocap.io.text_table import _parse_compiled, _parse_python, parse_table, read_head
from tests.conftest import REALDATA, realdata_path

RAGGED = "cells where the header names"
SHORT = ("opensim_models", "Pipelines", "Leg39", "leg39_swing_short.trc")   # 14 frames, 41 markers
TEXT_FILES = sorted(
    str(p.relative_to(REALDATA)) for pattern in ("**/*.trc", "**/*.csv")
    for p in REALDATA.glob(pattern) if p.name != "manifest.csv") or ["(no real data)"]


@pytest.mark.parametrize("name", TEXT_FILES)
def test_no_real_trc_or_csv_file_has_ragged_rows(name):
    """Every real TRC and CSV file (4 OpenSim pipelines, a tutorial, pyomeca's Vicon export)
    reads without the warning, though 7 of them end every row with an empty cell; and the
    compiled loop counts each row's cells as the Python one does."""
    path = realdata_path(*Path(name).parts)
    assert not [w for w in read(path).metadata["warnings"] if RAGGED in w]
    if path.suffix == ".trc":
        _, body = read_head(path, 5)
        delimiter = "\t" if b"\t" in body[:1000] else ","
        width = 2 + 3 * len(read(path).labels)
    else:
        return      # the Vicon export is parsed from its lines; its body is checked above
    table, cells = _parse_compiled(body, delimiter, width)
    python_table, python_cells = _parse_python(body.decode(), delimiter, width)
    assert (cells == width).all() and (python_cells == width).all()
    np.testing.assert_array_equal(table, python_table)


def _rows(path: Path) -> tuple[list[str], list[list[str]]]:
    lines = path.read_text().splitlines()
    return lines[:6], [line.split("\t") for line in lines[6:] if line.strip()]


def _write(target: Path, head: list[str], rows: list[list[str]]) -> Path:
    target.write_text("\n".join(head + ["\t".join(row) for row in rows]) + "\n")
    return target


def test_a_short_trc_row_reads_as_gaps_with_a_warning_naming_its_line(tmp_path):
    source = realdata_path(*SHORT)
    head, rows = _rows(source)
    assert head[5] == "" and len(rows[0]) == 125            # line 6 blank, rows from line 7
    rows[3] = rows[3][:5]                                   # Frame#, Time and one marker
    rows[9] = rows[9][:50]
    trial, original = read(_write(tmp_path / "m.trc", head, rows)), read(source)
    notes = [w for w in trial.metadata["warnings"] if RAGGED in w]
    assert notes == ["2 rows have 5 to 50 cells where the header names 125 (first at line "
                     "10); the missing cells read as gaps"]
    np.testing.assert_array_equal(trial.points[3, 0], original.points[3, 0])
    assert np.isnan(trial.points[3, 1:]).all() and np.isnan(trial.points[9, 16:]).all()
    np.testing.assert_array_equal(trial.points[9, :16], original.points[9, :16])
    np.testing.assert_array_equal(trial.points[4:9], original.points[4:9])


def test_a_wide_trc_row_is_cut_with_a_warning_and_trailing_blanks_are_not_cells(tmp_path):
    source = realdata_path(*SHORT)
    head, rows = _rows(source)
    rows = [row + ["", " "] for row in rows]                # blank cells end every row
    assert not [w for w in read(_write(tmp_path / "blank.trc", head, rows))
                .metadata["warnings"] if RAGGED in w]
    rows[0] = rows[0] + ["1", "2", "3", ""]
    trial = read(_write(tmp_path / "m.trc", head, rows))
    assert [w for w in trial.metadata["warnings"] if RAGGED in w] == [
        "1 row has 130 cells where the header names 125 (first at line 7); the cells beyond "
        "the header's were ignored"]
    np.testing.assert_array_equal(trial.points, read(source).points)


def test_the_compiled_loop_counts_cells_as_the_python_one(tmp_path):
    """A table of over 1.2 MB (read by the compiled loop) warns as a small one does, with
    the same line: the real 14 rows repeated 120 times, one row short, one wide."""
    head, rows = _rows(realdata_path(*SHORT))
    rows = rows * 120
    rows[1000] = rows[1000][:20]
    rows[1500] = rows[1500] + ["7"]
    body = "\n\n".join("\t".join(row) for row in rows).encode()   # blank lines between
    assert len(body) > 1_200_000
    notes_fast, notes_small = [], []
    fast = parse_table(body, "\t", 125, notes_fast, first_line=7)
    small, _ = _parse_python(body.decode(), "\t", 125)
    parse_table(b"\n\n".join(body.split(b"\n\n")[999:1501]), "\t", 125, notes_small,
                first_line=7 + 2 * 999)
    np.testing.assert_array_equal(fast, small)
    assert notes_fast == notes_small == [
        "1 row has 20 cells where the header names 125 (first at line 2007); the missing "
        "cells read as gaps",
        "1 row has 126 cells where the header names 125 (first at line 3007); the cells "
        "beyond the header's were ignored"]


def test_csv_rows_of_another_width_warn_on_the_command_line(tmp_path, capsys):
    """This project's CSV layout and a Vicon export (pyomeca's), through ``mocap convert``:
    the warning is one line naming the file, and the conversion goes on (exit 0)."""
    plain = tmp_path / "m.csv"
    plain.write_text("time,A_x,A_y,A_z,B_x,B_y,B_z\n0,1,2,3,4,5,6\n0.01,1,2,3\n"
                     "0.02,1,2,3,4,5,6,9\n")
    assert main(["convert", str(plain), str(tmp_path / "out.trc")]) == 0
    err = capsys.readouterr().err.splitlines()
    assert f"mocap convert: warning: {plain}: 1 row has 4 cells where the header names 7 " \
           f"(first at line 3); the missing cells read as gaps" in err
    assert f"mocap convert: warning: {plain}: 1 row has 8 cells where the header names 7 " \
           f"(first at line 4); the cells beyond the header's were ignored" in err
    lines = realdata_path("pyomeca", "markers.csv").read_text().splitlines()
    lines[7] = ",".join(lines[7].split(",")[:11])
    vicon = tmp_path / "v.csv"
    vicon.write_text("\n".join(lines) + "\n")
    assert main(["convert", str(vicon), str(tmp_path / "v.trc")]) == 0
    err = capsys.readouterr().err
    assert "1 row has 11 cells where the header names 155 (first at line 8)" in err
    assert np.isnan(read(tmp_path / "v.trc").points[2, 3:]).all()
