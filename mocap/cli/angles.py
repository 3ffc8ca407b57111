"""``mocap angles`` (marker files to joint-angle CSV) and ``mocap generate``."""
from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path

from mocap.rotations.angles import GimbalLockWarning, check_sequence
from mocap.cli import options
from mocap.io.angles_csv import write_angles_csv
from mocap.cli.commands import Subparsers, summary
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


def register(subparsers: Subparsers) -> None:
    """Add ``angles`` and ``generate`` to ``subparsers``."""
    parser = subparsers.add_parser(
        "angles", help=summary("angles"),
        description="Write joint angles as CSV. With -m plugingait-lower: Plug-in Gait's "
                    "clinical joint angles (columns <side>_<joint>.flexion|adduction|rotation "
                    "for pelvis, hip, knee, ankle and foot progression, Vicon's axes "
                    "and signs; --static "
                    "calibrates them). Otherwise (or with --no-clinical): segment angles "
                    "from three markers per segment, child relative to parent, the root "
                    "relative to the lab, as <segment>.<axis> on the principal Euler branch. "
                    "Time in seconds, angles in degrees; frames where markers are missing "
                    "give empty cells, unless --fill-gaps fills them.",
        epilog="Examples: mocap angles walk.c3d -m plugingait-lower --static static.c3d "
               "-o walk.csv --cycles cycles.csv;  mocap angles walk.c3d -m plugingait-lower "
               "--no-clinical --sequence YXZ -o walk.csv --plot walk.png;  mocap angles "
               "corpus/ --markerset synthetic15 -o angles/")
    parser.add_argument("inputs", nargs="+", metavar="IN",
                        help="marker file(s) (.c3d, .trc, .csv) or folders of them")
    parser.add_argument("--markerset", "-m", metavar="SET",
                        help="marker set: a preset name (plugingait-lower, plugingait-full, synthetic15) or a "
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
    parser.add_argument("--sequence", "-s", default=None, metavar="SEQ",
                        help="Euler sequence of segment angles as in scipy: upper case "
                             "intrinsic (ZXY, YXZ, ZYZ ...), lower case extrinsic (zxy ...); 24 "
                             "in all (default ZXY; clinical angles are always Plug-in Gait's "
                             "YXZ)")
    parser.add_argument("--clinical", action=argparse.BooleanOptionalAction, default=None,
                        help="Plug-in Gait joint angles in columns <side>_<joint>.flexion|"
                             "adduction|rotation (pelvis, hip, knee, ankle, foot_progress = "
                             "Vicon's <Side>FootProgressAngles; Vicon's signs, see "
                             "docs/plugingait.md); the default with -m plugingait-lower. "
                             "--no-clinical gives segment angles (<segment>.<axis>)")
    parser.add_argument("--static", metavar="STATIC.c3d",
                        help="static (standing) trial of the same subject: calibrates "
                             "Plug-in Gait's foot offsets and missing subject measurements "
                             "(clinical angles only; without it, the walk's PROCESSING group, "
                             "else estimates from the markers, one warning line each); a "
                             "knee alignment device in it (LKAX, "
                             "LKD1, LKD2 / RKAX, RKD1, RKD2 with data) is used automatically "
                             "for the knee axis and the thigh and shank rotation offsets")
    parser.add_argument("--upper-body", action="store_true",
                        help="clinical angles of Plug-in Gait's upper body too: thorax, "
                             "spine, neck, head, shoulder, elbow and wrist, "
                             "columns <side>_<joint>.flexion|adduction|rotation = Vicon's "
                             "<Side><Joint>Angles X|Y|Z (see docs/plugingait-upper.md). "
                             "Needs C7, T10, CLAV, "
                             "STRN, the head, shoulder, elbow, wrist and finger markers and "
                             "the subject's shoulder offset, elbow and wrist widths and hand "
                             "thickness (the PROCESSING group of the walk or --static); what "
                             "is missing is left empty with a warning")
    parser.add_argument("--flat-foot", choices=("auto", "on", "off"), default="auto",
                        help="Plug-in Gait's foot-flat static option: on, off, or auto (the "
                             "choice a previous Plug-in Gait run stored in the files, else "
                             "off; default)")
    parser.add_argument("--cycles", metavar="OUT.csv",
                        help="also write each side's gait cycles (foot strike to foot "
                             "strike, from the C3D events or detected from heel and toe "
                             "markers) normalised to 0-100 %% in 101 samples as a tidy CSV "
                             "(side, cycle, percent, angles) and the mean +- SD plot beside "
                             "it (.png); with several inputs a folder")
    parser.add_argument("--parameters", metavar="OUT.csv|OUT.json",
                        help="also write Vicon's gait-cycle parameters (cadence, speed, "
                             "stride and step time and length, foot off, support), one row "
                             "per side with Vicon's names and units; one input only")
    parser.add_argument("--fill-gaps", type=options.SECONDS_GAP, metavar="SECONDS",
                        help="fill gaps up to this long before computing angles, each marker "
                             "from its own segment (rigid with its other markers and, for "
                             "Plug-in Gait, the proximal joint centre; else a cubic spline); "
                             "longer gaps, and gaps at either end, stay empty and are reported")
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
    if getattr(args, "upper_body", False):
        if markerset is None or args.clinical is False:
            raise MocapError("--upper-body adds Plug-in Gait's upper body to the clinical "
                             "angles: it needs --markerset and does not go with "
                             "--no-clinical or --from-rotations")
        args.clinical = True
    if args.clinical is None:
        args.clinical = markerset is not None and markerset.name == "plugingait-lower"
    if args.clinical and markerset is None:
        raise MocapError("--clinical computes Plug-in Gait angles from markers; it does not "
                         "go with --from-rotations")
    if args.clinical and args.sequence not in (None, "YXZ"):
        raise MocapError(f"--sequence {args.sequence}: clinical angles use Plug-in Gait's "
                         f"YXZ; give --no-clinical for segment angles in another sequence")
    if args.static is not None and not args.clinical:
        raise MocapError("--static calibrates the clinical (Plug-in Gait) angles; drop "
                         "--no-clinical")
    if args.sequence is None:
        args.sequence = "YXZ" if args.clinical else "ZXY"
    check_sequence(args.sequence)
    args.static_trial = None
    if args.static is not None:
        from mocap.io import read
        if not Path(args.static).exists():
            raise MocapError("static trial not found", args.static)
        args.static_trial = read(args.static)
    files = find_files(args.inputs, MARKER_SUFFIXES)
    output = Path(args.output)
    folder_mode = (len(files) > 1 or any(Path(i).is_dir() for i in args.inputs)
                   or output.is_dir() or args.output.endswith(os.sep))
    args.cycles_folder = folder_mode and args.cycles is not None
    if getattr(args, "parameters", None) is not None:
        if folder_mode:
            raise MocapError("--parameters takes one input file", args.inputs[0])
        if Path(args.parameters).suffix.lower() not in (".csv", ".json"):
            raise MocapError("--parameters is written as .csv or .json", args.parameters)
    if not folder_mode:
        if output.suffix.lower() != ".csv":
            raise MocapError("the angles are written as CSV: name the output .csv (or a "
                             "folder, ending in /, for several inputs)", output)
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
    done = (f"{jobs[0][1]}" if len(jobs) == 1 else f"{len(jobs)} angle files to {output}")
    print(f"wrote {done}", file=sys.stderr)
    return 0


def _read_marker_trial(source: Path):
    """The marker trial of ``source``; a skeleton motion (BVH, AMC) is refused in one line."""
    from mocap.io import read
    from mocap.trial import Trial

    trial = read(source)
    if not isinstance(trial, Trial):
        raise MocapError("holds a skeleton motion, not marker trajectories: its joint angles "
                         "are written by 'mocap export -f csv'", source)
    return trial


def _angles_one(source: Path, target: Path, plot: Path | None, markerset,
                args: argparse.Namespace) -> None:
    if markerset is None:
        from mocap.io.c3d.rotations import rotation_angles

        angles = rotation_angles(_read_marker_trial(source), args.sequence, args.segments)
        write_angles_csv(angles, target)
        if plot is not None:
            plot_angles(angles, plot, title=f"{source.name} (segment poses, {args.sequence})")
        return
    from mocap.markersets.model import MissingMarkerWarning
    from mocap.plugingait.estimates import EstimatedMeasurementWarning
    from mocap.plugingait.model import AnatomicalOffsetWarning

    trial = _read_marker_trial(source)
    clinical = args.clinical
    from mocap.plugingait.upper import UpperBodyWarning

    ours = (GimbalLockWarning, AnatomicalOffsetWarning, MissingMarkerWarning, UpperBodyWarning,
            EstimatedMeasurementWarning)
    with warnings.catch_warnings(record=True) as caught:
        for category in ours:
            warnings.simplefilter("always", category)
        if clinical:
            angles, gaps = _clinical_angles(trial, args)
        else:
            padded, absent, empty = markerset.pad_missing(trial)
            if absent:
                print(f"mocap angles: warning: {source}: no marker(s) {', '.join(absent)}: "
                      f"segment(s) {', '.join(empty)} left empty", file=sys.stderr)
            cleaning = Cleaning(max_gap_seconds=args.fill_gaps, lowpass_hz=args.lowpass,
                                order=args.order, short_runs=args.short_runs)
            result = marker_file_angles(padded, markerset, args.sequence, cleaning)
            angles, gaps = result.angles, result.gaps
    if gaps is not None and gaps.unfilled:
        lines = gaps.summary().splitlines()
        shown = lines[:11] + ([f"  … {len(lines) - 11} more marker(s)"]
                              if len(lines) > 11 else [])
        print(f"mocap angles: {source}: " + "\n".join(shown), file=sys.stderr)
    for warning in caught:
        if issubclass(warning.category, AnatomicalOffsetWarning):
            if getattr(args, "offsets_said", False):
                continue                   # said once per run, not once per file
            args.offsets_said = True
        if issubclass(warning.category, ours):
            print(f"mocap angles: warning: {warning.message}", file=sys.stderr)
        else:
            warnings.showwarning(warning.message, warning.category, warning.filename,
                                 warning.lineno)
    cycles = None
    if args.cycles is not None:
        from mocap.plugingait.events import check_events, gait_events, normalise_cycles

        cycles = normalise_cycles(angles, gait_events(trial))
        check_events(cycles, str(source))
    write_angles_csv(angles, target)
    label = "clinical, Plug-in Gait" if clinical else args.sequence
    if plot is not None:
        plot_angles(angles, plot, title=f"{source.name} ({markerset.name}, {label})")
    if cycles is not None:
        _write_cycles(cycles, source, args)
    if getattr(args, "parameters", None) is not None:
        from mocap.plugingait.parameters import gait_parameters, write_parameters

        write_parameters(gait_parameters(trial), args.parameters)


def _clinical_angles(trial, args: argparse.Namespace):
    """Plug-in Gait angles of one walk: the library's recipe with the command's options."""
    from mocap.pipeline import Cleaning, clinical_angles

    flat = {"on": True, "off": False}.get(args.flat_foot, "auto")
    cleaning = Cleaning(max_gap_seconds=args.fill_gaps, lowpass_hz=args.lowpass,
                        order=args.order, short_runs=args.short_runs)
    result = clinical_angles(trial, args.static_trial, cleaning=cleaning, flat_foot=flat,
                             upper_body=getattr(args, "upper_body", False))
    return result.angles, result.gaps


def _write_cycles(cycles, source: Path, args: argparse.Namespace) -> None:
    """The tidy cycles CSV and its mean ± SD plot beside it (.png)."""
    from mocap.atomic import atomic_path, make_folder
    from mocap.plugingait.events import cycles_figure, write_cycles_csv

    where = Path(args.cycles)
    csv_path = where / f"{source.stem}.csv" if args.cycles_folder else where
    if args.cycles_folder:
        make_folder(where)
    write_cycles_csv(cycles, csv_path)
    figure = cycles_figure(cycles, title=f"{source.name}: mean ± SD of "
                                         f"{cycles.side.count('l')} left and "
                                         f"{cycles.side.count('r')} right cycles")
    with atomic_path(csv_path.with_suffix(".png")) as tmp:
        figure.savefig(tmp, dpi=100, format="png")
