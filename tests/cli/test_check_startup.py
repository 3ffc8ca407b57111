"""``mocap check`` and ``mocap plugingait`` load only what they use (issues 13, 22: speed).

scipy.spatial.transform alone costs about 0.4 s of CPU to import (more than the whole
check of a real walk without it), scipy.signal more, numba and matplotlib 0.3 s each; the
check of a C3D trial needs none of them (quaternions in numpy, :mod:`mocap.rotations.quaternions`;
the low-pass in numpy, :mod:`mocap.clean.filtering`). A structural test, not a timed one.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from tests.conftest import realdata_path

ROOT = Path(__file__).resolve().parents[2]

#: Run the command in-process, then list the loaded top-level packages on stderr.
PROBE = r"""
import contextlib, io, json, sys
from mocap.cli import main
out = io.StringIO()
with contextlib.redirect_stdout(out):
    status = main(sys.argv[1:])
sys.stderr.write(json.dumps({"status": status, "stdout": out.getvalue(),
                             "modules": sorted(sys.modules)}))
"""


def _probe(*argv: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, "-c", PROBE, *argv], env=env, cwd=ROOT,
                          capture_output=True,
                          text=True, timeout=600)
    return json.loads(done.stderr.strip().splitlines()[-1])


def test_check_of_a_real_c3d_trial_imports_no_scipy_numba_or_matplotlib():
    trial = realdata_path("biomechzoo_sample_study/HC030A/Turn/HC030A22.c3d")
    probe = _probe("check", str(trial), "-m", "plugingait-full", "--json")
    assert probe["status"] == 0
    report = json.loads(probe["stdout"])
    assert report["frames"] == 556 and report["verdict"] in ("plausible", "implausible")
    loaded = {name.split(".")[0] for name in probe["modules"]}
    assert "pinocchio" in loaded                 # the probe does see the real imports
    assert not loaded & {"scipy", "numba", "matplotlib", "tensorly", "dask", "ezc3d"}, \
        sorted(loaded & {"scipy", "numba", "matplotlib", "tensorly", "dask", "ezc3d"})


def test_plugingait_of_a_real_walk_imports_no_scipy_pandas_matplotlib_or_pinocchio(tmp_path):
    """``mocap plugingait`` (issue 22: <= 1 s CPU on a short walk): its event detection
    finds peaks in numpy (:func:`mocap.plugingait.events.find_peaks`), not scipy.signal."""
    study = realdata_path("biomechzoo_sample_study", "HC030A")
    out, csv = tmp_path / "p.c3d", tmp_path / "p.csv"
    probe = _probe("plugingait", str(study / "Straight" / "HC030A05.c3d"), "--static",
                   str(study / "Static" / "HC030A01.c3d"), "-o", str(out), "--csv", str(csv))
    assert probe["status"] == 0 and out.is_file() and csv.is_file()
    assert "gait cycles L 1, R 1" in probe["stdout"]
    loaded = {name.split(".")[0] for name in probe["modules"]}
    assert "mocap" in loaded and "numpy" in loaded   # the probe does see the real imports
    unwanted = {"scipy", "pandas", "matplotlib", "pinocchio", "numba", "tensorly", "dask"}
    assert not loaded & unwanted, sorted(loaded & unwanted)
