"""The ``mocap info`` and ``mocap convert`` commands (marker files in, summaries or files out)."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from mocap.errors import MocapError
from mocap.trial import Trial


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``info`` and ``convert`` to the ``mocap`` command line."""
    info = subparsers.add_parser(
        "info",
        help="summarise marker files: rate, frames, duration, markers, units, gaps",
        description="Summarise C3D, CSV or TRC marker files: sampling rate, frames, "
                    "duration, marker labels, units as stored, and per marker the "
                    "fraction of frames missing, the number of gaps and the longest gap. "
                    "Damaged files are reported, one line each, and make the exit "
                    "status 2.",
    )
    info.add_argument("files", nargs="+", metavar="FILE",
                      help="marker files (.c3d, .csv, .trc, any case); a folder stands for "
                           "every marker file below it")
    info.add_argument("--json", action="store_true",
                      help="print one JSON object per file (one per line) with path, format, "
                           "rate, frames, duration, markers, units, missing, gaps, "
                           "longest_gap, warnings")
    info.add_argument("--markers", action="store_true",
                      help="in the text form, list every marker with its missing fraction "
                           "and gaps (the JSON form always has them)")
    info.set_defaults(func=run_info)

    convert = subparsers.add_parser(
        "convert",
        help="convert a marker file between C3D, CSV and TRC",
        description="Convert a marker file to another format, chosen by the output "
                    "suffix: .c3d, .csv (time and <label>_x/_y/_z in metres) or .trc. "
                    "Missing samples stay missing; the output appears only when "
                    "complete.",
    )
    convert.add_argument("input", metavar="IN", help="marker file to read (.c3d, .csv, .trc)")
    convert.add_argument("output", metavar="OUT", help="file to write; its suffix picks the "
                                                      "format (.c3d, .csv, .trc)")
    convert.add_argument("--units", choices=("mm", "cm", "m"), default="mm",
                         help="length unit stored in a C3D or TRC output (default mm; CSV "
                              "output is always metres)")
    convert.set_defaults(func=run_convert)


# ---------------------------------------------------------------- info

def gap_table(trial) -> tuple[np.ndarray, np.ndarray]:
    """Number of gaps and longest gap (frames) per marker, vectorised.

    Parameters
    ----------
    trial : Trial

    Returns
    -------
    gaps : ndarray, shape (markers,), int
        Runs of consecutive missing frames.
    longest : ndarray, shape (markers,), int
        Length of the longest run, in frames.
    """
    markers = len(trial.labels)
    missing = np.isnan(trial.points).any(axis=2).T.astype(np.int8)    # (markers, frames)
    edges = np.diff(np.pad(missing, ((0, 0), (1, 1))), axis=1)
    starts = np.argwhere(edges == 1)
    ends = np.argwhere(edges == -1)
    gaps = np.bincount(starts[:, 0], minlength=markers)
    longest = np.zeros(markers, dtype=int)
    np.maximum.at(longest, starts[:, 0], ends[:, 1] - starts[:, 1])
    return gaps, longest


def summarise(trial) -> dict:
    """The ``mocap info --json`` object of one trial (DESIGN 3.2b and extras)."""
    gaps, longest = gap_table(trial)
    missing = trial.missing_fraction()
    summary = {
        "path": trial.path,
        "format": trial.format,
        "rate": trial.rate,
        "frames": trial.frames,
        "duration": trial.duration,
        "markers": list(trial.labels),
        "units": trial.units,
        "missing": missing,
        "missing_overall": float(np.mean(list(missing.values()))) if missing else 0.0,
        "gaps": {label: int(n) for label, n in zip(trial.labels, gaps)},
        "longest_gap": {label: int(n) for label, n in zip(trial.labels, longest)},
        "analog_channels": len(trial.analog_labels),
        "analog_rate": trial.analog_rate,
        "warnings": list(trial.metadata.get("warnings", [])),
    }
    if "reader" in trial.metadata:
        summary["reader"] = trial.metadata["reader"]
    if "modelled" in trial.metadata:
        summary["modelled_points"] = list(trial.metadata["modelled"]["labels"])
    if "events" in trial.metadata:
        summary["events"] = trial.metadata["events"]
    return summary


