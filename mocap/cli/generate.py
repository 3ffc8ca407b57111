"""``mocap generate``: the synthetic people × actions corpus."""
from __future__ import annotations

import argparse

from mocap.cli.commands import summary
from mocap.errors import MocapError
from mocap.synthetic import ACTIONS, generate_corpus


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``generate`` to ``subparsers``."""

    parser = subparsers.add_parser(
        "generate", help=summary("generate"),
        description="Generate synthetic marker trials <person>_<action>.c3d for several people "
                    "doing several actions, each person with a distinct motion signature "
                    "(body size, cadence, style, timing, asymmetry), plus the exact joint "
                    "angles in OUT/truth/.")
    parser.add_argument("out", metavar="OUT_DIR", help="folder to write the corpus into")
    parser.add_argument("--people", type=int, default=6, help="number of people (default 6)")
    parser.add_argument("--actions", default=",".join(ACTIONS),
                        help=f"comma-separated actions (default {','.join(ACTIONS)})")
    parser.add_argument("--seed", type=int, default=0,
                        help="random seed; the same seed gives the same corpus (default 0)")
    parser.add_argument("--noise-mm", type=float, default=0.0,
                        help="Gaussian marker noise, standard deviation in mm (default 0)")
    parser.add_argument("--gaps", type=float, default=0.0, metavar="FRACTION",
                        help="fraction of marker samples removed as gaps of 3-30 frames (default 0)")
    parser.add_argument("--cycles", type=float, default=1.0,
                        help="gait cycles per trial (default 1)")
    parser.add_argument("--rate", type=float, default=100.0, help="sampling rate in Hz (default 100)")
    parser.add_argument("--sequence", default="ZXY",
                        help="Euler sequence of the ground-truth angle CSVs (default ZXY)")
    parser.add_argument("--format", dest="file_format", choices=("c3d", "trc", "csv"),
                        default="c3d", help="marker file format (default c3d)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Write the corpus and print where it went."""

    actions = [a.strip() for a in args.actions.split(",") if a.strip()]
    if args.people < 1:
        raise MocapError(f"--people must be at least 1, got {args.people}")
    if not 0 <= args.gaps < 0.9:
        raise MocapError(f"--gaps must be a fraction between 0 and 0.9, got {args.gaps}")
    if args.noise_mm < 0:
        raise MocapError(f"--noise-mm must not be negative, got {args.noise_mm}")
    files = generate_corpus(args.out, people=args.people, actions=actions, seed=args.seed,
                            noise_mm=args.noise_mm, gap_fraction=args.gaps, cycles=args.cycles,
                            rate=args.rate, sequence=args.sequence, file_format=args.file_format)
    print(f"wrote {len(files)} trials ({args.people} people × {len(actions)} actions) to {args.out}; "
          f"ground truth in {args.out}/truth/")
    return 0
