"""Property-based fuzzing of the readers (issue 11): C3D, marker CSV, marker-set TOML and
scene TOML.

Whatever the bytes, a reader either returns something sane (a finite, plausible rate; the
shapes its labels promise; no infinities; memory in proportion to the file) or raises
:class:`~mocap.errors.MocapError`: never another exception, never a hang, never a memory
bomb. Seeded (``derandomize``) and bounded (``max_examples``), so the suite is the same
on every run and takes a fixed few seconds in CI.
"""
from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from dynamics.scenes.build import MAX_PARTICLES, build_scene
from dynamics.scenes.schema import SCENES_DIR
from mocap.errors import MocapError
from mocap.io import MAX_RATE_HZ, MIN_RATE_HZ, read, write
from mocap.markersets import parse_markerset
from mocap.markersets.parse import markerset_from_dict
from mocap.synthetic import synthesize_trial
from mocap.trial import Trial

ROOT = Path(__file__).resolve().parents[3]
PRESET = ROOT / "data" / "markersets" / "synthetic15.toml"

FUZZ = settings(max_examples=60, derandomize=True, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow,
                                       HealthCheck.function_scoped_fixture])

#: Values a damaged field takes: the edges of every range.
NASTY_FLOATS = st.sampled_from([0.0, -0.0, -1.0, 1e-30, 1e30, 1e300, math.inf, -math.inf,
                                math.nan, 65535.0, 2.0 ** 31, -2.0 ** 31])
NASTY_INTS = st.sampled_from([0, -1, 1, 2, 255, 32767, 32768, 65535, -32768, 2 ** 31 - 1,
                              2 ** 62, 2 ** 64, -(2 ** 63)])
ANY_VALUE = st.one_of(NASTY_FLOATS, NASTY_INTS, st.text(max_size=8), st.booleans(),
                      st.lists(NASTY_INTS, max_size=4), st.lists(NASTY_FLOATS, max_size=4),
                      st.dictionaries(st.text(max_size=4), NASTY_INTS, max_size=2))


def _sane(trial: Trial, size: int) -> None:
    assert isinstance(trial, Trial)
    assert math.isfinite(trial.rate)
    assert trial.rate == 0 or MIN_RATE_HZ <= trial.rate <= MAX_RATE_HZ
    assert trial.points.shape == (trial.frames, len(trial.labels), 3)
    assert not np.isinf(trial.points).any()
    # no memory bomb: the arrays stay in proportion to the bytes that were read
    assert trial.points.nbytes <= 16 * size + 1_000_000


# ---------------------------------------------------------------- C3D

@pytest.fixture(scope="module")
def c3d_bytes(tmp_path_factory) -> bytes:
    trial, _ = synthesize_trial(0, "walk", seed=1)
    small = Trial(trial.labels[:6], trial.points[:30, :6], trial.rate)
    path = tmp_path_factory.mktemp("fuzz") / "seed.c3d"
    write(small, path)
    return path.read_bytes()


@st.composite
def c3d_mutants(draw, data: bytes) -> bytes:
    buffer = bytearray(data)
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["bytes", "float", "word", "cut"]))
        if kind == "cut":
            buffer = buffer[:draw(st.integers(0, len(buffer)))]
            continue
        if len(buffer) < 8:
            continue
        at = draw(st.integers(0, len(buffer) - 4))
        if kind == "bytes":
            chunk = draw(st.binary(min_size=1, max_size=4))
            buffer[at:at + len(chunk)] = chunk
        elif kind == "float":
            with np.errstate(over="ignore"):
                buffer[at:at + 4] = np.float32(draw(NASTY_FLOATS)).tobytes()
        else:
            buffer[at:at + 2] = (draw(NASTY_INTS) & 0xFFFF).to_bytes(2, "little")
    return bytes(buffer)


@FUZZ
@given(data=st.data())
def test_c3d_reader_returns_sane_trials_or_one_error(data, c3d_bytes, tmp_path):
    mutant = data.draw(c3d_mutants(c3d_bytes))
    path = tmp_path / "mutant.c3d"
    path.write_bytes(mutant)
    try:
        trial = read(path)
    except MocapError as error:
        assert "\n" not in str(error) and str(path) in str(error)
        return
    _sane(trial, len(mutant))


# ---------------------------------------------------------------- marker CSV

CELL = st.one_of(st.sampled_from(["", "nan", "NaN", "inf", "-inf", "1e999", "0", "-0",
                                  "1e-30", "x", " ", "1,5", '"3"']),
                 st.floats(allow_nan=True, allow_infinity=True).map(repr),
                 st.integers(-10 ** 6, 10 ** 6).map(str))


