"""The synthesis figure table of docs/synthesis.md, from the command line as a user runs it.

Every row is ``mocap evaluate --leave-one-out --json`` in a fresh process, once per method
(``interaction`` = the default, ``signature``, ``transfer``), on a corpus of
``../shared/realdata``: bandai2 with its three takes, each take alone, the locomotion
actions, whole trials (no ``--cycles``), walk + run + wave, the design and the report styles
alone; the generated corpus (``mocap generate``); the biomechzoo straight walks and turns.
Subsets are the CLI's ``--actions`` / ``--people`` (filtered before reading, so the corpus'
rotation means and cycle signal are those of the subset: a subset read this way can differ
from the same cells cut out of a larger corpus). For the bandai2 corpora the rows
"design styles" / "report styles" are the cells of those people in the same run (issue 25's
split: every choice was made on active, elderly, exhausted, feminine and is reported on
masculine, normal, youthful).

Prints a Markdown table: RMS errors (degrees) of the baseline (mean of the other people), the
additive model (mean + the person's offset) and each method with its ratio to the additive
model (above 1.00 the method lost to it), the default's cells won / lost against the
additive model with the median difference, and recognition top-1 / top-3 of the default
and the signature. Figures, not timings; never asserts. About 4 minutes on 2 cores.

    python benchmarks/synthesis_figures.py [--only NAME,NAME] [--realdata DIR]
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from synthesis.corpus import read_manifest  # noqa: E402

REALDATA = ROOT.parent / "shared" / "realdata"
METHODS = ("interaction", "signature", "transfer")
DESIGN = ("active", "elderly", "exhausted", "feminine")
REPORT = ("masculine", "normal", "youthful")
LOCOMOTION = "walk,walk-turn-left,walk-turn-right,run"
WAVES = "walk,run,wave-both-hands"


def bandai_manifest(realdata: Path, folder: Path, take: str | None) -> Path:
    """bandai2's manifest with absolute paths, one take only when ``take`` is given."""
    out = folder / f"bandai2_{take or 'all'}.csv"
    with open(out, "w", newline="") as target:
        writer = csv.writer(target)
        writer.writerow(["path", "person", "action"])
        for entry in read_manifest(realdata / "bandai2" / "manifest.csv"):
            if take is None or entry.path.stem.endswith(f"_{take}"):
                writer.writerow([str(entry.path.resolve()), entry.person, entry.action])
    return out


def biomechzoo_manifest(realdata: Path, folder: Path) -> Path:
    """The 16 straight-walk and turn trials of the biomechzoo sample study."""
    out = folder / "biomechzoo.csv"
    with open(out, "w", newline="") as target:
        writer = csv.writer(target)
        writer.writerow(["path", "person", "action"])
        for subject in sorted(p for p in (realdata / "biomechzoo_sample_study").iterdir()
                              if p.is_dir()):
            for action in ("Straight", "Turn"):
                for trial in sorted((subject / action).glob("*.c3d")):
                    writer.writerow([str(trial), subject.name, action.lower()])
    return out


def corpora(realdata: Path, folder: Path) -> list[tuple[str, list[str], bool]]:
    """(row name, ``mocap evaluate`` corpus arguments, split into design/report styles)."""
    takes = {take: bandai_manifest(realdata, folder, take) for take in (None, "001", "002",
                                                                           "003")}
    cycles = ["--cycles", "--samples", "50"]
    generated = folder / "generated"
    subprocess.run([sys.executable, "-m", "mocap", "generate", str(generated)], check=True,
                   capture_output=True)
    return [
        ("bandai2, 7 styles × 6 contents × 3 takes",
         ["--manifest", str(takes[None])] + cycles, True),
        ("bandai2, take 001 only", ["--manifest", str(takes["001"])] + cycles, True),
        ("bandai2, take 002 only", ["--manifest", str(takes["002"])] + cycles, True),
        ("bandai2, take 003 only", ["--manifest", str(takes["003"])] + cycles, True),
        ("bandai2 locomotion, take 001", ["--manifest", str(takes["001"]), "--actions",
                                          LOCOMOTION] + cycles, True),
        ("bandai2, take 001, whole trials", ["--manifest", str(takes["001"]), "--samples",
                                             "50"], True),
        ("bandai2 walk + run + wave, 3 takes", ["--manifest", str(takes[None]), "--actions",
                                                WAVES] + cycles, True),
        ("bandai2 walk + run + wave, take 001", ["--manifest", str(takes["001"]), "--actions",
                                                 WAVES] + cycles, True),
        ("bandai2, the 4 design styles alone", ["--manifest", str(takes[None]), "--people",
                                                ",".join(DESIGN)] + cycles, False),
        ("bandai2, the 3 report styles alone", ["--manifest", str(takes[None]), "--people",
                                                ",".join(REPORT)] + cycles, False),
        ("generated corpus (6 × 4)", [str(generated), "--markerset", "synthetic15"], False),
        ("biomechzoo, 8 × straight / turn, whole trials",
         ["--manifest", str(biomechzoo_manifest(realdata, folder)), "--markerset",
          "plugingait-lower", "--samples", "50"], False),
    ]


