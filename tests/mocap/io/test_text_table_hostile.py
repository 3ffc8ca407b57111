"""Hostile text files (issue 23): one numeric-cell rule for every text table, headers and
sizes checked before anything is allocated, and the valid variants (a byte-order mark,
CRLF line ends, trailing blanks) read as the plain file.

Each class is run as a new user meets it; every test here failed on the code before
issue 23 (non-finite cells were read as numbers or gaps without a word, a BOM was "not a
TRC file", a header naming 10⁶ markers took seconds and gigabytes)."""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mocap.cli import main
from mocap.errors import MocapError, MocapWarning
from mocap.io import read, write
from mocap.trial import Trial

ROOT = Path(__file__).resolve().parents[3]
BVH = ROOT / "tests" / "data" / "mocapbank_walk.bvh"

FUZZ = settings(max_examples=40, derandomize=True, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow,
                                       HealthCheck.function_scoped_fixture])


def _trial(frames: int = 20, markers: int = 3) -> Trial:
    rng = np.random.default_rng(4)
    points = rng.uniform(0.1, 1.5, (frames, markers, 3))
    return Trial([f"M{i}" for i in range(markers)], points, 100.0)


@pytest.fixture()
def files(tmp_path) -> dict[str, Path]:
    trial = _trial()
    paths = {suffix: tmp_path / f"clean.{suffix}" for suffix in ("trc", "csv")}
    for path in paths.values():
        write(trial, path)
    return paths


def _set_cell(path: Path, target: Path, line: int, column: int, text: str) -> Path:
    """``path`` with cell ``column`` of (1-based) ``line`` replaced by ``text``."""
    lines = path.read_text().split("\n")
    delimiter = "\t" if path.suffix == ".trc" else ","
    cells = lines[line - 1].split(delimiter)
    cells[column] = text
    lines[line - 1] = delimiter.join(cells)
    target.write_text("\n".join(lines))
    return target


def _notes(path: Path) -> tuple[Trial, list[str]]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        trial = read(path)
    return trial, trial.metadata["warnings"]


# ---------------------------------------------------------------- the numeric-cell rule

@pytest.mark.parametrize("suffix, line", [("trc", 12), ("csv", 7)])
@pytest.mark.parametrize("cell", ["inf", "-inf", "1e309", "abc", "--3"])
def test_a_non_finite_or_non_numeric_cell_is_a_missing_sample_with_one_warning(
        files, tmp_path, suffix, line, cell):
    """The sample holding the cell is missing (never a number), the others are as in the
    clean file, and one warning names the line, the count and the text."""
    clean, _ = _notes(files[suffix])
    column = 3 if suffix == "trc" else 2                    # marker 0's y
    trial, notes = _notes(_set_cell(files[suffix], tmp_path / f"bad.{suffix}", line,
                                    column, cell))
    frame = line - (7 if suffix == "trc" else 2)
    assert np.isnan(trial.points[frame, 0]).all()
    expected = clean.points.copy()
    expected[frame, 0] = np.nan
    np.testing.assert_array_equal(trial.points, expected)
    assert [n for n in notes if "finite" in n] == [
        f"1 cell is not a finite number (first at line {line}: {cell!r}); read as a "
        f"missing sample"]


def test_the_numeric_rule_holds_on_the_command_line_and_in_the_compiled_loop(tmp_path,
                                                                          capsys):
    """A table large enough for the compiled loop warns as a small one does; ``info`` shows
    the warning and exits 0."""
    trial = _trial(frames=12000, markers=4)
    path = tmp_path / "big.csv"
    write(trial, path)
    lines = path.read_text().split("\n")
    for number, text in ((5000, "inf"), (9000, "1e999"), (9001, "x1")):
        cells = lines[number - 1].split(",")
        cells[4] = text
        lines[number - 1] = ",".join(cells)
    path.write_text("\n".join(lines))
    assert path.stat().st_size > 1_200_000
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "3 cells are not a finite number (first at line 5000: 'inf')" in out
    assert np.isnan(read(path).points[[4998, 8998, 8999], 1]).all()


