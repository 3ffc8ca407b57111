"""``mocap view``: one self-contained HTML page to turn, scrub and play trials and motions
(:mod:`mocap.view`)."""
from __future__ import annotations

import argparse
import sys
import time

from mocap.cli import options
from mocap.cli.commands import Subparsers, summary
from mocap.cli.paths import output_format, refuse_overwrite
from mocap.errors import MocapError
from mocap.view import view_files


def register(subparsers: Subparsers) -> None:
    """Add ``view`` to ``subparsers``."""
    view = subparsers.add_parser(
        "view", help=summary("view"),
        description="Write one HTML file (three.js inside it: no network needed, opens from "
                    "disk) that shows the files overlaid in one lab, each in its own colour: "
                    "markers (labels on hover, gaps as gaps) with their marker set's "
                    "segments, BVH/ASF-AMC skeletons as bones, force plates with the ground "
                    "reaction at the centre of pressure (1 m per kN), the estimated reaction "
                    "under each foot of a dynamics check, and joint-angle curves with a cursor at the frame. "
                    "Play, pause, scrub, frame step, speed (real time by default), an orbiting "
                    "camera and a floor grid in metres. Z up when any file is a Z-up marker "
                    "trial, else Y up.",
        epilog="Examples: mocap view walk.c3d -o walk.html;  mocap view walk.c3d "
               "walk_synth.bvh --angles walk_angles.csv --curves r_thigh.Y,r_shank.Y;  "
               "mocap view walk.bvh --check check.json (from mocap check walk.bvh --json)")
    view.add_argument("files", nargs="+", metavar="FILE",
                      help="marker trials (.c3d, .trc, .csv), motions (.bvh, .amc with its "
                           ".asf, joint-angle .csv)")
    view.add_argument("-o", "--output", default="view.html", metavar="OUT.html",
                      help="the page to write (default view.html)")
    view.add_argument("--angles", metavar="CSV",
                      help="joint-angle CSV (as mocap angles writes it) drawn below the scene")
    view.add_argument("--curves", metavar="COL[,COL…]",
                      help="its columns to draw, e.g. r_thigh.Y,r_shank.Y (default: the "
                           "hip, knee and ankle flexions of clinical angles, else the first "
                           "six)")
    view.add_argument("--check", metavar="JSON",
                      help="output of mocap check --json: draw its estimated ground reaction "
                           "under each foot")
    view.add_argument("--markerset", "-m", default="auto", metavar="SET",
                      help="marker set whose segments are drawn over a marker trial: a preset "
                           "(synthetic15, plugingait-lower, plugingait-full), a TOML file, "
                           "'none', or 'auto' (default: the preset with the most segments "
                           "whose markers the trial has)")
    view.add_argument("--up", choices=("auto", "z", "y"), default="auto",
                      help="vertical axis of marker trials (default auto: Z unless the "
                           "markers stand along Y)")
    view.add_argument("--asf", metavar="ASF",
                      help="ASF skeleton of an AMC motion (default: found beside it)")
    view.add_argument("--units", choices=("m", "cm", "mm", "in", "cmu"),
                      help="length unit of BVH/ASF inputs (default: detected)")
    view.add_argument("--rate", type=options.RATE, default=120.0, metavar="HZ",
                      help="frame rate of an AMC motion (default 120)")
    view.add_argument("--title", help="title shown on the page (default: the file names)")
    view.set_defaults(func=run_view)


def run_view(args: argparse.Namespace) -> int:
    """Handler of ``mocap view``."""
    output_format(args.output, {".html": "html", ".htm": "html"})
    refuse_overwrite(args.output, [p for p in (args.angles, args.check) if p])
    curves = [c.strip() for c in args.curves.split(",") if c.strip()] if args.curves else None
    if args.curves is not None and not curves:
        raise MocapError("--curves names no column")
    start = time.perf_counter()
    view = view_files(args.files, angles=args.angles, curves=curves, check=args.check,
                      markerset=args.markerset, asf=args.asf, units=args.units,
                      rate=args.rate, up=args.up, title=args.title)
    size = view.write(args.output)
    scene = view.scene
    frames = max(layer.frames for layer in scene.layers)
    print(f"wrote {args.output} ({size / 1e6:.2f} MB, {len(scene.layers)} "
          f"layer{'' if len(scene.layers) == 1 else 's'}, {frames} frames, "
          f"{len(scene.plates)} force plate{'' if len(scene.plates) == 1 else 's'}, "
          f"{time.perf_counter() - start:.2f} s)", file=sys.stderr)
    for note in scene.notes:
        if not note.startswith("check:"):
            print(f"note: {note}", file=sys.stderr)
    return 0
