"""Whole-process timings of the ``mocap`` command beside plain-library references (issue 11).

Each line is the median wall time of several runs of a fresh process (start-up, imports,
work, exit), as a user meets it::

    python benchmarks/startup.py [C3D_FILE] [--runs 5] [--frames 100000]

- ``mocap --help`` beside ``python -c pass``;
- ``mocap info FILE`` beside ``python -c "import ezc3d; ezc3d.c3d(FILE)"``;
- ``mocap angles`` on FRAMES frames x 15 segments (synthetic15, written once as C3D) beside
  a plain ezc3d + numpy + scipy + ``np.savetxt`` script computing the same angles;
- ``mocap check`` on a BVH, first run (empty numba cache) and second run;
- ``mocap check`` of the real 556-frame Plug-in Gait trial HC030A22 (``--check-trial``)
  beside the plain reference ``python -c "import pinocchio"`` + the C3D read, with ezc3d
  and with the project's reader (issue 13's target: within 2x).

FILE defaults to a real Vicon walk of the shared corpus when it is there.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
REAL = ROOT.parent / "shared" / "realdata" / "biomechzoo_sample_study" / "HC002D" / "Straight" \
    / "HC002D06.c3d"
BVH = ROOT / "tests" / "data" / "mocapbank_walk.bvh"
CHECK_TRIAL = ROOT.parent / "shared" / "realdata" / "biomechzoo_sample_study" / "HC030A" \
    / "Turn" / "HC030A22.c3d"

#: The plain reference of ``mocap angles``: read with ezc3d, frames from three markers,
#: child-in-parent rotations, scipy Euler angles, ``np.savetxt``.
REFERENCE_ANGLES = r'''
import sys, numpy as np, ezc3d
from scipy.spatial.transform import Rotation
source, target, segments = sys.argv[1], sys.argv[2], sys.argv[3].split(";")
c3d = ezc3d.c3d(source)
labels = c3d["parameters"]["POINT"]["LABELS"]["value"]
points = c3d["data"]["points"][:3].transpose(2, 1, 0) / 1000.0
frames = {}
for item in segments:
    name, parent, o, a, l = item.split(",")
    po, pa, pl = (points[:, labels.index(m)] for m in (o, a, l))
    e1 = pa - po; e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e3 = np.cross(e1, pl - po); e3 /= np.linalg.norm(e3, axis=1, keepdims=True)
    e2 = np.cross(e3, e1)
    frames[name] = (parent, np.stack([e1, e2, e3], axis=2))
columns, times = [], np.arange(points.shape[0]) / float(c3d["header"]["points"]["frame_rate"])
for name, (parent, R) in frames.items():
    if parent:
        R = np.einsum("fji,fjk->fik", frames[parent][1], R)
    columns.append(np.unwrap(np.radians(Rotation.from_matrix(R).as_euler("ZXY", degrees=True)), axis=0))
table = np.column_stack([times] + [np.degrees(c) for c in columns])
np.savetxt(target, table, fmt="%.6f", delimiter=",")
'''


#: CPU seconds (user + system) of the last median_wall's processes, median.
LAST_CPU = [0.0]


def median_wall(argv: list[str], runs: int, env: dict | None = None, fresh=None) -> float:
    """Median wall time of ``runs`` fresh processes of ``argv`` (``fresh()`` before each);
    their median CPU time (user + system, less sensitive to other load) in LAST_CPU."""
    times, cpu = [], []
    for _ in range(runs):
        if fresh is not None:
            fresh()
        start = time.perf_counter()
        # cwd=ROOT: 'python -m mocap' puts the working folder first on sys.path, so run
        # from another checkout it would time that checkout's code
        child = subprocess.Popen(argv, env=env, cwd=ROOT, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
        _, status, usage = os.wait4(child.pid, 0)
        times.append(time.perf_counter() - start)
        if status:
            raise subprocess.CalledProcessError(status, argv)
        cpu.append(usage.ru_utime + usage.ru_stime)
    LAST_CPU[0] = statistics.median(cpu)
    return statistics.median(times)


def _long_trial(folder: Path, frames: int) -> tuple[Path, str]:
    """A synthetic15 walk tiled to ``frames`` frames, as C3D; and the segment spec."""
    sys.path.insert(0, str(ROOT))
    from mocap.io import write
    from mocap.markersets import load_markerset
    from mocap.synthetic import synthesize_trial
    from mocap.trial import Trial

    trial, _ = synthesize_trial(0, "walk", seed=0, cycles=4)
    reps = -(-frames // trial.frames)
    points = np.concatenate([trial.points] * reps)[:frames]
    path = folder / "long_walk.c3d"
    write(Trial(trial.labels, points, trial.rate), path)
    markerset = load_markerset("synthetic15")
    spec = ";".join(f"{s.name},{s.parent or ''},{','.join(s.markers)}"
                    for s in markerset.segments)
    return path, spec


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file", nargs="?", default=str(REAL), help="C3D file for info")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--frames", type=int, default=100_000)
    parser.add_argument("--check-trial", default=str(CHECK_TRIAL),
                        help="real C3D trial with Plug-in Gait markers for the check row")
    args = parser.parse_args()
    python = sys.executable
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    mocap = [python, "-m", "mocap"]
    rows = []

    measured: dict[str, tuple[float, float]] = {}      # name: (wall, CPU)

    def report(name: str, seconds: float, reference: str | None = None, label: str = ""):
        """Print a row; ``reference`` names an earlier row to give the ratios against."""
        measured[name] = (seconds, LAST_CPU[0])
        ratio = ""
        if reference:
            wall, cpu = measured[reference]
            ratio = f"  {seconds / wall:5.2f} x {label} (CPU {LAST_CPU[0] / cpu:4.2f} x)"
        rows.append(f"{name:<44} {seconds:7.3f} s  CPU {LAST_CPU[0]:6.3f} s{ratio}")
        print(rows[-1], flush=True)

    print(f"load average {os.getloadavg()[0]:.2f} ({os.cpu_count()} CPUs); medians of fresh "
          "processes: wall, and CPU (user + system, less sensitive to other load)", flush=True)
    bare = median_wall([python, "-c", "pass"], args.runs, env)
    report("python -c pass", bare)
    report("mocap --help", median_wall(mocap + ["--help"], args.runs, env), "python -c pass",
           "python -c pass")
    reference = median_wall([python, "-c", f"import ezc3d; ezc3d.c3d({args.file!r})"],
                            args.runs, env)
    ezc3d_row = "python -c 'import ezc3d; ezc3d.c3d(FILE)'"
    report(ezc3d_row, reference)
    report("mocap info FILE", median_wall(mocap + ["info", args.file], args.runs, env),
           ezc3d_row, "the ezc3d reference")

    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        source, spec = _long_trial(folder, args.frames)
        plain = median_wall([python, "-c", REFERENCE_ANGLES, str(source),
                             str(folder / "ref.csv"), spec], max(3, args.runs // 2), env)
        plain_row = f"plain ezc3d+numpy+scipy+savetxt ({args.frames} fr)"
        report(plain_row, plain)
        ours = median_wall(mocap + ["angles", str(source), "-m", "synthetic15", "-o",
                                    str(folder / "ours.csv")], max(3, args.runs // 2), env)
        report(f"mocap angles ({args.frames} frames x 15 segments)", ours, plain_row,
               "the plain script")

        cache = folder / "numba"
        numba_env = {**env, "NUMBA_CACHE_DIR": str(cache)}

        def empty_cache():
            subprocess.run(["rm", "-rf", str(cache)], check=True)

        check = mocap + ["check", str(BVH), "--json"]
        report("mocap check BVH, first run (empty cache)",
               median_wall(check, 1, numba_env, fresh=empty_cache))
        report("mocap check BVH, second run", median_wall(check, args.runs, numba_env))

    if Path(args.check_trial).exists():
        trial = args.check_trial
        ezc3d_floor = "import pinocchio + ezc3d.c3d(TRIAL)"
        report(ezc3d_floor, median_wall([python, "-c", f"import pinocchio, ezc3d; "
                                         f"ezc3d.c3d({trial!r})"], args.runs, env))
        own_floor = "import pinocchio + mocap.io.read(TRIAL)"
        report(own_floor, median_wall([python, "-c", f"import pinocchio; from mocap.io import "
                                       f"read; read({trial!r})"], args.runs, env))
        check = mocap + ["check", trial, "-m", "plugingait-full", "--json"]
        seconds = median_wall(check, args.runs, env)
        name = f"mocap check {Path(trial).name} -m plugingait-full"
        report(name, seconds, ezc3d_floor, "the ezc3d floor")
        report(name, seconds, own_floor, "the mocap.io floor")
    else:
        print(f"check trial not found ({args.check_trial}): skipped")
    print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