def test_a_csv_cut_inside_its_last_number_is_warned(files, tmp_path):
    text = files["csv"].read_text()
    cut = tmp_path / "cut.csv"
    cut.write_text(text.rstrip("\n")[:-4])
    _, notes = _notes(cut)
    assert "the file ends inside line 21, without a line break: if it was cut short, the " \
           "last number of that row may be incomplete" in notes
    assert not [n for n in _notes(files["csv"])[1] if "ends inside" in n]


# ---------------------------------------------------------------- TRC headers

def test_a_trc_numframes_that_is_not_a_number_is_warned(files, tmp_path):
    bad = _set_cell(files["trc"], tmp_path / "n.trc", 3, 2, "abc")
    trial, notes = _notes(bad)
    assert "header NumFrames 'abc' is not a whole number; it was ignored" in notes
    assert trial.frames == 20


def test_a_trc_without_its_axis_line_keeps_its_first_row(files, tmp_path):
    """With line 5 (X1 Y1 Z1) gone, the first row was taken for it and lost without a word."""
    lines = files["trc"].read_text().split("\n")
    for name, kept in (("no5.trc", lines[:4] + lines[6:]),       # no axis line, no blank
                       ("blank5.trc", lines[:4] + lines[5:])):   # no axis line
        path = tmp_path / name
        path.write_text("\n".join(kept))
        trial, notes = _notes(path)
        assert trial.frames == 20, name
        np.testing.assert_array_equal(trial.points, read(files["trc"]).points)
        assert any("line 5" in n and "X1 Y1 Z1" in n for n in notes), notes


# ---------------------------------------------------------------- valid variants

def test_bom_crlf_and_trailing_blanks_read_as_the_plain_file(files, tmp_path):
    """A TRC or BVH starting with a byte-order mark was "not a TRC/BVH file"."""
    sources = dict(files, bvh=BVH)
    for variant in ("bom", "crlf", "bom+crlf", "trailing blanks"):
        for suffix, source in sources.items():
            text = source.read_text()
            if "crlf" in variant:
                text = text.replace("\n", "\r\n")
            if variant == "trailing blanks":
                text = "\n".join(line + "  " for line in text.split("\n"))
            data = text.encode()
            if "bom" in variant:
                data = b"\xef\xbb\xbf" + data
            path = tmp_path / f"v.{suffix}"
            path.write_bytes(data)
            got, plain = read(path), read(source)
            if suffix == "bvh":
                np.testing.assert_array_equal(got.rotations, plain.rotations)
            else:
                np.testing.assert_array_equal(got.points, plain.points)
                assert got.labels == plain.labels and got.rate == plain.rate
            assert got.metadata["warnings"] == plain.metadata["warnings"], (suffix, variant)


# ---------------------------------------------------------------- sizes

def _trc_with_markers(source: Path, target: Path, markers: int) -> Path:
    lines = source.read_text().split("\n")
    lines[3] = "Frame#\tTime\t" + "\t".join(f"M{i}\t\t" for i in range(markers))
    lines[4] = "\t\t" + "\t".join(f"X{i}\tY{i}\tZ{i}" for i in range(1, markers + 1))
    target.write_text("\n".join(lines))
    return target


@pytest.mark.parametrize("kind", ["trc 10^6 markers", "csv 3·10^6 columns",
                                  "garbage after a trc header"])
def test_declared_sizes_beyond_memory_are_one_line_in_well_under_a_second(
        files, tmp_path, capsys, kind):
    if kind.startswith("trc"):
        path = _trc_with_markers(files["trc"], tmp_path / "wide.trc", 1_000_000)
        words = "fewer than one per cell"
    elif kind.startswith("csv"):
        path = tmp_path / "wide.csv"
        path.write_text("time," + ",".join(f"M{i}_{a}" for i in range(1_000_000)
                                           for a in "xyz") + "\n0,1\n0.01,2\n")
        words = "fewer than one per cell"
    else:
        write(_trial(frames=2, markers=60), tmp_path / "full.trc")     # a full-body header
        head = (tmp_path / "full.trc").read_text().split("\n")[:6]
        rng = np.random.default_rng(0)
        garbage = rng.choice(np.frombuffer(b"0123456789.-e\t\n", np.uint8), 6_000_000)
        path = tmp_path / "garbage.trc"
        path.write_bytes("\n".join(head).encode() + b"\n" + garbage.tobytes())
        words = "fewer than one per cell"
    for command in (["info", str(path)], ["convert", str(path), str(tmp_path / "o.c3d")]):
        assert main(command) == 2          # how quickly: benchmarks/hostile.py
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and str(path) in err[0] and words in err[0], err
    assert not (tmp_path / "o.c3d").exists()


