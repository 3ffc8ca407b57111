"""Every TOML the commands read (scene, marker set, joint map, segment hierarchy) refuses a
pathologically nested document with one MocapError naming the file: the standard library's
parser recursed once per level and a 3000-deep inline table gave a RecursionError traceback
(found by the hostile re-run of issue 11)."""
from __future__ import annotations

import pytest

from dynamics.scenes.schema import read_scene_document
from mocap.body.segments import read_joint_map
from mocap.errors import MocapError
from mocap.io.c3d.rotations import load_parents
from mocap.tomlfile import TOML_MAX_DEPTH, parse_toml
from mocap.markersets.parse import load_markerset

READERS = {"scene": read_scene_document, "marker set": load_markerset,
           "joint map": read_joint_map, "hierarchy": load_parents}
DEEP = {"inline tables": "x = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n",
        "arrays": "x = " + "[" * 5000 + "]" * 5000 + "\n"}


@pytest.mark.parametrize("reader", READERS)
@pytest.mark.parametrize("kind", DEEP)
def test_deep_toml_is_one_line_naming_the_file(tmp_path, reader, kind):
    path = tmp_path / "deep.toml"
    path.write_text(DEEP[kind])
    with pytest.raises(MocapError) as caught:
        READERS[reader](path)
    message = str(caught.value)
    assert "deep.toml" in message and "\n" not in message
    assert "nested" in message


def test_nesting_limit_is_exact_and_ordinary_documents_parse():
    at_limit = "x = " + "[" * TOML_MAX_DEPTH + "]" * TOML_MAX_DEPTH
    assert parse_toml(at_limit)["x"] is not None
    with pytest.raises(MocapError, match="nested more than"):
        parse_toml("x = " + "[" * (TOML_MAX_DEPTH + 1) + "]" * (TOML_MAX_DEPTH + 1))
    document = parse_toml('[simulation]\ndt = 0.01\n[[rigid]]\nsize = [0.3, 0.1, 0.04]\n'
                          'name = "a [bracket] in a string"\n')
    assert document["simulation"]["dt"] == 0.01 and document["rigid"][0]["size"][0] == 0.3
