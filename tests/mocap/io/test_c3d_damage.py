"""Seeded damage of real and synthetic C3D files never crashes or hangs the reader.

Each damaged copy (truncation at structural and random offsets, single bit
flips, absurd header fields) is read in a child process with a timeout, so a
segmentation fault or a hang shows up as a failure of this test rather than
killing pytest. Every read must end in a clear MocapError or a load; a
truncated file may load only when the cut fell in the padding after the data
(a full load) or exactly on a frame boundary (a load that says so).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mocap.errors import MocapError
from mocap.io import read, write
from tests.conftest import realdata_path
from tests.mocap.io.damage import bit_flip_variants, header_field_variants, truncation_variants
from tests.mocap.io.test_roundtrip import synthetic_trial

ROOT = Path(__file__).resolve().parents[3]
#: Seconds for one child process to read all variants of one source file.
TIMEOUT = 120

SOURCES = {
    "synthetic": None,                                                  # written by us
    "intel-int": "c3dorg_via_c3dio/sample_02/pc_int.c3d",
    "sgi-int": "c3dorg_via_c3dio/sample_02/sgi_int.c3d",
    "dec-float": "c3dorg_via_c3dio/sample_02/dec_real.c3d",
    "qualisys-float-analog": "c3dorg_via_c3dio/sample_26/Capture0004.c3d",
    "bts-odd-layout": "c3dorg_via_c3dio/sample_28/type1.C3D",
}


def _source_bytes(name: str, tmp_path: Path) -> bytes:
    if SOURCES[name] is None:
        path = tmp_path / "synthetic.c3d"
        write(synthetic_trial(frames=80), path)
        return path.read_bytes()
    return realdata_path(SOURCES[name]).read_bytes()


def _read_in_child(paths: list[Path]) -> list[dict]:
    """Results of reading ``paths`` in a child process; fails on a crash or hang."""
    try:
        completed = subprocess.run(
            [sys.executable, "-m", "tests.mocap.io.damage", *map(str, paths)],
            cwd=ROOT, capture_output=True, text=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired as expired:
        started = [json.loads(line)["start"] for line in (expired.stdout or b"").decode()
                   .splitlines() if '"start"' in line]
        pytest.fail(f"reader hung (> {TIMEOUT} s); last file started: "
                    f"{started[-1] if started else '?'}")
    lines = [json.loads(line) for line in completed.stdout.splitlines()]
    results = [line for line in lines if "status" in line]
    if completed.returncode != 0 or len(results) != len(paths):
        started = [line["start"] for line in lines if "start" in line]
        pytest.fail(f"reader process died (status {completed.returncode}) on "
                    f"{started[-1] if started else '?'}: {completed.stderr[-500:]}")
    return results


@pytest.mark.parametrize("source", list(SOURCES))
def test_damaged_c3d_ends_in_a_clear_error_or_a_correct_load(source, tmp_path):
    original = _source_bytes(source, tmp_path)
    (tmp_path / "original.c3d").write_bytes(original)
    reference = read(tmp_path / "original.c3d")
    rng = np.random.default_rng(2026)
    variants = (header_field_variants(original) + truncation_variants(original, rng, 25)
                + bit_flip_variants(original, rng, 60))
    paths = []
    for name, data in variants:
        path = tmp_path / f"{name}.c3d"
        path.write_bytes(data)
        paths.append(path)
    results = _read_in_child(paths)

    outcomes = {"ok": 0, "error": 0}
    for (name, data), result in zip(variants, results):
        assert result["status"] in outcomes, f"{name}: {result}"
        outcomes[result["status"]] += 1
        if result["status"] == "error":
            assert result["path"] in result["message"], result
            continue
        assert result["finite"], f"{name}: non-finite coordinates loaded"
        if name.startswith("truncated-"):
            complete = result["frames"] == reference.frames
            said_so = any("truncated" in warning for warning in result["warnings"])
            assert complete or said_so, f"{name}: half-read silently ({result['frames']} " \
                                        f"of {reference.frames} frames)"
    # The damage must be detected, not just survived.
    assert outcomes["error"] >= len(variants) // 4, outcomes


def test_damage_messages_name_the_problem(tmp_path):
    path = tmp_path / "t.c3d"
    write(synthetic_trial(frames=80), path)
    data = path.read_bytes()

    def message(damaged: bytes) -> str:
        target = tmp_path / "damaged.c3d"
        target.write_bytes(damaged)
        with pytest.raises(MocapError) as caught:
            read(target)
        assert str(target) in str(caught.value)
        return caught.value.problem

    assert "truncated" in message(data[:len(data) - 700])
    assert "not a C3D file" in message(b"\x02\x51" + data[2:])
    assert "parameter section starts at block" in message(b"\x00" + data[1:])
    processor_at = (data[0] - 1) * 512 + 3
    assert "unknown processor type" in message(
        data[:processor_at] + b"\x07" + data[processor_at + 1:])
    # An absurd header count that the parameters and the file size overrule
    # loads, and says so; one that nothing confirms is an error.
    absurd_points = bytearray(data)
    absurd_points[2:4] = (65535).to_bytes(2, "little")
    (tmp_path / "points.c3d").write_bytes(absurd_points)
    trial = read(tmp_path / "points.c3d")
    assert len(trial.labels) == 5
    assert any("header says 65535 points" in w for w in trial.metadata["warnings"])
    absurd_frames = bytearray(data)
    absurd_frames[8:10] = (65535).to_bytes(2, "little")
    frames_at = data.index(b"FRAMES") + 6 + 2 + 2          # name, offset, type + dims
    absurd_frames[frames_at:frames_at + 2] = (30000).to_bytes(2, "little")
    assert "truncated" in message(bytes(absurd_frames))
    assert "only 100 bytes" in message(data[:100])


def test_known_broken_real_file_is_rejected_before_any_library_touches_it():
    with pytest.raises(MocapError, match="parameter section is corrupt"):
        read(realdata_path("c3dorg_via_c3dio/sample_18/bad_parameter_section.c3d"))