def test_the_budget_is_the_environment_s_when_set(files, tmp_path, monkeypatch, capsys):
    """MOCAP_READ_BUDGET_MB sets the budget (here so small the clean file exceeds it); a
    TRC header naming 10⁶ markers over many rows is beyond the default budget."""
    monkeypatch.setenv("MOCAP_READ_BUDGET_MB", "0.001")
    with pytest.raises(MocapError, match="more than the reading budget of 0 MB"):
        read(files["trc"])
    monkeypatch.setenv("MOCAP_READ_BUDGET_MB", "nonsense")
    assert read(files["trc"]).frames == 20
    source = tmp_path / "long.trc"
    write(_trial(frames=400, markers=1), source)
    path = _trc_with_markers(source, tmp_path / "wide.trc", 1_000_000)
    assert main(["info", str(path)]) == 2
    assert "more than the reading budget of 1000 MB" in capsys.readouterr().err


# ---------------------------------------------------------------- properties

CELL = st.one_of(st.sampled_from(["", "nan", "NaN", "-nan", "inf", "-inf", "1e309", "-1e999",
                                  "abc", "--3", "1e", ".", "0x10", "1_0", " 7 ", "\x00"]),
                 st.floats(allow_nan=True, allow_infinity=True).map(repr),
                 st.integers(-10 ** 4, 10 ** 4).map(str))


def _usable(cell: str) -> bool:
    """Whether a cell is a finite number or a gap (empty, NaN), by Python's ``float``."""
    cell = cell.strip(" \t\r")
    try:
        return not cell or not math.isinf(float(cell))
    except ValueError:
        return False


def _read_or_refuse(path: Path, text: str, delimiter: str, data_from: int) -> None:
    """A clean read or one with warnings, or a one-line refusal naming the file; never a
    traceback, never a non-finite number that is not a missing sample, and never a silent
    read of a file whose rows (from line ``data_from``, 0-based) hold an unusable cell."""
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            trial = read(path)
    except MocapError as error:
        assert "\n" not in str(error) and str(path) in str(error)
        return
    assert math.isfinite(trial.rate)
    assert not np.isinf(trial.points).any()
    assert trial.points.shape == (trial.frames, len(trial.labels), 3)
    assert trial.points.nbytes <= 16 * len(text) + 1_000_000
    # a sample is missing as a whole: no half-numbers
    assert (np.isnan(trial.points).all(axis=2) | np.isfinite(trial.points).all(axis=2)).all()
    if not [w for w in caught if issubclass(w.category, MocapWarning)]:
        rows = text.split("\n")[data_from:]
        assert all(_usable(cell) for row in rows for cell in row.split(delimiter)), text


@st.composite
def damaged_text(draw, source: str, delimiter: str, header_lines: int) -> str:
    """``source`` with cells replaced, header cells replaced, lines dropped or the text cut."""
    lines = source.split("\n")
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["cell", "header", "drop", "cut", "crlf"]))
        if kind == "cut":
            text = "\n".join(lines)
            lines = text[:draw(st.integers(0, len(text)))].split("\n")
            continue
        if kind == "crlf":
            lines = [line + "\r" for line in lines]
            continue
        if len(lines) < 2:
            continue
        if kind == "drop":
            del lines[draw(st.integers(0, len(lines) - 1))]
            continue
        top = min(header_lines, len(lines)) - 1 if kind == "header" else len(lines) - 1
        first = 0 if kind == "header" else min(header_lines, top)
        at = draw(st.integers(first, top))
        cells = lines[at].split(delimiter)
        cells[draw(st.integers(0, len(cells) - 1))] = draw(CELL)
        lines[at] = delimiter.join(cells)
    return "\n".join(lines)


