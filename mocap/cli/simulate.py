"""``mocap simulate``: run a TOML scene (``docs/formats/scene-toml.md``) and save the frames (and a GIF/MP4)."""
from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

from dynamics.scenes.build import load_scene
from dynamics.scenes.run import run_scene
from dynamics.scenes.schema import SCENES_DIR, example_scene_path
from dynamics.viz.render import render_animation
from mocap.cli import options
from mocap.cli.commands import Subparsers, summary
from mocap.errors import MocapError


def register(subparsers: Subparsers) -> None:
    """Add this package's sub-commands to ``subparsers``."""
    parser = subparsers.add_parser(
        "simulate", help=summary("simulate"),
        description="Run a simulation scene file (TOML, format in the README) and write its saved frames to "
                    "an .npz file (times, positions, springs, temperature, energy, rigid "
                    "bodies), optionally also an animation. SCENE may be a path or the name "
                    "of a shipped example (see --list-examples).",
    )
    parser.add_argument("scene", nargs="?", metavar="SCENE.toml",
                        help="scene file, or an example name such as 'hanging-cloth'")
    parser.add_argument("-o", "--output", metavar="OUT.npz",
                        help="where to write the frames (.npz); required unless --list-examples")
    parser.add_argument("--gif", metavar="OUT.gif", help="also write an animated GIF of the run")
    parser.add_argument("--mp4", metavar="OUT.mp4",
                        help="also write an MP4 of the run (needs ffmpeg on the PATH)")
    parser.add_argument("--steps", type=options.whole(1, 100_000_000), metavar="N",
                        help="override [simulation] steps (number of time steps)")
    parser.add_argument("--dt", type=options.real(above=0, maximum=10), metavar="SECONDS",
                        help="override [simulation] dt (time step, seconds)")
    parser.add_argument("--integrator",
                        choices=("explicit-euler", "symplectic-euler", "rk4", "implicit-euler"),
                        help="override [simulation] integrator")
    parser.add_argument("--solver", choices=("projective", "direct", "cg"),
                        help="override the implicit solver (implicit-euler only)")
    parser.add_argument("--save-every", type=options.whole(1, 100_000_000), metavar="N",
                        help="override [simulation] save_every (keep every N-th step)")
    parser.add_argument("--fps", type=options.FPS, default=None,
                        help="frames per second of the animation (default: real time, the "
                             "run's own speed, as mocap animate)")
    parser.add_argument("--max-frames", type=options.whole(1, 100000), default=300, metavar="N",
                        help="draw at most N frames in the animation (default 300)")
    parser.add_argument("--no-progress", action="store_true", help="do not show a progress bar")
    parser.add_argument("--list-examples", action="store_true",
                        help="list the example scenes shipped with the package and exit")
    parser.set_defaults(func=simulate_command)


def simulate_command(args: argparse.Namespace) -> int:
    """Handler of ``mocap simulate``."""


    if args.list_examples:
        for path in sorted(SCENES_DIR.glob("*.toml")):
            print(f"{path.stem:20s} {path}")
        return 0
    if not args.scene:
        raise MocapError("give a scene file (or --list-examples)")
    if not args.output:
        raise MocapError("give the output file with -o OUT.npz", args.scene)
    scene_path = Path(args.scene)
    if not scene_path.exists() and not scene_path.suffix:
        scene_path = example_scene_path(args.scene)
    for flag, value in (("--gif", args.gif), ("--mp4", args.mp4)):
        if value and Path(value).suffix.lower() != "." + flag[2:]:
            raise MocapError(f"{flag} needs a file ending in .{flag[2:]}", value)
    if args.mp4:
        if shutil.which("ffmpeg") is None:
            raise MocapError("writing MP4 needs ffmpeg on the PATH; use --gif instead", args.mp4)
    scene = load_scene(scene_path)
    if args.steps is not None:
        if args.steps < 1:
            raise MocapError("--steps must be at least 1")
        scene.steps = args.steps
    if args.dt is not None:
        if not args.dt > 0:
            raise MocapError("--dt must be positive")
        scene.dt = args.dt
    if args.integrator:
        scene.integrator = args.integrator
    if args.solver:
        scene.solver = args.solver
    if args.save_every is not None:
        if args.save_every < 1:
            raise MocapError("--save-every must be at least 1")
        scene.save_every = args.save_every
    if args.fps is not None and not args.fps > 0:
        raise MocapError("--fps must be positive")
    result = run_scene(scene, show_progress=False if args.no_progress else None)
    result.save(args.output)
    summary = (f"{scene_path}: {scene.steps} steps of {scene.dt:g} s ({scene.integrator}), "
               f"{result.positions.shape[1]} particles, {len(result.springs)} springs, "
               f"{len(result.times)} saved frame{'s' if len(result.times) != 1 else ''} "
               f"-> {args.output}")
    for video in (args.gif, args.mp4):
        if video:
            drawn = render_animation(result.arrays(), video, fps=args.fps,
                                     max_frames=args.max_frames,
                                     title=scene.title or scene_path.stem)
            summary += f"; {drawn} frames -> {video}"
    print(summary, file=sys.stderr)
    return 0
