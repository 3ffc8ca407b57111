"""TRC and CSV text: NaN cells, precision, time base, up axis, labels that would corrupt."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.cli import main
from mocap.errors import MocapError
from mocap.io import read, write
from mocap.io.text_table import parse_table
from mocap.io.text_format import format_table
from mocap.trial import Trial
from tests.conftest import realdata_path


def _trial(labels=("A", "B"), frames=4):
    rng = np.random.default_rng(3)
    points = rng.uniform(-2, 2, (frames, len(labels), 3))
    points[1, 1] = np.nan                                  # a gap at the end of a row
    return Trial(list(labels), points, 50.0)


def test_gap_at_the_end_of_a_row_is_written_nan_not_empty(tmp_path):
    write(_trial(), tmp_path / "t.trc")
    row = (tmp_path / "t.trc").read_text().splitlines()[7].split("\t")
    assert row[-3:] == ["NaN", "NaN", "NaN"] and len(row) == 2 + 6


def test_parse_table_equals_python_float_and_keeps_empty_and_words_missing():
    rng = np.random.default_rng(0)
    values = rng.normal(0, 1, (300, 7)) * 10.0 ** rng.integers(-12, 12, (300, 7))
    text = "\n".join("\t".join(repr(v) for v in row) for row in values.tolist()) + "\n"
    np.testing.assert_array_equal(parse_table(text, "\t", 7), values)       # exact
    notes = []
    odd = parse_table(b"1,,x, 2.5 ,NaN,1e400,-0.0\n\n3\r\n", ",", 7, notes)
    # 1e400 is no finite number: missing, as the word is (issue 23: it was read as inf)
    assert odd.shape == (2, 7) and odd[0, 3] == 2.5 and odd[0, 6] == 0.0
    assert np.isnan(odd[0, [1, 2, 4, 5]]).all() and np.isnan(odd[1, 1:]).all()
    assert "2 cells are not a finite number (first at line 1: 'x')" in notes[-1]
    fixed = format_table(np.array([[1.23456789, -0.0000004, np.nan, 7.0]]), [3, 6, 2, 0], ",")
    assert fixed == "1.235,0.000000,NaN,7\n"          # no "-0" after rounding


@pytest.mark.parametrize("units, places, worst", [("mm", None, 5e-10), ("m", None, 5e-10),
                                                  ("mm", 3, 5e-7), ("m", 6, 5e-7)])
def test_precision_is_decimals_in_the_files_unit(tmp_path, units, places, worst):
    trial = _trial(frames=50)
    write(trial, tmp_path / "p.trc", units=units, precision=places)
    error = np.nanmax(np.abs(read(tmp_path / "p.trc").points - trial.points))
    assert worst / 10 < error <= worst * 1.000001


def test_precision_coarser_than_a_micrometre_is_refused(tmp_path):
    with pytest.raises(MocapError, match="coarser than 1 µm"):
        write(_trial(), tmp_path / "p.trc", units="m", precision=5)
    write(_trial(), tmp_path / "a.trc")
    assert main(["convert", str(tmp_path / "a.trc"), str(tmp_path / "b.trc"),
                 "--precision", "2"]) == 2
    assert main(["convert", str(tmp_path / "a.trc"), str(tmp_path / "b.c3d"),
                 "--precision", "6"]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.trc"]


@pytest.mark.parametrize("label, suffix", [("LA\nSI", ".trc"), ("LA\rSI", ".csv"),
                                           ("LA,SI", ".csv"), ("LA\tSI", ".trc"),
                                           ("LA\nSI", ".csv")])
def test_labels_that_would_corrupt_a_text_file_are_refused(tmp_path, label, suffix):
    bad = tmp_path / "bad.c3d"
    write(Trial([label, "B"], _trial().points, 50.0), bad)     # C3D holds any text
    out = tmp_path / f"out{suffix}"
    assert main(["convert", str(bad), str(out)]) == 2
    assert not out.exists()


def test_unlabelled_trc_columns_are_named_not_dropped(tmp_path):
    path = tmp_path / "u.trc"
    path.write_text("PathFileType\t4\t(X/Y/Z)\tu.trc\nDataRate\tCameraRate\tNumFrames\t"
                    "NumMarkers\tUnits\n100\t100\t2\t2\tmm\nFrame#\tTime\n\t\tX1\tY1\tZ1\tX2\tY2\t"
                    "Z2\n\n1\t0\t1\t2\t3\t4\t5\t6\n2\t0.01\t1\t2\t3\t4\t5\t7\n")
    trial = read(path)
    assert trial.labels == ["M001", "M002"]
    assert any("no label on line 4" in w for w in trial.metadata["warnings"])
    np.testing.assert_allclose(trial.points[1, 1], [0.004, 0.005, 0.007])
    path.write_text("PathFileType\t4\t(X/Y/Z)\tu.trc\nDataRate\tNumFrames\n100\t1\n"
                    "Frame#\tTime\n\n\n1\t0\n")
    with pytest.raises(MocapError, match="no marker columns"):
        read(path)


def test_c3d_to_trc_keeps_the_first_frame_and_up_y_turns_the_lab(tmp_path):
    source = realdata_path("pycgm", "Test_Files", "Movement_trial.c3d")
    trial = read(source)
    assert trial.first_frame == 695
    assert main(["convert", str(source), str(tmp_path / "z.trc")]) == 0
    assert main(["convert", str(source), str(tmp_path / "y.trc"), "--up", "y"]) == 0
    z, y = read(tmp_path / "z.trc"), read(tmp_path / "y.trc")
    numbers, times = z.time_base()
    assert numbers[0] == 695 and times[0] == pytest.approx(694 / 120.0)
    lines = (tmp_path / "z.trc").read_text().splitlines()
    assert lines[2].split("\t")[6] == "695"                     # OrigDataStartFrame
    # Y up: (x, y, z) -> (x, z, -y): height is the second coordinate
    np.testing.assert_allclose(y.points, np.stack([z.points[..., 0], z.points[..., 2],
                                                   -z.points[..., 1]], axis=-1), atol=2e-9)


def test_c3d_rewrite_says_in_one_line_what_it_could_not_keep(tmp_path, capsys):
    source = realdata_path("pycgm", "Test_Files", "Movement_trial.c3d")
    assert main(["convert", str(source), str(tmp_path / "copy.c3d")]) == 0
    notes = [line for line in capsys.readouterr().err.splitlines() if line.startswith("note")]
    # Vicon's axis points and centre of mass are model outputs too (mocap.io.c3d.outputs):
    # a conversion keeps the markers only and says what it left
    assert notes == ["note: not kept in copy.c3d: 78 computed positions (axis points, centre "
                     "of mass); 80 modelled points (angles, forces …)"]
    back = read(tmp_path / "copy.c3d")
    assert back.first_frame == 695
    assert int(back.parameters["FORCE_PLATFORM"]["USED"][0]) == 4


def test_compiled_and_python_paths_agree(monkeypatch):
    """Large tables go to the numba reader and the numpy writer, small ones to Python: the
    same numbers."""
    from mocap.io import text_table

    rng = np.random.default_rng(5)
    values = rng.normal(0, 1, (400, 9)) * 10.0 ** rng.integers(-8, 8, (400, 9))
    values[rng.random(values.shape) < 0.1] = np.nan
    text = "\n".join("\t".join("" if v != v else repr(v) for v in row)
                     for row in values.tolist()) + "\n\n \t\n"
    python = parse_table(text, "\t", 10)
    fixed_python = format_table(values, 6, ",")
    monkeypatch.setattr(text_table, "COMPILED_ABOVE", 0)
    compiled = parse_table(text, "\t", 10)
    np.testing.assert_array_equal(compiled, python)              # both exact, NaN alike
    assert python.shape == (400, 10) and np.isnan(python[:, 9]).all()
    fixed_compiled = format_table(values, 6, ",")
    a, b = parse_table(fixed_python, ",", 9), parse_table(fixed_compiled, ",", 9)
    np.testing.assert_array_equal(np.isnan(a), np.isnan(values))
    assert fixed_compiled == fixed_python
    np.testing.assert_allclose(a, values, rtol=1e-15, atol=5.000001e-7)


@pytest.mark.parametrize("huge", [False, True])
def test_small_and_large_tables_round_a_tie_alike(huge):
    """A tie (x.5 units of the last place, exact in binary) is rounded away from zero in a
    table of 4 cells, of 400 000 cells, and cell by cell in Python when one cell is beyond
    the whole-array writer's limit: small tables rounded half to even, large ones half up
    (found by the hostile re-run of issue 11)."""
    from mocap.io.text_table import COMPILED_ABOVE

    ties = np.array([[0.125, 2.5, -2.5, 0.375, -0.0625, 1e-7, 0.5]])
    places = [2, 0, 0, 2, 3, 6, 0]
    expected = "0.13,3,-3,0.38,-0.063,0.000000,1\n"
    if huge:                    # 1e20 at 0 places: beyond the limit, so all in Python
        ties, places, expected = np.hstack([ties, [[1e20]]]), places + [0], \
            expected[:-1] + ",100000000000000000000\n"
    assert format_table(ties, places, ",") == expected
    large = np.repeat(ties, COMPILED_ABOVE // ties.shape[1] + 1, axis=0)
    assert large.size > COMPILED_ABOVE
    assert format_table(large, places, ",") == expected * large.shape[0]


@pytest.mark.parametrize("huge", [False, True])
def test_write_table_writes_format_tables_bytes_block_by_block(tmp_path, monkeypatch, huge):
    """Streaming columns side by side gives the bytes of the whole table formatted at once,
    through the compiled loop, or through Python when one cell is beyond the loop's limit."""
    import io

    from mocap.io import text_format

    monkeypatch.setattr(text_format, "WRITE_BLOCK_ROWS", 700)
    rng = np.random.default_rng(8)
    times = np.arange(2000) / 100.0
    values = rng.normal(0, 50, (2000, 60))
    values[rng.random(values.shape) < 0.05] = np.nan
    if huge:
        values[1500, 7] = 2e10                  # >= 9e15 millionths: the Python path
    handle = io.BytesIO()
    text_format.write_table(handle, [times, values], 6, ",", nan="")
    expected = format_table(np.column_stack([times, values]), 6, ",", nan="", as_bytes=True)
    assert handle.getvalue() == expected
    assert handle.getvalue().count(b"\n") == 2000 and (b"20000000000.000000" in expected) == huge