@pytest.fixture(scope="module")
def sources(tmp_path_factory) -> dict[str, str]:
    folder = tmp_path_factory.mktemp("sources")
    trial = _trial(frames=6, markers=2)
    out = {}
    for suffix in ("trc", "csv"):
        write(trial, folder / f"s.{suffix}", precision=9 if suffix == "trc" else None,
              **({"units": "m"} if suffix == "trc" else {}))
        out[suffix] = (folder / f"s.{suffix}").read_text()
    return out


@FUZZ
@given(data=st.data())
def test_a_damaged_trc_reads_warns_or_is_refused_in_one_line(data, sources, tmp_path):
    text = data.draw(damaged_text(sources["trc"], "\t", 5))
    path = tmp_path / "d.trc"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))
    _read_or_refuse(path, text, "\t", 5)


@FUZZ
@given(data=st.data())
def test_a_damaged_csv_reads_warns_or_is_refused_in_one_line(data, sources, tmp_path):
    text = data.draw(damaged_text(sources["csv"], ",", 1))
    path = tmp_path / "d.csv"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))
    _read_or_refuse(path, text, ",", 1)


@FUZZ
@given(cells=st.lists(st.tuples(st.integers(0, 5), st.integers(0, 6), CELL), max_size=6))
def test_every_unusable_cell_is_counted_once(cells, sources, tmp_path):
    """Cells that are no finite number are exactly those counted by the warning."""
    lines = sources["csv"].split("\n")
    grid = [line.split(",") for line in lines[1:7]]
    for row, column, text in cells:
        grid[row][column] = text
    path = tmp_path / "c.csv"
    path.write_text("\n".join([lines[0]] + [",".join(r) for r in grid]) + "\n")
    try:
        trial, notes = _notes(path)
    except MocapError as error:
        assert "time" in str(error)         # a time cell made unusable: refused by its line
        return
    unusable = 0
    for row in grid:
        for text in row:
            text = text.strip(" \t\r")
            try:
                value = float(text) if text else math.nan
            except ValueError:
                unusable += 1
                continue
            unusable += math.isinf(value)
    counted = [n for n in notes if "not a finite number" in n]
    if unusable:
        assert len(counted) == 1 and counted[0].startswith(f"{unusable} cell"), counted
    else:
        assert not counted


