"""C3D parameters that contradict each other are named in a warning (issue 23: a second
POINT:LABELS overriding the first, and a header scale of 0 beside POINT:SCALE, were read
without a word)."""
from __future__ import annotations

import struct
import warnings
from pathlib import Path

import numpy as np

from mocap.cli import main
from mocap.io import read, write
from mocap.trial import Trial


def _c3d(path: Path) -> bytes:
    rng = np.random.default_rng(2)
    write(Trial(["A", "B", "C"], rng.uniform(0.1, 1.0, (40, 3, 3)), 100.0), path)
    return path.read_bytes()


def _read(path: Path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read(path)


def test_a_parameter_defined_twice_is_named(tmp_path, capsys):
    """POINT:FRAMES renamed LABELS (same length): a second POINT:LABELS after the first."""
    data = _c3d(tmp_path / "clean.c3d")
    start = (data[0] - 1) * 512
    at = data.index(b"FRAMES", start)
    assert data.index(b"LABELS", start) < at               # the second one overrides
    path = tmp_path / "twice.c3d"
    path.write_bytes(data[:at] + b"LABELS" + data[at + 6:])
    trial = _read(path)
    assert "parameter POINT:LABELS is defined twice; the second definition overrides the " \
           "first" in trial.metadata["warnings"]
    assert main(["info", str(path)]) == 0
    assert "POINT:LABELS is defined twice" in capsys.readouterr().out
    assert not [w for w in _read(tmp_path / "clean.c3d").metadata["warnings"] if "twice" in w]


def test_a_header_scale_of_zero_beside_point_scale_is_named(tmp_path):
    data = bytearray(_c3d(tmp_path / "clean.c3d"))
    data[12:16] = struct.pack("<f", 0.0)                    # header words 7-8: the scale
    path = tmp_path / "zero.c3d"
    path.write_bytes(bytes(data))
    trial, clean = _read(path), _read(tmp_path / "clean.c3d")
    assert [w for w in trial.metadata["warnings"] if "scale" in w] == [
        "the header's scale factor is 0; POINT:SCALE -1 was used (float storage)"]
    np.testing.assert_array_equal(trial.points, clean.points)