@st.composite
def marker_csvs(draw) -> str:
    if draw(st.booleans()):                                  # plain layout
        labels = draw(st.lists(st.text("ABCxyz_.", min_size=0, max_size=5), max_size=3))
        header = ["time"] + [f"{label}_{axis}" for label in labels for axis in "xyz"]
        if draw(st.booleans()):
            header = draw(st.lists(st.text("timexyz_,", max_size=6), max_size=7))
        width = len(header)
        rows = draw(st.lists(st.lists(CELL, min_size=max(width - 1, 0),
                                      max_size=width + 1), max_size=8))
        return "\n".join([",".join(header)] + [",".join(r) for r in rows]) + "\n"
    rate = draw(CELL)                                         # Vicon Nexus export
    units = draw(st.sampled_from(["mm", "m", "", "furlong"]))
    rows = draw(st.lists(st.lists(CELL, min_size=4, max_size=6), max_size=6))
    return (f"Trajectories\n{rate}\n,,A,,\nFrame,Sub Frame,X,Y,Z\n,,{units},{units},{units}\n"
            + "\n".join(",".join(r) for r in rows) + "\n")


@FUZZ
@given(text=marker_csvs())
def test_csv_reader_returns_sane_trials_or_one_error(text, tmp_path):
    path = tmp_path / "fuzz.csv"
    path.write_text(text)
    try:
        trial = read(path)
    except MocapError as error:
        assert "\n" not in str(error)
        return
    _sane(trial, len(text))


# ---------------------------------------------------------------- TOML documents

def _leaves(document, prefix=()):
    """Paths to every value of a parsed TOML document."""
    if isinstance(document, dict):
        for key, value in document.items():
            yield prefix + (key,)
            yield from _leaves(value, prefix + (key,))
    elif isinstance(document, list):
        for i, value in enumerate(document):
            yield prefix + (i,)
            yield from _leaves(value, prefix + (i,))


@st.composite
def mutated(draw, document: dict) -> dict:
    """``document`` with some values replaced by hostile ones, or removed."""
    document = copy.deepcopy(document)
    paths = list(_leaves(document))
    for _ in range(draw(st.integers(1, 4))):
        where = draw(st.sampled_from(paths))
        parent = document
        try:
            for key in where[:-1]:
                parent = parent[key]
            if draw(st.integers(0, 4)) == 0 and isinstance(parent, dict):
                del parent[where[-1]]
            else:
                parent[where[-1]] = draw(ANY_VALUE)
        except (KeyError, IndexError, TypeError):
            continue                    # an earlier mutation removed the path
    return document


MARKERSET = tomllib.loads(PRESET.read_text())


@settings(FUZZ, max_examples=30)
@given(document=mutated(MARKERSET))
def test_markerset_parser_validates_or_says_what_is_wrong(document):
    try:
        markerset = markerset_from_dict(document, "fuzz.toml")
    except MocapError as error:
        assert "\n" not in str(error)
        return
    assert markerset.segments


@settings(FUZZ, max_examples=12)
@given(depth=st.integers(1, 2100), cycle=st.booleans())
def test_markerset_virtual_chains_of_any_depth_are_quick_and_safe(depth, cycle):
    lines = ['[[segment]]', 'name = "pelvis"', 'markers = ["A", "B", "C"]']
    for i in range(depth):
        source = f"v{depth - 1}" if cycle and i == 0 else (f"v{i - 1}" if i else "A")
        lines += ["[[virtual]]", f'name = "v{i}"', 'type = "midpoint"',
                  f'markers = ["{source}", "B"]']
    try:
        markerset = parse_markerset("\n".join(lines) + "\n", "chain.toml")
    except MocapError as error:
        message = str(error)
        assert (cycle and ("cycle" in message or "itself" in message)) or "at most" in message
        return
    assert not cycle
    names = [v.name for v in markerset.virtual]
    assert names == [f"v{i}" for i in range(depth)]          # inputs before dependants


SCENES = {path.stem: tomllib.loads(path.read_text()) for path in sorted(SCENES_DIR.glob("*.toml"))}


@FUZZ
@given(data=st.data())
def test_scene_builder_validates_or_says_what_is_wrong(data):
    name = data.draw(st.sampled_from(sorted(SCENES)))
    document = data.draw(mutated(SCENES[name]))
    try:
        scene = build_scene(document, f"{name}.toml")
    except MocapError as error:
        assert "\n" not in str(error)
        return
    assert len(scene.system.particles) <= MAX_PARTICLES
    assert scene.dt > 0 and math.isfinite(scene.dt) and scene.steps >= 1
