"""Places that stop a write (issue 11, found by the second hostile harness): a disk that
fills part way, a file-size limit, names too long for the file system. Each is one line
naming the file, exit status 2, and no output (whole or partial) left behind.

A full disk is played by RLIMIT_FSIZE (``ulimit -f``) with SIGXFSZ ignored: every write
past the limit fails as it would on a full disk, for any user, without mounting anything.
"""
from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from mocap.cli import main
from mocap.io import write
from mocap.synthetic import synthesize_trial

ROOT = Path(__file__).resolve().parents[2]
BVH = ROOT / "tests" / "data" / "mocapbank_walk.bvh"


@pytest.fixture(scope="module")
def walk(tmp_path_factory) -> Path:
    """A synthetic full-body walk (synthetic15 markers) as C3D."""
    path = tmp_path_factory.mktemp("limits") / "ana_walk.c3d"
    trial, _ = synthesize_trial(0, "walk", seed=3)
    write(trial, path)
    return path


def _run_limited(argv: list[str], cwd: Path, limit: int | None) -> subprocess.CompletedProcess:
    def limited():
        if limit is not None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-m", "mocap", *argv], cwd=cwd, env=env,
                          capture_output=True, text=True, preexec_fn=limited, timeout=300)


@pytest.mark.parametrize("argv", [
    ["convert", "{walk}", "out.c3d"],          # ezc3d's writer: it reports no failed write
    ["convert", "{walk}", "out.trc"],
    ["convert", "{walk}", "out.csv"],
    ["export", "{bvh}", "-f", "c3d", "-o", "out.c3d"],
    ["export", "{bvh}", "-f", "json", "-o", "out.json"],
])
def test_a_write_the_system_stops_part_way_is_one_line_and_leaves_nothing(argv, walk, tmp_path):
    argv = [a.format(walk=walk, bvh=BVH) for a in argv]
    out = tmp_path / argv[-1]
    whole = _run_limited(argv, tmp_path, None)
    assert whole.returncode == 0, whole.stderr
    size = out.stat().st_size
    out.unlink()
    cut = _run_limited(argv, tmp_path, size // 2)
    lines = [line for line in cut.stderr.splitlines() if "warning" not in line]
    assert cut.returncode == 2, cut.stderr
    assert len(lines) == 1 and out.name in lines[0] and "cannot write" in lines[0], lines
    assert "Traceback" not in cut.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []     # no output, no .part


def test_a_name_too_long_for_the_file_system_is_one_line(walk, tmp_path, capsys):
    long = "x" * 300
    assert main(["info", str(tmp_path / f"{long}.c3d")]) == 2
    assert "too long" in capsys.readouterr().err
    assert main(["convert", str(walk), str(tmp_path / f"{long}.trc")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "too long" in err[0], err
    assert list(tmp_path.iterdir()) == []


def test_a_legal_name_near_the_limit_is_written(walk, tmp_path, capsys):
    """250 characters is a legal name; its temporary sibling must fit the limit too."""
    name = "y" * 246 + ".trc"
    assert main(["convert", str(walk), str(tmp_path / name)]) == 0
    assert [p.name for p in tmp_path.iterdir()] == [name]


def _immutable(path: Path) -> bool:
    try:
        return subprocess.run(["chattr", "+i", str(path)], capture_output=True).returncode == 0
    except OSError:
        return False


def test_an_output_the_system_refuses_to_replace_leaves_no_backup(tmp_path, capsys):
    """An existing output the system will not replace (an immutable file): the backup of it
    taken for the all-or-nothing journal was left beside it as '.o.c3d.<pid>-old-….part'."""
    target = tmp_path / "o.c3d"
    target.write_text("user file\n")
    if not _immutable(target):
        pytest.skip("needs chattr +i (root, a file system with the immutable flag)")
    try:
        assert main(["export", str(BVH), "-f", "c3d", "-o", str(target)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "o.c3d" in err[0] and "cannot write" in err[0], err
        assert sorted(p.name for p in tmp_path.iterdir()) == ["o.c3d"]
        assert target.read_text() == "user file\n"
    finally:
        subprocess.run(["chattr", "-i", str(target)])


@pytest.mark.skipif(sys.platform != "linux", reason="a file system that takes any bytes as names")
@pytest.mark.parametrize("argv", [
    ["convert", "{walk}", "{out}.trc"],             # the name goes into the header
    ["convert", "{walk}", "{out}.c3d"],             # ezc3d takes UTF-8 paths only
    ["export", "{bvh}", "-f", "mot", "-o", "{out}.mot"],
    ["export", "{bvh}", "-f", "c3d", "-o", "{out}.c3d"],
])
def test_an_output_name_that_is_not_utf8_is_written(argv, walk, tmp_path, capsys):
    """A Latin-1 name (from an old archive or USB stick): TRC and MOT traced back with
    UnicodeEncodeError, C3D was refused with ezc3d's overload list as the message."""
    out = os.fsdecode(bytes(tmp_path) + b"/caf\xe9")
    argv = [a.format(walk=walk, bvh=BVH, out=out) for a in argv]
    done = _run_limited(argv, tmp_path, None)      # a real process: its stderr escapes names
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr
    written = Path(argv[-1])
    assert [p.name for p in tmp_path.iterdir()] == [written.name]
    if written.suffix != ".mot":
        back = _run_limited(["info", "--json", str(written)], tmp_path, None)
        assert back.returncode == 0, back.stderr
