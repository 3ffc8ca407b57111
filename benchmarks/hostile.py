"""How quickly hostile files are refused: CPU seconds per refusal, whole command in-process.

Each case is a file built to ask for more than reason (issue 23): an AMC of two million
empty frames, a CSV header naming three million columns, a TRC of six million random
bytes under a full-body header, a cloth of two million particles. Each must be refused
with one line before the work it asks for is started; the figure beside it is ``mocap
info`` of an ordinary file (a 120-frame TRC of 60 markers) in the same run, so the ratio
says how much more than an ordinary read a refusal costs. CPU time (``process_time``),
not wall time: the refusals must not depend on the machine's load. The tests assert the
refusals and their messages; this script measures them (run ``python benchmarks/hostile.py``).
"""
from __future__ import annotations

import contextlib
import io
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mocap.cli import main                      # noqa: E402
from mocap.io import write                      # noqa: E402
from mocap.resources import data_path           # noqa: E402
from mocap.trial import Trial                   # noqa: E402


def cpu_seconds(argv: list[str], expected: int) -> float:
    """CPU seconds of ``mocap argv`` in this process; its exit status must be ``expected``."""
    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
        start = time.process_time()
        status = main(argv)
        seconds = time.process_time() - start
    if status != expected:
        raise SystemExit(f"mocap {' '.join(argv)}: exit {status}, expected {expected}")
    return seconds


def cases(folder: Path) -> dict[str, list[str]]:
    """The hostile commands, by name."""
    asf = (ROOT / "tests" / "data" / "cmu_lambada.asf").read_text()
    (folder / "s.asf").write_text(asf)
    (folder / "s_01.amc").write_text(":FULLY-SPECIFIED\n:DEGREES\n" +
                                     "\n".join(str(k) for k in range(1, 2_000_001)) + "\n")
    (folder / "wide.csv").write_text("time," + ",".join(
        f"M{i}_{a}" for i in range(1_000_000) for a in "xyz") + "\n0,1\n0.01,2\n")
    head = (folder / "full.trc").read_text().split("\n")[:6]
    garbage = np.random.default_rng(0).choice(
        np.frombuffer(b"0123456789.-e\t\n", np.uint8), 6_000_000)
    (folder / "garbage.trc").write_bytes("\n".join(head).encode() + b"\n" + garbage.tobytes())
    (folder / "cloth.toml").write_text(data_path("scenes", "hanging-cloth.toml").read_text()
                                       .replace("resolution = [32, 32]",
                                                "resolution = [1414, 1414]"))
    return {
        "AMC, 2 000 000 empty frames (export)": [
            "export", str(folder / "s_01.amc"), "-f", "bvh", "-o", str(folder / "o.bvh")],
        "CSV header of 3 000 000 columns (info)": ["info", str(folder / "wide.csv")],
        "TRC, 6 MB of random digits (convert)": [
            "convert", str(folder / "garbage.trc"), str(folder / "o.c3d")],
        "cloth of 1 999 396 particles (simulate)": [
            "simulate", str(folder / "cloth.toml"), "-o", str(folder / "o.npz")],
    }


def run() -> None:
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        rng = np.random.default_rng(1)
        labels = [f"M{k}" for k in range(60)]
        write(Trial(labels, rng.normal(size=(120, 60, 3)), 100.0), folder / "full.trc")
        reference = min(cpu_seconds(["info", str(folder / "full.trc")], 0) for _ in range(3))
        print(f"{'reference: mocap info of a 120-frame TRC, 60 markers':58s} "
              f"{reference:6.3f} s CPU")
        for title, argv in cases(folder).items():
            seconds = min(cpu_seconds(argv, 2) for _ in range(2))
            print(f"{title:58s} {seconds:6.3f} s CPU  ({seconds / reference:5.1f}× reference)")


if __name__ == "__main__":
    run()