def format_summary(summary: dict, list_markers: bool = False) -> str:
    """Readable text form of :func:`summarise`'s dictionary."""
    markers = summary["markers"]
    with_gaps = [label for label in markers if summary["gaps"][label]]
    reader = f" (read by {summary['reader']})" if "reader" in summary else ""
    lines = [
        f"path:      {summary['path']}",
        f"format:    {summary['format']}{reader}",
        f"rate:      {summary['rate']:g} Hz",
        f"frames:    {summary['frames']} ({summary['duration']:.3f} s)",
        f"markers:   {len(markers)}"
        + (f" ({', '.join(markers[:8])}{', …' if len(markers) > 8 else ''})" if markers
           else ""),
        f"units:     {summary['units'] or '(not stated)'}",
        f"missing:   {100 * summary['missing_overall']:.1f}% of marker-frames; "
        f"{len(with_gaps)} of {len(markers)} markers have gaps",
    ]
    if summary["analog_channels"]:
        lines.append(f"analogs:   {summary['analog_channels']} channels at "
                     f"{summary['analog_rate']:g} Hz")
    if summary.get("modelled_points"):
        lines.append(f"modelled:  {len(summary['modelled_points'])} computed points "
                     f"(angles, forces …) kept apart from the markers")
    if summary.get("events"):
        shown = ", ".join(f"{e['context']} {e['label']} {e['time']:.2f} s".strip()
                          for e in summary["events"][:6])
        more = f" … ({len(summary['events'])} in all)" if len(summary["events"]) > 6 else ""
        lines.append(f"events:    {shown}{more}")
    for warning in summary["warnings"]:
        lines.append(f"warning:   {warning}")
    shown = markers if list_markers else with_gaps
    if shown:
        width = max(len(label) for label in shown)
        lines.append("")
        lines.append(f"{'marker':<{width}}  missing  gaps  longest gap (frames)")
        for label in shown:
            lines.append(f"{label:<{width}}  {100 * summary['missing'][label]:6.1f}%  "
                         f"{summary['gaps'][label]:4d}  {summary['longest_gap'][label]:d}")
    return "\n".join(lines)


def _expand(paths: list[str]) -> list[Path]:
    from mocap.io import formats

    known = {suffix for suffix, f in formats().items() if f.kind == "markers"}
    files: list[Path] = []
    for name in paths:
        path = Path(name)
        if path.is_dir():
            files += sorted(p for p in path.rglob("*")
                            if p.is_file() and p.suffix.lower() in known)
        else:
            files.append(path)
    return files


def read_marker_file(path) -> Trial:
    """A marker trial from ``path``; MocapError for motion formats such as BVH."""
    from mocap.io import format_of, read

    file_format = format_of(path)
    if file_format.kind != "markers":
        raise MocapError(f"a {file_format.description} file holds joint motion, not "
                         f"markers (use .c3d, .csv or .trc)", path)
    return read(path)


def run_info(args: argparse.Namespace) -> int:
    """Handler of ``mocap info``."""
    from tqdm.auto import tqdm

    from mocap.progress import progress

    files = _expand(args.files)
    if not files:
        raise MocapError("no marker files found in " + ", ".join(args.files))
    if len(files) == 1:
        trial = read_marker_file(files[0])    # a MocapError becomes the CLI's one line
        _print_summary(summarise(trial), args)
        return 0
    status = 0
    for path in progress(files, "reading marker files"):
        try:
            trial = read_marker_file(path)
        except MocapError as error:
            # One line per bad file, printed above the progress bar, and go on.
            tqdm.write(f"mocap info: error: {error}", file=sys.stderr)
            status = 2
            continue
        _print_summary(summarise(trial), args)
        if not args.json:
            print()
    return status


def _print_summary(summary: dict, args: argparse.Namespace) -> None:
    if args.json:
        print(json.dumps(summary, allow_nan=False, default=_json_default))
    else:
        print(format_summary(summary, list_markers=args.markers))


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


# ---------------------------------------------------------------- convert

def run_convert(args: argparse.Namespace) -> int:
    """Handler of ``mocap convert``."""
    from mocap.io import format_of, write

    source, target = Path(args.input), Path(args.output)
    target_format = format_of(target, for_writing=True)     # fail before reading
    if target_format.kind != "markers":
        raise MocapError(f"convert writes marker files (.c3d, .csv, .trc), not "
                         f"{target_format.description}", target)
    if source.exists() and target.exists() and source.resolve() == target.resolve():
        raise MocapError("output is the input file; choose another name", target)
    trial = read_marker_file(source)
    options = {"units": args.units} if target_format.name in ("c3d", "trc") else {}
    write(trial, target, **options)
    dropped = []
    if trial.analog_labels and target_format.name != "c3d":
        dropped.append(f"{len(trial.analog_labels)} analog channels")
    if "modelled" in trial.metadata:
        dropped.append(f"{len(trial.metadata['modelled']['labels'])} modelled points "
                       f"(angles, forces …)")
    if dropped:
        print(f"note: {' and '.join(dropped)} not written; {target.suffix} holds markers",
              file=sys.stderr)
    print(f"wrote {target} ({trial.frames} frames, {len(trial.labels)} markers, "
          f"{trial.rate:g} Hz)", file=sys.stderr)
    return 0