def evaluate(arguments: list[str], method: str) -> dict | str:
    """``mocap evaluate --leave-one-out --json`` in a fresh process: its JSON, or the error."""
    environment = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    done = subprocess.run([sys.executable, "-m", "mocap", "evaluate", *arguments,
                           "--leave-one-out", "--json", "--method", method],
                          capture_output=True, text=True, env=environment)
    if done.returncode != 0:
        return (done.stderr.strip().splitlines() or ["exit %d" % done.returncode])[-1]
    return json.loads(done.stdout)


def rms(values) -> float:
    return float(np.sqrt(np.mean(np.square(values)))) if len(values) else float("nan")


def figures(result: dict, people: tuple[str, ...] | None = None) -> dict:
    """RMS errors and recognition over the cells of ``people`` (all when None)."""
    cells = [c for c in result["cells"] if people is None or c["person"] in people]
    return {"baseline": rms([c["baseline_rms_deg"] for c in cells]),
            "additive": rms([c["additive_rms_deg"] for c in cells]),
            "model": rms([c["synthesis_rms_deg"] for c in cells]),
            "top1": np.mean([c["recognised"] == c["person"] for c in cells]),
            "top3": np.mean([c["recognised_rank"] < 3 for c in cells])}


def row(name: str, results: dict, people: tuple[str, ...] | None, whole: bool) -> str:
    if any(isinstance(r, str) for r in results.values()):
        return f"| {name} | " + "; ".join(f"{m}: {r}" for m, r in results.items()
                                          if isinstance(r, str)) + " |"
    by_method = {m: figures(r, people) for m, r in results.items()}
    default = by_method["interaction"]
    cells = [f"{default['baseline']:.1f}°", f"{default['additive']:.1f}°"]
    for method in METHODS:
        f = by_method[method]
        cells.append(f"{f['model']:.1f}° ({f['model'] / f['additive']:.3f})")
    paired = results["interaction"]["versus_additive"]
    cells.append(f"{paired['wins']}/{paired['losses']}, {paired['median_difference_deg']:+.2f}°"
                 if whole else "–")
    for method in ("interaction", "signature"):
        f = by_method[method]
        cells.append(f"{100 * f['top1']:.0f} % / {100 * f['top3']:.0f} %" if whole
                     else f"{100 * f['top1']:.0f} % / –")
    return f"| {name} | " + " | ".join(cells) + " |"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--realdata", type=Path, default=REALDATA)
    parser.add_argument("--only", default="", help="comma-separated words; rows whose name "
                        "contains one of them (default: every row)")
    args = parser.parse_args()
    if not (args.realdata / "bandai2" / "manifest.csv").exists():
        parser.error(f"--realdata {args.realdata}: no bandai2/manifest.csv there")
    words = [w.strip() for w in args.only.split(",") if w.strip()]
    print("| corpus (leave-one-out, geodesic RMS) | baseline | additive | default "
          "(`interaction`) | `--method signature` | `transfer` | default vs additive: "
          "won/lost, median | recognition default top-1 / top-3 | recognition signature "
          "top-1 / top-3 |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        for name, arguments, split in corpora(args.realdata, Path(folder)):
            if words and not any(w in name for w in words):
                continue
            results = {m: evaluate(arguments, m) for m in METHODS}
            print(row(name, results, None, True), flush=True)
            if split and not any(isinstance(r, str) for r in results.values()):
                print(row("  design styles", results, DESIGN, False))
                print(row("  report styles", results, REPORT, False), flush=True)


if __name__ == "__main__":
    main()
