"""``mocap check``, ``mocap export`` and ``mocap animate``: motions given a body.

MOTION may be a BVH file, an AMC file (its ASF found beside it or given with ``--asf``),
a joint-angle CSV (DESIGN 3.2, played on the default body) or a marker trial
(C3D/TRC/CSV) with ``--markerset``.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from dynamics.humanoid.check import Thresholds, check_motion
from dynamics.humanoid.model import JOINT_OF_SEGMENT
from dynamics.humanoid.tracking import simulate_tracking
from dynamics.secondary import simulate_secondary
from dynamics.viz.animate import animate_motion, plot_check
from mocap.body.anthropometry import segment_kind
from mocap.body.retarget import reduce_to_segments
from mocap.cli import options
from mocap.cli.commands import summary
from mocap.errors import MocapError
from mocap.io.bvh import units_note
from mocap.io.export import EXPORT_FORMATS, export_motion
from mocap.io.motion import read_motion

#: Formats of ``mocap export``.


def _motion_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("motion", metavar="MOTION",
                        help="motion file: .bvh, .amc (with its .asf), a joint-angle .csv, or a "
                             "marker trial (.c3d, .trc, .csv) with --markerset")
    parser.add_argument("--asf", metavar="ASF",
                        help="ASF skeleton of an AMC motion (default: <name>.asf beside it, "
                             "or the longest prefix of the name cut at _ or -: 01.asf for "
                             "01_01.amc as in CMU, HDM_bd.asf for HDM_bd_01-01_01_120.amc "
                             "as in HDM05)")
    parser.add_argument("--markerset", "-m", metavar="SET",
                        help="marker set of a marker trial: preset name (synthetic15, "
                             "plugingait-lower) or TOML file")
    parser.add_argument("--units", choices=("m", "cm", "mm", "in", "cmu"),
                        help="length unit of the input BVH (or ASF) file; detected from the "
                             "standing height of its first frame when not given (and printed)")
    parser.add_argument("--rate", type=options.RATE, default=120.0, metavar="HZ",
                        help="frame rate of an AMC motion, which does not store it "
                             "(default 120, as CMU and HDM05)")
    parser.add_argument("--joint-map", metavar="FILE.toml",
                        help="which joint is which body segment, for rigs whose joint names "
                             "are not recognised: lines such as l_thigh = \"MyLeftThigh\" "
                             "(segments: pelvis, thorax, head, l_/r_upperarm, forearm, hand, "
                             "thigh, shank, foot)")


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``check``, ``export`` and ``animate`` to ``subparsers``."""
    check = subparsers.add_parser(
        "check", help=summary("check"),
        description="Inverse dynamics of the motion on a 15-segment body (de Leva 1996 "
                    "inertias scaled to the skeleton and --mass): residual force and torque "
                    "at the root that ground reactions inside friction cones cannot supply, "
                    "foot skating, floor penetration, floating, peak joint torques, and a "
                    "verdict with reasons. The floor is y = 0, Y up (z = 0 of a "
                    "Z-up marker lab). A lower-body marker set is enough: the trunk, head "
                    "and arms are then carried rigidly by the pelvis. In text and --json, "
                    "joint torques are named by the segment the joint moves (l_thigh: left hip, "
                    "l_shank: left knee, l_foot: left ankle).",
        epilog="Examples: mocap check walk.bvh --mass 70 --json;  "
               "mocap check 01_01.amc --plot check.png;  "
               "mocap check walk.c3d --markerset synthetic15")
    _motion_options(check)
    check.add_argument("--mass", type=options.MASS, default=75.0, metavar="KG",
                       help="body mass in kg (default 75)")
    check.add_argument("--sex", choices=("male", "female"), default="male",
                       help="which de Leva table of segment parameters (default male)")
    check.add_argument("--mu", type=options.real(0, 10), default=0.8,
                       help="floor friction coefficient (default 0.8)")
    check.add_argument("--max-residual", type=options.real(above=0, maximum=1000), default=5.0, metavar="PCT",
                       help="RMS residual force above which the motion is implausible, in %% "
                            "of body weight (default 5; captured walking on a lower-body "
                            "marker set scores about 2.5-7)")
    check.add_argument("--max-penetration", type=options.real(0, 10000), default=20.0, metavar="MM",
                       help="deepest floor penetration allowed, mm (default 20)")
    check.add_argument("--floor", default="0", metavar="Y|auto",
                       help="height of the floor in the motion file, metres along the up "
                            "axis (default 0), or 'auto': where the feet stand still")
    check.add_argument("--json", action="store_true",
                       help="print one JSON object instead of text (keys as in the README)")
    check.add_argument("--plot", metavar="OUT.png",
                       help="also plot residuals, ground reactions, joint torques and the "
                            "lowest point over time (.png, .pdf, .svg)")
    check.set_defaults(func=run_check)

    export = subparsers.add_parser(
        "export", help=summary("export"),
        description="Convert a motion: bvh (hierarchy + channels, centimetres), csv (joint "
                    "angles as mocap angles writes them, in a Z-up lab), c3d/trc (one marker per joint and "
                    "end site, Z-up lab, stored in millimetres as C3D and TRC files usually "
                    "are), mot (OpenSim storage: root translation and "
                    "joint Euler angles in degrees: the csv's angles, Z-up lab), json "
                    "(skeleton, root translation, joint quaternions and joint positions).",
        epilog="Examples: mocap export 01_01.amc --format bvh -o 01_01.bvh;  "
               "mocap export walk.bvh --format mot -o walk.mot")
    _motion_options(export)
    export.add_argument("--format", "-f", required=True, choices=EXPORT_FORMATS,
                        help="output format")
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
    export.add_argument("--model", choices=("gait2392", "rajagopal"),
                        help="with --format mot: write the coordinates of this OpenSim model "
                             "(pelvis_tilt … pelvis_tx/ty/tz, hip_flexion_r, knee_angle_r, "
                             "ankle_angle_r …) with its names, signs and units, Y up "
                             "(docs/opensim.md)")
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


