"""``mocap angles`` (marker files to joint-angle CSV) and ``mocap generate``."""
from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path

from mocap.angles import GimbalLockWarning, check_sequence
from mocap.cli import options
from mocap.io.angles_csv import write_angles_csv
from mocap.cli.commands import summary
from mocap.cli.paths import refuse_overwrite
from mocap.errors import MocapError
from mocap.io import suffixes
from mocap.io.discovery import find_files
from mocap.markersets import load_markerset
from mocap.pipeline import Cleaning, marker_file_angles
from mocap.plot import plot_angles
from mocap.progress import progress

#: Suffixes ``mocap angles`` picks up when given a folder.
MARKER_SUFFIXES = suffixes("markers")


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``angles`` and ``generate`` to ``subparsers``."""
    parser = subparsers.add_parser(
        "angles", help=summary("angles"),
        description="Compute segment frames from three markers per segment and write the "
                    "joint angles (child relative to parent, the root relative to the lab) "
                    "as CSV: time in seconds, then <segment>.<axis> in degrees, continuous. "
                    "Frames where a segment's markers are missing give empty cells, unless "
                    "--fill-gaps fills them.",
        epilog="Examples: mocap angles walk.c3d --markerset plugingait-lower --sequence YXZ "
               "-o walk.csv --plot walk.png;  mocap angles corpus/ --markerset synthetic15 "
               "-o angles/")
    parser.add_argument("inputs", nargs="+", metavar="IN",
                        help="marker file(s) (.c3d, .trc, .csv) or folders of them")
    parser.add_argument("--markerset", "-m", metavar="SET",
                        help="marker set: a preset name (plugingait-lower, synthetic15) or a "
                             "TOML file defining segments and virtual markers (needed "
                             "unless --from-rotations)")
    parser.add_argument("--from-rotations", action="store_true",
                        help="angles of a markerless C3D file from its segment poses "
                             "(ROTATION group, e.g. Theia3D) instead of markers; the "
                             "hierarchy comes from the segment names or --segments")
    parser.add_argument("--segments", metavar="FILE.toml",
                        help="with --from-rotations: the hierarchy as a [parents] table "
                             "(child = \"parent\", \"\" for the root) instead of the guess from "
                             "the names")
    parser.add_argument("--sequence", "-s", default="ZXY", metavar="SEQ",
                        help="Euler sequence as in scipy: upper case intrinsic (ZXY, YXZ, ZYZ "
                             "...), lower case extrinsic (zxy ...); 24 in all (default ZXY)")
    parser.add_argument("--fill-gaps", type=options.SECONDS_GAP, metavar="SECONDS",
                        help="fill gaps up to this long with a cubic spline before computing "
                             "angles; longer gaps, and gaps at either end, stay empty and are "
                             "reported")
    parser.add_argument("--lowpass", type=options.CUTOFF, metavar="HZ",
                        help="zero-lag Butterworth low-pass of the markers at this cutoff "
                             "(after gap filling); must be below half the sampling rate")
    parser.add_argument("--order", type=options.FILTER_ORDER, default=4,
                        help="order of the Butterworth filter of --lowpass (default 4; run "
                             "forward and backward, so the response is squared)")
    parser.add_argument("--short-runs", choices=("error", "keep", "drop"), default="error",
                        help="with --lowpass, what to do with runs of valid frames too short "
                             "to filter: stop with an error (default), keep them unfiltered, "
                             "or drop them (empty cells)")
    parser.add_argument("-o", "--output", required=True, metavar="OUT",
                        help="output CSV; with several inputs (or a folder) an output folder "
                             "that receives <input name>.csv per input")
    parser.add_argument("--plot", metavar="OUT.png",
                        help="also draw the angle curves, one panel per segment, to this PNG "
                             "(with several inputs: a folder receiving <input name>.png)")
    parser.set_defaults(func=run_angles)


def run_angles(args: argparse.Namespace) -> int:
    """Handler of ``mocap angles``; returns the exit status."""
    check_sequence(args.sequence)
    if args.from_rotations:
        if args.markerset or args.fill_gaps is not None or args.lowpass is not None:
            raise MocapError("--from-rotations reads segment poses: --markerset, --fill-gaps "
                             "and --lowpass apply to markers")
        markerset = None
    elif args.segments:
        raise MocapError("--segments goes with --from-rotations")
    elif not args.markerset:
        raise MocapError("give --markerset (markers) or --from-rotations (segment poses of "
                         "a markerless C3D file)")
    else:
        markerset = load_markerset(args.markerset)
    files = find_files(args.inputs, MARKER_SUFFIXES)
    output = Path(args.output)
    folder_mode = (len(files) > 1 or any(Path(i).is_dir() for i in args.inputs)
                   or output.is_dir() or args.output.endswith(os.sep))
    if not folder_mode:
        jobs = [(files[0], output, Path(args.plot) if args.plot else None)]
    else:
        if output.exists() and not output.is_dir():
            raise MocapError("with several inputs, -o must be a folder", output)
        stems = [f.stem for f in files]
        clash = sorted({s for s in stems if stems.count(s) > 1})
        if clash:
            raise MocapError(f"several inputs are named {', '.join(clash)}: their outputs "
                             f"would overwrite each other in {output}")
        plot_folder = Path(args.plot) if args.plot else None
        jobs = [(f, output / f"{f.stem}.csv",
                 plot_folder / f"{f.stem}.png" if plot_folder else None) for f in files]

    for _, target, plot in jobs:
        refuse_overwrite(target, files)
        if plot is not None:
            refuse_overwrite(plot, files + [target])
    failures = 0
    for source, target, plot in progress(jobs, "joint angles", total=len(jobs)):
        try:
            _angles_one(source, target, plot, markerset, args)
        except MocapError as error:
            if len(jobs) == 1:
                raise
            failures += 1
            print(f"mocap angles: error: {error}", file=sys.stderr)
    if failures:
        print(f"mocap angles: {failures} of {len(jobs)} input(s) failed", file=sys.stderr)
        return 2
    return 0


def _angles_one(source: Path, target: Path, plot: Path | None, markerset,
                args: argparse.Namespace) -> None:
    if markerset is None:
        from mocap.io import read
        from mocap.io.c3d.rotations import rotation_angles

        angles = rotation_angles(read(source), args.sequence, args.segments)
        write_angles_csv(angles, target)
        if plot is not None:
            plot_angles(angles, plot, title=f"{source.name} (segment poses, {args.sequence})")
        return
    cleaning = Cleaning(max_gap_seconds=args.fill_gaps, lowpass_hz=args.lowpass,
                        order=args.order, short_runs=args.short_runs)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", GimbalLockWarning)
        result = marker_file_angles(source, markerset, args.sequence, cleaning)
    if result.gaps is not None and result.gaps.unfilled:
        lines = result.gaps.summary().splitlines()
        shown = lines[:11] + ([f"  … {len(lines) - 11} more marker(s)"]
                              if len(lines) > 11 else [])
        print(f"mocap angles: {source}: " + "\n".join(shown), file=sys.stderr)
    for warning in caught:
        if issubclass(warning.category, GimbalLockWarning):
            print(f"mocap angles: warning: {warning.message}", file=sys.stderr)
        else:
            warnings.showwarning(warning.message, warning.category, warning.filename,
                                 warning.lineno)
    write_angles_csv(result.angles, target)
    if plot is not None:
        plot_angles(result.angles, plot,
                    title=f"{source.name} ({markerset.name}, {args.sequence})")
