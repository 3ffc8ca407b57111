"""Motion files as users meet them on the command line: bad input is one line and exit 2;
--joint-map, units printed, BVH export for Blender (--out-units, --round-rate)."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from mocap.cli import main
from mocap.io.bvh import read_bvh
from mocap.body.retarget import reduce_to_segments
from mocap.body.segments import BODY_SEGMENTS
from tests.mocap.io.test_bvh_hostile import SMALL

DATA = Path(__file__).resolve().parents[1] / "data"
#: A rig whose names say nothing (b0 … b6).
UNNAMED = SMALL.replace("ROOT Hips", "ROOT b0").replace("JOINT LeftUpLeg", "JOINT b1") \
    .replace("JOINT LeftLeg", "JOINT b2").replace("JOINT Spine", "JOINT b3")


def _run(capsys, *argv) -> tuple[int, str, str]:
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


def _one_line_error(err: str, path: Path, words: str) -> None:
    lines = [line for line in err.splitlines() if "error" in line]
    assert len(lines) == 1 and str(path) in lines[0] and words in lines[0], err
    assert "Traceback" not in err


@pytest.mark.parametrize("name, text, words", [
    ("channels.bvh", SMALL.replace("CHANNELS 3 Zrotation Xrotation Yrotation\n    End",
                                   "CHANNELS 2 Zrotation Xrotation\n    End"),
     "the hierarchy declares 14 channels"),
    ("truncated.bvh", SMALL[: SMALL.rindex("2.0 95.0")], "truncated"),
    ("unnamed.bvh", UNNAMED, "cannot map the skeleton onto the body model: missing"),
])
def test_bad_motion_files_are_one_line_and_exit_2(tmp_path, capsys, name, text, words):
    path = tmp_path / name
    path.write_text(text)
    out = tmp_path / "out.bvh"
    status, _, err = _run(capsys, "export", path, "--format", "bvh", "--body", "-o", out)
    assert status == 2
    _one_line_error(err, path, words)
    assert not out.exists()


def test_amc_without_its_asf_is_one_line_and_exit_2(tmp_path, capsys):
    amc = tmp_path / "HDM_bd_01-01_01_120.amc"
    amc.write_text((DATA / "cmu_lambada.amc").read_text())
    status, _, err = _run(capsys, "export", amc, "--format", "json", "-o", tmp_path / "o.json")
    assert status == 2
    _one_line_error(err, amc, "no ASF skeleton found")
    assert "HDM_bd.asf" in err
    # With the HDM05-style skeleton name beside it, the AMC finds it.
    (tmp_path / "HDM_bd.asf").write_text((DATA / "cmu_lambada.asf").read_text())
    status, _, err = _run(capsys, "export", amc, "--format", "json", "-o", tmp_path / "o.json")
    assert status == 0 and "units: in" in err


def test_joint_map_makes_an_unnamed_rig_usable(tmp_path, capsys):
    """The mocapbank walk with its joints renamed j0, j1 …: unmappable by name, mapped by
    a joint map, and then on the body exactly as the named original."""
    source = DATA / "mocapbank_walk.bvh"
    named = read_bvh(source)
    text = source.read_text()
    for k, name in sorted(enumerate(named.names), key=lambda item: -len(item[1])):
        text = re.sub(rf"(ROOT|JOINT) {name}\b", rf"\1 j{k}", text)
    path = tmp_path / "renamed.bvh"
    path.write_text(text)
    out = tmp_path / "body.bvh"
    status, _, err = _run(capsys, "export", path, "--format", "bvh", "--body", "-o", out)
    assert status == 2
    _one_line_error(err, path, "cannot map the skeleton onto the body model")
    expected = reduce_to_segments(named)
    mapping = tmp_path / "map.toml"
    mapping.write_text("".join(f'{segment} = "j{named.names.index(joint)}"\n'
                               for segment, joint in expected.metadata["segment_map"].items()))
    status, _, err = _run(capsys, "export", path, "--format", "bvh", "--body",
                          "--joint-map", mapping, "-o", out)
    assert status == 0, err
    body = read_bvh(out)
    assert body.names == BODY_SEGMENTS
    np.testing.assert_allclose(body.forward_kinematics()[1], expected.forward_kinematics()[1],
                               atol=1e-7)
    mapping.write_text('l_thigh = "nosuch"\n')
    status, _, err = _run(capsys, "export", path, "--format", "bvh", "--body",
                          "--joint-map", mapping, "-o", out)
    assert status == 2
    _one_line_error(err, path, "no such joint")


def test_export_bvh_for_blender_in_metres_with_the_rate_kept_or_rounded(tmp_path, capsys):
    source = DATA / "mocapbank_walk.bvh"
    out = tmp_path / "walk_m.bvh"
    status, _, err = _run(capsys, "export", source, "--format", "bvh", "--out-units", "m",
                          "-o", out)
    assert status == 0
    assert "units: cm (detected from a standing height of" in err
    original, metres = read_bvh(source), read_bvh(out)
    assert metres.metadata["units"] == "m"
    assert "Frame Time:\t0.033333" in source.read_text() and "Frame Time: 0.033333\n" in \
        out.read_text()
    np.testing.assert_allclose(metres.forward_kinematics()[1],
                               original.forward_kinematics()[1], atol=1e-6)
    # The input unit can be overridden: the file read as metres is 100× larger.
    status, _, err = _run(capsys, "export", source, "--units", "m", "--format", "bvh",
                          "--out-units", "cm", "-o", tmp_path / "big.bvh")
    assert status == 0 and "units: m (as given" in err
    big = read_bvh(tmp_path / "big.bvh", units="cm")
    np.testing.assert_allclose(big.skeleton.offsets, original.skeleton.offsets * 100,
                               atol=1e-4)
    status, _, err = _run(capsys, "export", source, "--format", "csv", "--out-units", "m",
                          "-o", tmp_path / "a.csv")
    assert status == 2 and "--format bvh only" in err


def test_motion_lines_beyond_the_stated_frames_are_a_warning(tmp_path, capsys):
    path = tmp_path / "extra.bvh"
    path.write_text(SMALL + SMALL.splitlines()[-1] + "\n")
    status, _, err = _run(capsys, "export", path, "--format", "json", "-o", tmp_path / "o.json")
    assert status == 0
    assert "warning:" in err and "1 motion lines after the 3 frames" in err


def test_decompose_takes_a_joint_map_for_a_renamed_rig(tmp_path, capsys):
    """Four bandai2 takes (2 styles × 2 contents) with their joints renamed j0, j1 …: on the
    body, decompose refuses them in one line, and reads them with a joint map."""
    from tests.conftest import realdata_path

    folder = tmp_path / "corpus"
    folder.mkdir()
    names = None
    for style in ("active", "normal"):
        for content in ("walk", "run"):
            source = realdata_path("bandai2", f"dataset-2_{content}_{style}_001.bvh")
            if names is None:
                names = read_bvh(source).names
            text = source.read_text()
            for k, name in sorted(enumerate(names), key=lambda item: -len(item[1])):
                text = re.sub(rf"(ROOT|JOINT) {name}\b", rf"\1 j{k}", text)
            (folder / f"{style}_{content}_001.bvh").write_text(text)
    model = tmp_path / "model.npz"
    status, _, err = _run(capsys, "decompose", folder, "--body", "-o", model)
    assert status == 2 and "cannot map the skeleton" in err and not model.exists()
    segments = {"pelvis": "Hips", "thorax": "Chest", "head": "Head"}
    for side, suffix in (("l", "_L"), ("r", "_R")):
        for segment, joint in (("upperarm", "UpperArm"), ("forearm", "LowerArm"),
                               ("hand", "Hand"), ("thigh", "UpperLeg"), ("shank", "LowerLeg"),
                               ("foot", "Foot")):
            segments[f"{side}_{segment}"] = joint + suffix
    mapping = tmp_path / "map.toml"
    mapping.write_text("".join(f'{s} = "j{names.index(j)}"\n' for s, j in segments.items()))
    status, _, err = _run(capsys, "decompose", folder, "--body", "--joint-map", mapping,
                          "-o", model)
    assert status == 0, err
    assert model.exists()
