"""``mocap export`` and ``mocap animate``: motions given a body (``mocap check`` is in
:mod:`mocap.cli.check`).

MOTION may be a BVH file, an AMC file (its ASF found beside it or given with ``--asf``),
a joint-angle CSV (``docs/formats/angles-csv.md``, played on the default body) or a marker trial
(C3D/TRC/CSV) with ``--markerset``.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from dynamics.humanoid.tracking import simulate_tracking
from dynamics.secondary import simulate_secondary
from dynamics.viz.animate import animate_motion
from mocap.body.retarget import reduce_to_segments
from mocap.cli import options
from mocap.cli.check import _motion_options, refuse_unused_motion_options
from mocap.cli.commands import Subparsers, summary
from mocap.cli.paths import output_format
from mocap.errors import MocapError
from mocap.io.bvh import units_note
from mocap.io.export import EXPORT_FORMATS, export_motion
from mocap.io.motion import read_motion

#: Output suffix -> format of ``mocap export`` (OpenSim reads its storage as .mot or .sto).
EXPORT_SUFFIXES = {**{f".{name}": name for name in EXPORT_FORMATS}, ".sto": "mot"}


def register(subparsers: Subparsers) -> None:
    """Add ``export`` and ``animate`` to ``subparsers`` (``check`` is :mod:`mocap.cli.check`)."""
    export = subparsers.add_parser(
        "export", help=summary("export"),
        description="Convert a motion, in the format -o's suffix names (or --format): bvh "
                    "(hierarchy + channels, centimetres unless --out-units), csv (joint "
                    "angles as mocap angles writes them, in a Z-up lab), c3d/trc (one marker per joint and "
                    "end site, Z-up lab, stored in millimetres as C3D and TRC files usually "
                    "are), mot (OpenSim storage: root translation in metres and "
                    "joint Euler angles in degrees: the csv's angles, Z-up lab), json "
                    "(skeleton, root translation, joint quaternions and joint positions; "
                    "metres, Y up).",
        epilog="Examples: mocap export 01_01.amc -o 01_01.bvh;  "
               "mocap export walk.bvh -o walk.mot;  mocap export walk.bvh -o walk.trc --up y")
    _motion_options(export)
    export.add_argument("--format", "-f", choices=EXPORT_FORMATS,
                        help="output format (default: the one -o's suffix names, as every "
                             "command: walk.trc is trc; needed only for an output without "
                             "a suffix)")
    export.add_argument("-o", "--output", required=True, metavar="OUT",
                        help="output file")
    export.add_argument("--body", action="store_true",
                        help="map the skeleton onto the 15-segment body first (pelvis, "
                             "thorax, head, arms, legs)")
    export.add_argument("--sequence", default="ZXY", metavar="SEQ",
                        help="Euler sequence of csv and mot angles, scipy convention "
                             "(default ZXY)")
    export.add_argument("--out-units", choices=("m", "cm", "mm", "in"), default=None,
                        help="length unit of a bvh output (default cm; Blender wants m); "
                             "--units stays the input's")
    export.add_argument("--round-rate", action="store_true",
                        help="resample a bvh output to the nearest whole frame rate (Hz); "
                             "by default the rate is kept exactly")
    export.add_argument("--fps", type=options.real(above=0, maximum=10000), metavar="FPS",
                        help="frames per second written (rotations by slerp, positions "
                             "linearly; default: the motion's own rate)")
    export.add_argument("--model", choices=("gait2392", "rajagopal"),
                        help="with --format mot: write the coordinates of this OpenSim model "
                             "(pelvis_tilt … pelvis_tx/ty/tz, hip_flexion_r, knee_angle_r, "
                             "ankle_angle_r …) with its names, signs and units, Y up "
                             "(docs/opensim.md)")
    export.add_argument("--static", metavar="STATIC.c3d",
                        help="with --model and a Plug-in Gait marker trial: the standing "
                             "trial of the same subject; the hip, knee and ankle coordinates "
                             "are then Plug-in Gait's calibrated clinical angles (as mocap "
                             "angles --static gives them)")
    from mocap.cli.io import add_output_options
    add_output_options(export)
    export.set_defaults(func=run_export)

    animate = subparsers.add_parser(
        "animate", help=summary("animate"),
        description="Draw the motion as a stick figure over the floor, optionally with a cape "
                    "pinned to the shoulders and a rope at the head (mass-spring cloth driven "
                    "by the skeleton, colliding with the body), or replayed under physics "
                    "(forward dynamics with PD tracking and ground contact).",
        epilog="Examples: mocap animate walk.bvh --cape -o walk.gif;  "
               "mocap animate walk.bvh --physics --rope -o physics.gif")
    _motion_options(animate)
    animate.add_argument("--cape", action="store_true", help="add a cloth cape")
    animate.add_argument("--rope", action="store_true", help="add a rope at the head")
    animate.add_argument("--physics", action="store_true",
                         help="replay the motion under physics (ABA, PD servos, penalty "
                              "ground contact) and print how well it tracked")
    animate.add_argument("--mass", type=options.MASS, default=75.0, metavar="KG",
                         help="body mass for --physics (default 75)")
    animate.add_argument("--max-frames", type=options.whole(1, 100000), default=200, metavar="N",
                         help="draw at most N frames, evenly spaced (default 200)")
    animate.add_argument("--fps", type=options.FPS, metavar="FPS",
                         help="playback frames per second (default: real time, the "
                              "motion's own speed)")
    animate.add_argument("--dpi", type=options.whole(10, 600), default=80, help="resolution (default 80)")
    animate.add_argument("-o", "--output", required=True, metavar="OUT",
                         help="animation file: .gif (or .mp4 when ffmpeg is installed)")
    animate.set_defaults(func=run_animate)


# ----------------------------------------------------------------------------------------
def _load(args: argparse.Namespace):
    """The command's motion (``motion.metadata["note"]``: the unit it was read in)."""
    motion = read_motion(args.motion, asf=args.asf, markerset=args.markerset,
                         units=args.units, rate=args.rate, joint_map=args.joint_map)
    motion.metadata["note"] = (units_note(motion) or "").replace("units=", "--units")
    return motion


