"""A C3D file whose POINT:USED, POINT:FRAMES or the sign of POINT:SCALE disagrees with the header and the file size
(found by the hostile re-run of issue 11): the reader used the header's counts, rightly, but
without a word, while the opposite disagreement (the header overruled) was reported."""
from __future__ import annotations

import struct

import numpy as np
import pytest

from mocap.io import read
from mocap.io.c3d.layout import inspect_c3d
from tests.conftest import realdata_path

WALK = ("c3dorg_via_c3dio", "sample_00", "Motion_Analysis_Corporation", "Walk1.c3d")


def _set_parameter(data: bytearray, group: str, name: str, value: float) -> None:
    """Overwrite the first value (int16 or float32) of GROUP:NAME in an Intel C3D's
    parameter section."""
    position = (data[0] - 1) * 512 + 4
    groups: dict[int, str] = {}
    while True:
        length, gid = struct.unpack_from("<bb", data, position)
        assert length != 0, f"{group}:{name} not found"
        label = data[position + 2: position + 2 + abs(length)].decode("latin-1").upper()
        at = position + 2 + abs(length)
        step = struct.unpack_from("<h", data, at)[0]
        if gid < 0:
            groups[-gid] = label
        elif groups.get(gid) == group and label == name:
            kind, dims = struct.unpack_from("<bB", data, at + 2)
            assert kind in (2, 4)
            struct.pack_into("<H" if kind == 2 else "<f", data, at + 4 + dims, value)
            return
        position = at + step


@pytest.mark.parametrize("name, value, words", [
    ("USED", 32767, "POINT:USED says 32767 points"),
    ("USED", 1, "POINT:USED says 1 points"),
    ("FRAMES", 0, "POINT:FRAMES says 0 frames"),
    ("FRAMES", 2, "POINT:FRAMES says 2 frames"),
    # a positive scale on a float file: the header's storage wins, now with a word
    ("SCALE", 1e30, "POINT:SCALE 1e+30 disagree on the storage; the header's (float) was used"),
])
def test_an_overruled_count_parameter_is_said(name, value, words, tmp_path):
    source = realdata_path(*WALK)
    data = bytearray(source.read_bytes())
    _set_parameter(data, "POINT", name, value)
    path = tmp_path / "m.c3d"
    path.write_bytes(bytes(data))
    trial, reference = read(path), read(source)
    notes = [w for w in trial.metadata["warnings"] if "says" in w or "disagree" in w]
    assert len(notes) == 1 and words in notes[0], trial.metadata["warnings"]
    assert name == "SCALE" or "the header and the file size say 49 points and 151 frames" \
        in notes[0]
    np.testing.assert_array_equal(trial.points, reference.points)


def test_no_real_c3d_has_an_overruled_count_parameter():
    files = sorted(realdata_path().rglob("*.c3d")) + sorted(realdata_path().rglob("*.C3D"))
    assert len(files) > 90
    for path in files:
        try:
            layout = inspect_c3d(path)
        except Exception:          # files the reader refuses are tested elsewhere
            continue
        assert not [w for w in layout.warnings if "POINT:" in w and " says " in w], path
        assert not [w for w in layout.warnings if "disagree on the storage" in w], path