def run_check(args: argparse.Namespace) -> int:
    """Handler of ``mocap check``."""

    if not args.mass > 0:
        raise MocapError(f"--mass must be positive, got {args.mass}")
    if not (args.max_residual > 0 and args.max_penetration >= 0):
        raise MocapError("--max-residual must be positive and --max-penetration not negative")
    if args.plot and Path(args.plot).suffix.lower() not in (".png", ".pdf", ".svg"):
        raise MocapError("the plot must be a .png, .pdf or .svg file", args.plot)
    motion = _load(args)
    if args.floor == "auto":
        floor: float | str = "auto"
    else:
        try:
            floor = float(args.floor)
        except ValueError:
            raise MocapError(f"--floor must be a height in metres or 'auto', got "
                             f"{args.floor!r}") from None
    limits = Thresholds(residual_rms_pct_bw=args.max_residual,
                        penetration_mm=args.max_penetration)
    report = check_motion(motion, body_mass=args.mass, sex=args.sex, mu=args.mu,
                          thresholds=limits, floor=floor)
    summary = {"path": str(args.motion), **report.summary()}
    _report_input(args, motion)
    if args.plot:
        plot_check(report, args.plot)
    if args.json:
        print(json.dumps(summary))
        return 0
    print(f"{args.motion}: {summary['verdict']}  ({report.frames} frames at "
          f"{report.rate:g} Hz, {report.mass_kg:g} kg)")
    print(f"  residual force   RMS {summary['residual_force_rms_N']:8.1f} N "
          f"({summary['residual_force_rms_pct_bw']:.1f} % BW), peak "
          f"{summary['residual_force_peak_N']:.1f} N ({summary['residual_force_peak_pct_bw']:.1f} % BW)")
    print(f"  residual torque  RMS {summary['residual_torque_rms_Nm']:8.1f} N·m, peak "
          f"{summary['residual_torque_peak_Nm']:.1f} N·m (about the centre of mass)")
    print(f"  foot skating     {summary['foot_skate_mm']:.1f} mm per frame in contact "
          f"(skating ratio {summary['skating_ratio']:.2f})")
    print(f"  penetration      {summary['penetration_mm']:.1f} mm   floating "
          f"{summary['floating_mm']:.1f} mm ({summary['floating_frames']} frames unsupported)")

    def joint(segment: str) -> str:
        joint_name = JOINT_OF_SEGMENT.get(segment_kind(segment))
        return f"{segment} ({joint_name})" if joint_name else segment

    # named as in --json (by the segment each joint moves), the joint in brackets
    print("  peak joint torques (N·m): " + ", ".join(
        f"{joint(name)} {value:.0f}" for name, value in summary["peak_joint_torque_Nm"].items()))
    if summary["floor_m"]:
        print(f"  (floor taken at {summary['floor_m'] * 1000:.0f} mm)")
    if summary["lumped_segments"]:
        print("  (no markers for " + ", ".join(summary["lumped_segments"]) + ": carried "
              "rigidly by the pelvis)")
    for reason in summary["reasons"]:
        print(f"  - {reason}")
    return 0


def run_export(args: argparse.Namespace) -> int:
    """Handler of ``mocap export``."""

    if args.model and args.format != "mot":
        raise MocapError("--model goes with --format mot (OpenSim coordinates)")
    if args.precision is not None and args.format not in ("trc", "mot"):
        raise MocapError("--precision applies to trc and mot output")
    if args.up != "z" and args.format not in ("c3d", "trc"):
        raise MocapError("--up applies to c3d and trc joint markers (bvh, mot and json are "
                         "Y up already; csv angles are in the Z-up lab)")
    if args.format != "bvh" and (args.out_units or args.round_rate):
        raise MocapError("--out-units and --round-rate apply to --format bvh only")
    motion = _load(args)
    if args.body:
        motion = reduce_to_segments(motion)
    export_motion(motion, args.output, args.format, sequence=args.sequence,
                  model=args.model, up=args.up, precision=args.precision,
                  units=args.out_units or "cm", round_rate=args.round_rate)
    _report_input(args, motion)
    print(f"wrote {args.output} ({args.format}, {motion.frames} frames)", file=sys.stderr)
    return 0


def run_animate(args: argparse.Namespace) -> int:
    """Handler of ``mocap animate``."""

    output = Path(args.output)
    if output.suffix.lower() not in (".gif", ".mp4"):
        raise MocapError("the animation must be a .gif or .mp4 file", output)
    if args.max_frames < 1:
        raise MocapError(f"--max-frames must be at least 1, got {args.max_frames}")
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
    print(f"wrote {output} ({frames} frames)", file=sys.stderr)
    return 0