def _report_input(args: argparse.Namespace, motion) -> None:
    """After a command succeeded: the unit the input was read in, on stderr (not before an
    error, which stays the one line)."""
    if motion.metadata.get("note"):
        print(f"{args.motion}: {motion.metadata['note']}", file=sys.stderr)


def run_export(args: argparse.Namespace) -> int:
    """Handler of ``mocap export``."""

    args.format = output_format(args.output, EXPORT_SUFFIXES, args.format, "--format")
    refuse_unused_motion_options(args)
    if args.model and args.format != "mot":
        raise MocapError("--model goes with --format mot (OpenSim coordinates)")
    if args.precision is not None and args.format not in ("trc", "mot"):
        raise MocapError("--precision applies to trc and mot output")
    if args.up != "z" and args.format not in ("c3d", "trc"):
        raise MocapError("--up applies to c3d and trc joint markers (bvh, mot and json are "
                         "Y up already; csv angles are in the Z-up lab)")
    if args.format != "bvh" and (args.out_units or args.round_rate):
        raise MocapError("--out-units and --round-rate apply to --format bvh only")
    if args.fps is not None and args.round_rate:
        raise MocapError("give --fps or --round-rate, not both: both set the frame rate")
    if args.fps is not None and args.static is not None:
        raise MocapError("--fps resamples the motion; --static's clinical angles come at the "
                         "trial's own rate: give one of them")
    plugingait = bool(args.markerset) and str(args.markerset).startswith("plugingait")
    if args.static is not None:
        if not (args.model and plugingait):
            raise MocapError("--static calibrates Plug-in Gait's angles for an OpenSim "
                             "model: it goes with a marker trial, -m plugingait-lower (or "
                             "-full) and --model")
        if not Path(args.static).is_file():
            raise MocapError("static trial not found", args.static)
    motion = _load(args)
    if args.body:
        motion = reduce_to_segments(motion)
    if args.fps is not None and args.fps != motion.rate:
        motion = motion.resampled(args.fps)
    clinical = None
    if args.model and plugingait:
        if args.static is None:
            print(f"warning: {args.output}: hip, knee and ankle coordinates from the marker "
                  f"set's segment frames, uncalibrated (ankle and hip adduction several "
                  f"degrees off Plug-in Gait's): give --static STATIC.c3d", file=sys.stderr)
        else:
            from mocap.pipeline import clinical_angles
            clinical = clinical_angles(args.motion, args.static).angles
    notes = export_motion(motion, args.output, args.format, sequence=args.sequence,
                          model=args.model, up=args.up, precision=args.precision,
                          units=args.out_units or "cm", round_rate=args.round_rate,
                          clinical=clinical)
    _report_input(args, motion)
    for note in notes:
        print(f"note: {args.output}: {note}", file=sys.stderr)
    print(f"wrote {args.output} ({args.format}, {motion.frames} frames)", file=sys.stderr)
    return 0


def run_animate(args: argparse.Namespace) -> int:
    """Handler of ``mocap animate``."""

    output = Path(args.output)
    if output.suffix.lower() not in (".gif", ".mp4"):
        raise MocapError("the animation must be a .gif or .mp4 file", output)
    if args.max_frames < 1:
        raise MocapError(f"--max-frames must be at least 1, got {args.max_frames}")
    refuse_unused_motion_options(args)
    motion = loaded = _load(args)
    title = Path(args.motion).stem
    if args.physics:
        result = simulate_tracking(motion, body_mass=args.mass)
        motion = result.motion
        weight = args.mass * 9.81
        print(f"physics: mean joint error {result.joint_error_deg.mean():.1f}°, root drift "
              f"{result.root_error_m.max() * 1000:.0f} mm, root assist "
              f"{100 * result.assist_force.mean() / weight:.0f} % BW on average",
              file=sys.stderr)
        title += " (physics)"
    secondary = None
    if args.cape or args.rope:
        secondary = simulate_secondary(motion, cape=args.cape, rope=args.rope)
    frames = animate_motion(motion, output, secondary=secondary, fps=args.fps,
                            max_frames=args.max_frames, dpi=args.dpi, title=title)
    _report_input(args, loaded)
    print(f"wrote {output} ({frames} frame{'' if frames == 1 else 's'})", file=sys.stderr)
    return 0
