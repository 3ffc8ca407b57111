"""A stated unit that puts the markers where no capture is (issue 11, found by the second
hostile harness): millimetre coordinates labelled m put a walk kilometres from the origin,
metre coordinates labelled mm put a body inside 2 mm; both were read without a word."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from mocap.io import read
from tests.conftest import realdata_path

LEG = ("opensim_models", "Pipelines", "Leg39", "leg39_swing_short.trc")


def _warnings_of(path) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        trial = read(path)
    return [str(w.message) for w in caught] + list(trial.metadata.get("warnings", []))


def _trc_with_units(tmp_path, units: str):
    lines = realdata_path(*LEG).read_text().split("\n")
    keys, values = lines[1].split("\t"), lines[2].split("\t")
    values[keys.index("Units")] = units
    lines[2] = "\t".join(values)
    path = tmp_path / f"leg_{units}.trc"
    path.write_text("\n".join(lines))
    return path


def test_a_trc_in_mm_labelled_m_warns(tmp_path):
    messages = _warnings_of(_trc_with_units(tmp_path, "m"))
    assert any("stated unit 'm'" in m and "millimetres" in m for m in messages), messages
    assert not any("stated unit" in m for m in _warnings_of(realdata_path(*LEG)))


def test_a_c3d_whose_units_disagree_with_its_values_warns(tmp_path):
    ezc3d = pytest.importorskip("ezc3d")
    rng = np.random.default_rng(0)
    for units, scale, word in (("m", 1000.0, "millimetres"), ("mm", 1.0, "metres")):
        c3d = ezc3d.c3d()
        c3d["parameters"]["POINT"]["RATE"]["value"] = [100.0]
        c3d["parameters"]["POINT"]["LABELS"]["value"] = ["A", "B", "C"]
        c3d["parameters"]["POINT"]["UNITS"]["value"] = [units]
        points = np.ones((4, 3, 50))
        points[:3] = (np.array([0.5, 0.4, 0.9])[:, None, None]
                      + rng.normal(0, 0.05, (3, 3, 50))) * scale      # a body, in m or mm
        c3d["data"]["points"] = points
        path = tmp_path / f"body_{units}.c3d"
        c3d.write(str(path))
        messages = _warnings_of(path)
        assert any(f"stated unit {units!r}" in m and word in m for m in messages), messages


def test_no_real_file_is_said_to_have_a_wrong_unit():
    root = realdata_path()                  # skips on a user's clone, fails under CI
    files = sorted(root.glob("**/*.c3d")) + sorted(root.glob("**/*.trc"))
    assert files, root
    flagged = []
    for path in files:
        try:
            messages = _warnings_of(path)
        except Exception:          # damaged files of the collection: their own tests
            continue
        flagged += [(path.name, m) for m in messages if "stated unit" in m]
    assert flagged == []
