"""Reading and decomposing a real 7 × 6 × 3 corpus (bandai2), whole process, per step.

Runs ``mocap decompose`` and ``mocap evaluate --leave-one-out`` on
``../shared/realdata/bandai2/manifest.csv`` with ``--cycles`` as a user would (fresh Python
process each, so imports count), and reports wall and CPU seconds of each, beside the same
commands with ``--body`` (every trial mapped onto the 15-segment body model, the older
route; with a BVH reader that cannot map the rig this fails — printed, not raised).
CPU seconds are the ones to compare on a shared machine. Then the same two commands with
every ``--method`` (interaction = the default, signature, transfer = the previous default),
with each one's CPU time as a ratio of transfer's, and the default's beside the issue-25
reference figures (:data:`REFERENCE_CPU`; the target is at most twice them). Never asserts.

    PYTHONPATH=$PWD python benchmarks/synthesis_corpus.py [--manifest FILE.csv] [--no-body]
"""
from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: CPU seconds of ``decompose`` and ``evaluate --leave-one-out`` on bandai2 when issue 25 was
#: filed (the action-transfer default of then, same machine class).
REFERENCE_CPU = {"decompose": 3.0, "evaluate": 15.6}

DEFAULT = Path(__file__).resolve().parents[1] / ".." / "shared" / "realdata" / "bandai2" / \
    "manifest.csv"


def run(arguments: list[str]) -> tuple[float, float, int, str]:
    """Wall seconds, CPU seconds (children), exit status, last stderr line."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "mocap", *arguments], capture_output=True,
                          text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    last = (done.stderr.strip().splitlines() or [""])[-1]
    return wall, cpu, done.returncode, last


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--manifest", default=str(DEFAULT))
    parser.add_argument("--no-body", action="store_true", help="skip the --body runs")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        model = str(Path(folder) / "model.npz")
        routes = [("rig joints (new)", [])] + ([] if args.no_body
                                               else [("body model (--body)", ["--body"])])
        for label, extra in routes:
            for command in (["decompose", "--manifest", args.manifest, "--cycles", "-o", model],
                            ["evaluate", "--manifest", args.manifest, "--cycles",
                             "--leave-one-out", "--json"]):
                wall, cpu, status, last = run(command + extra)
                note = "" if status == 0 else f"  exit {status}: {last}"
                reference = REFERENCE_CPU[command[0]]
                print(f"{label:<22} {command[0]:<10} wall {wall:7.2f} s  cpu {cpu:7.2f} s  "
                      f"({cpu / reference:.2f}x the reference {reference:.1f} s){note}")
        print()
        cpus: dict = {}
        for method in ("transfer", "interaction", "signature"):
            for command in (["decompose", "--manifest", args.manifest, "--cycles", "-o", model],
                            ["evaluate", "--manifest", args.manifest, "--cycles",
                             "--leave-one-out", "--json"]):
                wall, cpu, status, last = run(command + ["--method", method])
                cpus[(method, command[0])] = cpu
                ratio = cpu / cpus[("transfer", command[0])]
                note = "" if status == 0 else f"  exit {status}: {last}"
                print(f"--method {method:<12} {command[0]:<10} wall {wall:7.2f} s  cpu "
                      f"{cpu:7.2f} s  ({ratio:.2f}x transfer's cpu){note}")


if __name__ == "__main__":
    main()
