"""The ``mocap info`` and ``mocap convert`` commands (marker files in, summaries or files out)."""
from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

import numpy as np

from mocap.cli import options
from mocap.cli.commands import Subparsers, summary
from mocap.errors import MocapError, MocapWarning, one_line
from mocap.io import format_of, motion_suffixes, read, suffixes, write
from mocap.io.c3d.outputs import computed_positions
from mocap.io.discovery import find_files
from mocap.progress import progress, write_line
from mocap.summary import format_summary, summarise
from mocap.trial import Trial


def register(subparsers: Subparsers) -> None:
    """Add ``info`` and ``convert`` to the ``mocap`` command line."""
    info = subparsers.add_parser(
        "info", help=summary("info"),
        description="Summarise C3D, CSV or TRC marker files: sampling rate, frames, "
                    "duration, marker labels, units as stored, and per marker the "
                    "fraction of frames missing, the number of gaps and the longest gap. "
                    "Damaged files are reported, one line each, and make the exit "
                    "status 2. A BVH or ASF/AMC skeleton motion named directly gets its rate, "
                    "frames, duration, joints and length unit (detected as check and export "
                    "read it).",
    )
    info.add_argument("files", nargs="+", metavar="FILE",
                      help="marker files (.c3d, .csv, .trc, any case) or motions (.bvh, .amc); a folder stands for "
                           "the marker files directly inside it (sub-folders are not searched)")
    info.add_argument("--json", action="store_true",
                      help="print one JSON object per file (one per line) with path, format, "
                           "rate, frames, duration, markers, units, missing, gaps, "
                           "longest_gap, warnings")
    info.add_argument("--markers", action="store_true",
                      help="in the text form, list every marker with its missing fraction "
                           "and gaps (the JSON form always has them)")
    info.set_defaults(func=run_info)

    convert = subparsers.add_parser(
        "convert", help=summary("convert"),
        description="Convert a marker file to another format, chosen by the output "
                    "suffix: .c3d, .csv (time and <label>_x/_y/_z in metres) or .trc. "
                    "Missing samples stay missing; the output appears only when "
                    "complete. Only the markers are written: a model's outputs stored "
                    "as points (Plug-in Gait angles, forces, axis points such as PELO, "
                    "joint centres, CentreOfMass) are left out, with a note.",
    )
    convert.add_argument("input", metavar="IN", help="marker file to read (.c3d, .csv, .trc)")
    convert.add_argument("out", nargs="?", metavar="OUT",
                         help="file to write; its suffix picks the format (.c3d, .csv, .trc)")
    convert.add_argument("-o", "--output", dest="output", metavar="OUT",
                         help="the output file, as every command spells it (instead of OUT)")
    convert.add_argument("--out-units", "--units", dest="units", choices=("mm", "cm", "m"),
                         default=None,
                         help="length unit stored in a C3D or TRC output (default mm; CSV "
                              "output is always metres); spelt --out-units as in export, "
                              "where --units is the input's")
    add_output_options(convert)
    convert.set_defaults(func=run_convert)


def add_output_options(parser: argparse.ArgumentParser) -> None:
    """``--up`` and ``--precision``, shared by ``convert`` and ``export``."""
    parser.add_argument("--up", choices=("z", "y"), default="z",
                        help="vertical axis of the written lab: z as captured (C3D, Vicon: "
                             "X anterior, Y left, Z up) or y for OpenSim and Blender (X "
                             "anterior, Y up, Z right: the lab turned -90 degrees about X)")
    parser.add_argument("--precision", type=options.whole(0, 15), metavar="DECIMALS",
                        help="decimal places of coordinates in a TRC or CSV output, in the "
                             "file's unit (default: 1 nm, i.e. 6 in mm, 9 in m; at least 1 "
                             "um: 3 in mm, 6 in m)")


# ---------------------------------------------------------------- info

def _expand(paths: list[str]) -> list[Path]:
    return find_files(paths, suffixes("markers"), missing="keep")


def read_marker_file(path, quiet: bool = False) -> Trial:
    """A marker trial from ``path``; MocapError for motion formats such as BVH.

    ``quiet`` keeps the reader's warnings in the trial's metadata only (``info`` shows them
    in its summary); otherwise each is printed as a ``warning:`` line.
    """
    file_format = format_of(path)
    if file_format.kind != "markers":
        raise MocapError(f"a {file_format.description} file holds joint motion, not "
                         f"markers (use .c3d, .csv or .trc; mocap check, export and animate "
                         f"read motions)", path)
    with warnings.catch_warnings():
        if quiet:
            warnings.simplefilter("ignore", MocapWarning)
        return read(path)


def run_info(args: argparse.Namespace) -> int:
    """Handler of ``mocap info``."""


    files = _expand(args.files)
    if not files:
        raise MocapError("no marker files found in " + ", ".join(args.files))
    if len(files) == 1:
        # a MocapError becomes the CLI's one line
        _print_summary(_summary_of(files[0]), args)
        return 0
    status = 0
    for path in progress(files, "reading files"):
        try:
            summary = _summary_of(path)
        except MocapError as error:
            # One line per bad file, printed above the progress bar, and go on.
            write_line(f"mocap info: error: {error}")
            status = 2
            continue
        _print_summary(summary, args)
        if not args.json:
            print()
    return status


