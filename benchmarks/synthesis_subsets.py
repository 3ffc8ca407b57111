"""Synthesis on every k-person subset of a real corpus: does the model hold with fewer people?

For each subset of ``--people`` people of the corpus (all of its actions), runs the same
leave-one-out as ``mocap evaluate --leave-one-out`` and prints the synthesis error as a ratio
to the additive model (mean + the person's offset; above 1.000 the model lost to it) and
recognition top-1 / top-3; then the mean, worst and count of subsets above the additive model
or below 90 % top-1. Figures, not timings; never asserts (issue 25: "robust to 5–15 people
and one take per cell").

    python benchmarks/synthesis_subsets.py [--method interaction|signature|transfer]
        [--people 5] [--take 001] [--no-cycles] [--manifest M]

The default corpus is bandai2 take 001 read as whole trials (``--no-cycles``: one
repetition per cell, like the kept-back corpus B); ``--take all`` keeps every take.
"""
from __future__ import annotations

import argparse
import itertools
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from synthesis.corpus import read_corpus, read_manifest  # noqa: E402
from synthesis.evaluate import leave_one_out  # noqa: E402
from tests.conftest import REALDATA  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--manifest", type=Path, default=REALDATA / "bandai2" / "manifest.csv")
    parser.add_argument("--method", default="interaction")
    parser.add_argument("--people", type=int, default=5, help="people per subset (≥ 4)")
    parser.add_argument("--take", default="001", help="take suffix kept, or 'all'")
    parser.add_argument("--no-cycles", action="store_true",
                        help="whole trials time-normalised (default: cut into cycles)")
    args = parser.parse_args()
    if args.people < 4:
        parser.error("--people must be at least 4 (three donors per held-out person)")
    entries = read_manifest(args.manifest)
    if args.take != "all":
        entries = [e for e in entries if e.path.stem.endswith(f"_{args.take}")]
        if not entries:
            parser.error(f"--take {args.take}: no trial of {args.manifest} ends in _{args.take}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        corpus = read_corpus(entries, samples=50, cycles=not args.no_cycles)
    if args.people > len(corpus.people):
        parser.error(f"--people {args.people}: the corpus has {len(corpus.people)}")
    print(f"{args.manifest.name}, take {args.take}, "
          f"{'whole trials' if args.no_cycles else 'cycles'}: {len(corpus.people)} people × "
          f"{len(corpus.actions)} actions; method {args.method}; subsets of {args.people}")
    ratios, top1, top3 = [], [], []
    start = time.process_time()
    for people in itertools.combinations(corpus.people, args.people):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = leave_one_out(corpus.subset(list(people), None), method=args.method)
        figures = result.to_json()
        ratios.append(figures["synthesis_rms_deg"] / figures["additive_rms_deg"])
        top1.append(figures["recognition_accuracy"])
        top3.append(figures["recognition_top3"])
        paired = figures["versus_additive"]
        print(f"  {'+'.join(people):60s} ratio {ratios[-1]:.3f}  top-1 {100 * top1[-1]:3.0f} %"
              f"  top-3 {100 * top3[-1]:3.0f} %  cells won/lost {paired['wins']}/"
              f"{paired['losses']}", flush=True)
    ratios, top1 = np.array(ratios), np.array(top1)
    print(f"{len(ratios)} subsets: ratio to additive mean {ratios.mean():.3f}, worst "
          f"{ratios.max():.3f}, above 1.000 in {np.sum(ratios > 1.0005)}; top-1 mean "
          f"{100 * top1.mean():.0f} %, worst {100 * top1.min():.0f} %, below 90 % in "
          f"{np.sum(top1 < 0.9)}; top-3 mean {100 * np.mean(top3):.0f} % "
          f"({time.process_time() - start:.0f} s CPU)")


if __name__ == "__main__":
    main()