def test_the_budget_is_said_in_the_help(capsys):
    assert main(["--help"]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "reading budget of 1 GB of numbers (MOCAP_READ_BUDGET_MB sets another)" in out
    assert (ROOT / "docs" / "formats" / "limits.md").exists()


# ---------------------------------------------------------------- a valid variant of anything

def _outcome(read_it) -> tuple:
    """What a reading gives, comparable across files: the arrays and warnings, or the
    refusal's message without the file name."""
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = read_it()
    except MocapError as error:
        assert "\n" not in str(error)
        return ("refused", error.problem)
    notes = sorted([str(w.message).split(": ", 1)[-1] for w in caught]
                   + list(result.metadata.get("warnings", [])))
    arrays = [result.points] if isinstance(result, Trial) else \
        [result.rotations, result.root_translation]
    for array in arrays:
        assert not np.isinf(array).any()
    return ("read", [a.tobytes() for a in arrays], notes)


def _variant(text: str) -> bytes:
    """The same text with a byte-order mark, CRLF line ends and blanks at line ends."""
    return b"\xef\xbb\xbf" + "  \r\n".join(text.split("\n")).encode("utf-8", "surrogatepass")


@FUZZ
@given(data=st.data(), suffix=st.sampled_from(["trc", "csv"]))
def test_a_bom_crlf_variant_of_any_damaged_table_reads_the_same(data, suffix, sources,
                                                                tmp_path):
    text = data.draw(damaged_text(sources[suffix], "\t" if suffix == "trc" else ",",
                                  5 if suffix == "trc" else 1))
    plain, variant = tmp_path / f"p.{suffix}", tmp_path / f"v.{suffix}"
    plain.write_bytes(text.encode("utf-8", "surrogatepass"))
    variant.write_bytes(_variant(text))
    assert _outcome(lambda: read(variant)) == _outcome(lambda: read(plain))


AMC_CELL = st.one_of(CELL, st.sampled_from(["root", "lfemur", "1", "999", ":DEGREES"]))


@FUZZ
@given(edits=st.lists(st.tuples(st.sampled_from(["cell", "drop", "cut"]), st.floats(0, 1),
                                AMC_CELL), min_size=1, max_size=4))
def test_a_damaged_amc_or_bvh_reads_warns_or_is_refused_the_same_as_its_variant(
        edits, tmp_path):
    """ASF/AMC and BVH: random cells, dropped lines and cuts give a finite motion, warnings
    or a one-line refusal, and the byte-order-mark/CRLF variant gives the same."""
    from mocap.io.asfamc import read_asf_amc
    from mocap.io.bvh import read_bvh

    data = ROOT / "tests" / "data"
    asf = tmp_path / "s.asf"
    asf.write_text((data / "cmu_lambada.asf").read_text())
    sources = {"amc": (data / "cmu_lambada.amc").read_text(),
               "bvh": "\n".join(BVH.read_text().split("\n")[:200])}
    for kind, text in sources.items():
        lines = text.split("\n")
        if kind == "bvh":
            frames = sum(1 for line in lines[lines.index("MOTION") + 3:] if line.strip())
            lines = [f"Frames: {frames}" if l.startswith("Frames:") else l for l in lines]
        for what, where, cell in edits:
            at = int(where * (len(lines) - 1))
            if what == "drop" and len(lines) > 1:
                del lines[at]
            elif what == "cut":
                text = "\n".join(lines)
                lines = text[:int(where * len(text))].split("\n")
            elif lines:
                words = lines[at].split(" ")
                words[int(where * 7) % len(words)] = cell
                lines[at] = " ".join(words)
        text = "\n".join(lines)
        plain, variant = tmp_path / f"p.{kind}", tmp_path / f"v.{kind}"
        plain.write_bytes(text.encode("utf-8", "surrogatepass"))
        variant.write_bytes(_variant(text))
        if kind == "amc":
            (tmp_path / "v.asf").write_bytes(_variant(asf.read_text()))
            outcomes = [_outcome(lambda: read_asf_amc(asf, plain)),
                        _outcome(lambda: read_asf_amc(tmp_path / "v.asf", variant))]
        else:
            outcomes = [_outcome(lambda: read_bvh(plain)), _outcome(lambda: read_bvh(variant))]
        assert outcomes[0] == outcomes[1], kind


def test_a_joint_angle_csv_refuses_what_is_no_number_naming_its_line(tmp_path):
    """np.loadtxt read 'inf' and '1e999' in an angle CSV (written by programs only, so
    strict) as infinite angles, without a word; such a cell is refused as a word is, naming
    its line, and an empty cell is still a missing angle."""
    from mocap.io.angles_csv import read_angles_csv

    path = tmp_path / "a.csv"
    for cell, line in (("inf", 3), ("1e999", 3), ("two", 3)):
        path.write_text(f"time,pelvis.Z,pelvis.X,pelvis.Y\n0,1,2,3\n0.01,{cell},2,3\n")
        with pytest.raises(MocapError, match=f"a.csv: 1 cell is not a finite number \\(first "
                                             f"at line {line}: '{cell}'\\): every row must"):
            read_angles_csv(path)
    path.write_text("time,pelvis.Z,pelvis.X,pelvis.Y\n0,1,2,3\n0.01,,2,3\n")
    assert np.isnan(read_angles_csv(path).values[1, 0, 0])
    path.write_text("time,pelvis.Z,pelvis.X,pelvis.Y\n0,1,2,3\nx,1,2,3\n")
    with pytest.raises(MocapError, match="line 3"):
        read_angles_csv(path)