def _hand_rule(value: float, places: int, nan: str) -> str:
    """The large-table rule written out cell by cell: u = floor(|x| 10^p + 0.5) units of
    the last place, ``[-]u // 10^p . u % 10^p`` (p digits), no sign when u is 0."""
    if value != value:
        return nan
    units = int(np.floor(abs(value) * 10.0 ** places + 0.5))
    sign = "-" if value < 0 and units else ""
    whole, fraction = divmod(units, 10 ** places)
    return f"{sign}{whole}" + (f".{fraction:0{places}d}" if places else "")


@pytest.mark.parametrize("nan", ["", "NaN"])
def test_large_tables_are_written_to_the_rounding_rule_cell_by_cell(nan):
    """The whole-array writer (8 digits per integer operation, one record per cell) gives
    the hand rule's text for every cell: ties, -0, NaN, 0-15 places, integer parts of 1 to
    16 digits, columns of different places side by side."""
    from mocap.io.text_format import WRITE_BLOCK_ROWS, _format_block

    rng = np.random.default_rng(11)
    for trial in range(60):
        rows = int(rng.integers(1, 2 * WRITE_BLOCK_ROWS)) if trial < 4 else \
            int(rng.integers(1, 40))
        cols = int(rng.integers(1, 9))
        places = rng.integers(0, 16, cols) if trial % 2 else np.full(cols, rng.integers(0, 16))
        values = rng.normal(0, 1, (rows, cols)) * 10.0 ** rng.integers(-9, 16, (rows, cols))
        values = values / 10.0 ** places                        # mostly below the limit
        ties = rng.random(values.shape) < 0.15
        values[ties] = (rng.integers(-10 ** 7, 10 ** 7, ties.sum()) + 0.5) \
            / 10.0 ** rng.integers(0, 9, ties.sum())
        values[rng.random(values.shape) < 0.05] = -0.0
        values[rng.random(values.shape) < 0.05] = -1e-12
        values[rng.random(values.shape) < 0.1] = np.nan
        limit = 9.0e15 / 10.0 ** places
        values[np.abs(values) >= limit] = np.nan                # else the Python path
        expected = "".join(",".join(_hand_rule(v, int(p), nan) for v, p in zip(row, places))
                           + "\n" for row in values.tolist())
        assert _format_block(values, places, ",", nan == "NaN") == expected.encode(), trial
