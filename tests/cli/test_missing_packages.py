"""A command whose package is not installed says so in one line (exit 2, nothing written),
and the core commands (info, convert, angles) run without the heavy packages at all.

Each run is a fresh interpreter in which the named packages cannot be imported: a finder
placed first on ``sys.meta_path`` raises the ModuleNotFoundError Python raises for a package
that is not installed (same class, same ``name``), before any of them is loaded.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import realdata_path

ROOT = Path(__file__).resolve().parents[2]
#: A fresh interpreter lacking the packages named in argv[1] (comma-separated), then mocap.
RUNNER = """
import importlib.abc, sys
absent = set(sys.argv[1].split(","))
class Absent(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in absent:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
sys.meta_path.insert(0, Absent())
from mocap.cli import main
status = main(sys.argv[2:])
assert not absent & {m.split(".")[0] for m in sys.modules}, "a blocked package was loaded"
sys.exit(status)
"""
#: What the core commands never need (the synthesis, dynamics and plotting stacks).
HEAVY = "pinocchio,tensorly,matplotlib,PIL,dask,pandas,opensim,bvhio"


def mocap_without(absent: str, *argv, cwd: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-c", RUNNER, absent, *map(str, argv)], cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("absent, argv, names", [
    ("pinocchio", ["check", "{bvh}"], ("mocap check: error: this command needs pinocchio",
                                       "pip install pin")),
    ("tensorly", ["decompose", "--manifest", "{manifest}", "-o", "{tmp}/m.npz"],
     ("mocap decompose: error: this command needs tensorly", "pip install tensorly")),
    ("matplotlib", ["forces", "{walk}", "-o", "{tmp}/grf.csv", "--plot", "{tmp}/grf.png"],
     ("mocap forces: error: this command needs matplotlib", "pip install matplotlib")),
])
def test_a_missing_package_is_one_line(tmp_path, absent, argv, names):
    bvh = realdata_path("bandai2", "dataset-2_walk_active_001.bvh")
    manifest = realdata_path("bandai2", "manifest.csv")
    out = tmp_path / "out"
    out.mkdir()
    walk = realdata_path("biomechzoo_sample_study", "HC030A", "Turn", "HC030A22.c3d")
    words = [w.format(bvh=bvh, manifest=manifest, tmp=out, walk=walk) for w in argv]
    result = mocap_without(absent, *words, cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    assert all(name in result.stderr for name in names), result.stderr
    assert not any(out.iterdir())


def test_core_commands_run_without_the_heavy_packages(tmp_path):
    """info, convert and clinical angles of a real walk with its static, and a stick-figure
    preview: no Pinocchio, tensorly, matplotlib, pandas, dask, OpenSim or bvhio in the
    process (the preview needs pillow only)."""
    walk = realdata_path("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")
    static = realdata_path("biomechzoo_sample_study", "HC030A", "Static", "HC030A01.c3d")
    for argv in (["info", walk], ["convert", walk, tmp_path / "walk.trc"],
                 ["angles", walk, "-m", "plugingait-lower", "--static", static,
                  "--fill-gaps", "0.2", "-o", tmp_path / "angles.csv"]):
        result = mocap_without(HEAVY, *argv, cwd=tmp_path)
        assert result.returncode == 0, (argv[0], result.stderr)
    bvh = realdata_path("bandai2", "dataset-2_walk_active_001.bvh")
    result = mocap_without(HEAVY.replace(",PIL", ""), "animate", bvh, "-o", tmp_path / "w.gif",
                           "--max-frames", "5", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "walk.trc").stat().st_size > 0
    assert (tmp_path / "angles.csv").stat().st_size > 0