def _summary_of(path: Path) -> dict:
    """``summarise`` of a marker file, or :func:`motion_summary` of a BVH or AMC."""
    if path.suffix.lower() in motion_suffixes():     # by suffix: no header read twice
        return motion_summary(path)
    return summarise(read_marker_file(path, quiet=True))


def motion_summary(path: Path) -> dict:
    """What ``mocap info`` says of a skeleton motion (BVH, ASF/AMC): path, format, rate (Hz),
    frames, duration (s), joints, units (the file's length unit, detected as ``check`` and
    ``export`` read it), units_detected, height_file_units, warnings."""
    from mocap.io.motion import read_motion   # deferred: only motion files need it

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MocapWarning)
        motion = read_motion(path)
    meta = motion.metadata
    height = meta.get("height_file_units")
    return {"path": str(path), "format": path.suffix.lower()[1:], "rate": float(motion.rate),
            "frames": int(motion.frames),
            "duration": (motion.frames - 1) / motion.rate if motion.rate > 0 else None,
            "joints": list(motion.skeleton.names), "units": meta.get("units"),
            "units_detected": bool(meta.get("units_detected")),
            "height_file_units": None if height is None else float(height),
            "warnings": [one_line(str(w.message)) for w in caught
                         if issubclass(w.category, MocapWarning)]}


def _format_motion_summary(summary: dict) -> str:
    joints = summary["joints"]
    shown = ", ".join(joints[:8]) + (", …" if len(joints) > 8 else "")
    duration = ("unknown" if summary["duration"] is None else f"{summary['duration']:.3f} s")
    how = ("as given" if not summary["units_detected"] else
           "detected" if summary["height_file_units"] is None else
           f"detected from a standing height of {summary['height_file_units']:.4g} file units")
    lines = [f"path:      {one_line(summary['path'])}",
             f"format:    {summary['format']} (skeleton motion)",
             f"rate:      {summary['rate']:g} Hz",
             f"frames:    {summary['frames']} ({duration})",
             f"joints:    {len(joints)} ({shown})",
             f"units:     {summary['units'] or '(not stated)'} ({how}; --units of check, "
             f"export and animate overrides)"]
    lines += [f"warning:   {w}" for w in summary["warnings"]]
    return "\n".join(lines)


def _print_summary(summary: dict, args: argparse.Namespace) -> None:
    if args.json:
        print(json.dumps(summary, allow_nan=False, default=_json_default))
    elif "joints" in summary:
        print(_format_motion_summary(summary))
    else:
        print(format_summary(summary, list_markers=args.markers))


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


# ---------------------------------------------------------------- convert

def run_convert(args: argparse.Namespace) -> int:
    """Handler of ``mocap convert``."""

    if (args.out is None) == (args.output is None):
        raise MocapError("give the output file once: OUT or -o/--output")
    source, target = Path(args.input), Path(args.out or args.output)
    target_format = format_of(target, for_writing=True)     # fail before reading
    if target_format.kind != "markers":
        raise MocapError(f"convert writes marker files (.c3d, .csv, .trc), not "
                         f"{target_format.description}", target)
    if source.exists() and target.exists() and source.resolve() == target.resolve():
        raise MocapError("output is the input file; choose another name", target)
    if args.units is not None and target_format.name == "csv":
        raise MocapError("--out-units sets the unit of a C3D or TRC output; a CSV holds "
                         "metres", target)
    if args.precision is not None and target_format.name not in ("trc", "csv"):
        raise MocapError(f"--precision applies to TRC and CSV output; {target.suffix} "
                         f"stores 32-bit floats", target)
    from mocap.io.lab import rotate_trial

    source_trial = read_marker_file(source)
    computed = computed_positions(source_trial.labels) if source_trial.format == "c3d" else {}
    markers = source_trial.select([label for label in source_trial.labels
                                   if label not in computed]) if computed else source_trial
    trial = rotate_trial(markers, args.up)
    writer_options = {"units": args.units or "mm"} if target_format.name in ("c3d", "trc") \
        else {}
    if target_format.name in ("trc", "csv"):
        writer_options["precision"] = args.precision
    notes = write(trial, target, **writer_options) or []
    dropped = []
    if trial.analog_labels and target_format.name != "c3d":
        dropped.append(f"{len(trial.analog_labels)} analog channels")
    if computed:
        kinds = sorted(set(computed.values()))
        dropped.append(f"{len(computed)} computed positions ({', '.join(kinds)})")
    if source_trial.modelled is not None:
        dropped.append(f"{len(source_trial.modelled['labels'])} modelled points "
                       f"(angles, forces …)")
    if target_format.name == "csv" and trial.frames < 2 and trial.rate > 0:
        # a CSV's only clock is its time column: one row cannot carry a rate
        print(f"note: not kept in {target.name}: the rate ({trial.rate:g} Hz; a CSV's time "
              "column of one frame holds no time step)", file=sys.stderr)
    if dropped and target_format.name != "c3d":
        listed = ", ".join(dropped[:-1]) + " and " + dropped[-1] if len(dropped) > 1 \
            else dropped[0]
        print(f"note: {listed} not written; {target.suffix} holds markers", file=sys.stderr)
    elif dropped or notes:
        print(f"note: not kept in {target.name}: {'; '.join(dropped + list(notes))}",
              file=sys.stderr)
    print(f"wrote {target} ({trial.frames} frames, {len(trial.labels)} markers, "
          f"{trial.rate:g} Hz)", file=sys.stderr)
    return 0
