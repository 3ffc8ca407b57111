"""``mocap generate``: the synthetic people × actions corpus."""
from __future__ import annotations

import argparse

from mocap.atomic import atomic_folder
from mocap.cli import options
from mocap.cli.commands import Subparsers, summary
from mocap.errors import MocapError
from mocap.synthetic import ACTIONS, generate_corpus


def register(subparsers: Subparsers) -> None:
    """Add ``generate`` to ``subparsers``."""

    parser = subparsers.add_parser(
        "generate", help=summary("generate"),
        description="Generate synthetic marker trials <person>_<action>.c3d for several people "
                    "doing several actions, each person with a distinct motion signature "
                    "(body size, cadence, style, timing, asymmetry), plus the exact joint "
                    "angles in OUT/truth/.")
    parser.add_argument("out", nargs="?", metavar="OUT_DIR",
                        help="folder to write the corpus into (or give -o/--output)")
    parser.add_argument("-o", "--output", dest="output", metavar="OUT_DIR",
                        help="the output folder, as every command spells it")
    parser.add_argument("--people", type=options.PEOPLE, default=6, metavar="N", help="number of people (default 6)")
    parser.add_argument("--actions", default=",".join(ACTIONS),
                        help=f"comma-separated actions (default {','.join(ACTIONS)})")
    parser.add_argument("--seed", type=options.SEED, default=0, metavar="SEED",
                        help="random seed; the same seed gives the same corpus (default 0)")
    parser.add_argument("--noise-mm", type=options.real(0, 1000), default=0.0, metavar="MM",
                        help="Gaussian marker noise, standard deviation in mm (default 0)")
    parser.add_argument("--gaps", type=options.real(0, below=0.9), default=0.0, metavar="FRACTION",
                        help="fraction of marker samples removed as gaps of 3-30 frames (default 0)")
    parser.add_argument("--cycles", type=options.real(above=0, maximum=100), default=1.0, metavar="N",
                        help="gait cycles per trial (default 1)")
    parser.add_argument("--rate", type=options.RATE, default=100.0, metavar="HZ",
                        help="sampling rate in Hz (default 100)")
    parser.add_argument("--sequence", default="ZXY", metavar="SEQ",
                        help="Euler sequence of the ground-truth angle CSVs, scipy convention "
                             "(default ZXY)")
    parser.add_argument("--format", dest="file_format", choices=("c3d", "trc", "csv"),
                        default="c3d", help="marker file format (default c3d)")
    parser.add_argument("--force", action="store_true",
                        help="replace OUT_DIR when it already holds files (default: refuse)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Write the corpus and print where it went."""

    if (args.out is None) == (args.output is None):
        raise MocapError("give the output folder once: OUT_DIR or -o/--output")
    args.out = args.out or args.output
    actions = [a.strip() for a in args.actions.split(",") if a.strip()]
    # the corpus appears whole or not at all (a failure or Ctrl-C leaves nothing behind)
    with atomic_folder(args.out, replace=args.force) as staging:
        files = generate_corpus(staging, people=args.people, actions=actions, seed=args.seed,
                                noise_mm=args.noise_mm, gap_fraction=args.gaps,
                                cycles=args.cycles, rate=args.rate, sequence=args.sequence,
                                file_format=args.file_format)
    print(f"wrote {len(files)} trials ({args.people} people × {len(actions)} actions) to {args.out}; "
          f"ground truth in {args.out}/truth/")
    return 0
