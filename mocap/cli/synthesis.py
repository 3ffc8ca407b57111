"""Sub-commands of the synthesis package: decompose, synthesize, recognize, evaluate.

``mocap decompose CORPUS --markerset SET -o model.npz``
``mocap synthesize model.npz --person P --action A -o OUT.csv|OUT.bvh``
``mocap recognize model.npz TRIAL [--json]``
``mocap evaluate CORPUS --markerset SET --leave-one-out [--plot OUT.png]``
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.rotations.angles import JointAngles
from mocap.cli import options
from mocap.io.angles_csv import write_angles_csv
from mocap.cli.clip_rate import RATE_KEY, corpus_rate_hz
from mocap.cli.commands import Subparsers, summary
from mocap.errors import MocapError
from mocap.io.bvh import write_bvh
from mocap.io.motion import read_motion
from mocap.progress import progress
from synthesis.corpus import load_corpus
from synthesis.evaluate import leave_one_out
from synthesis.methods import METHODS, configuration_name
from synthesis.model import MotionModel
from synthesis.model_file import load_model, read_trial_cycle, save_model
from synthesis.plot import plot_evaluation
from synthesis.rotations import feature_joints

OUTPUT_SUFFIXES = (".csv", ".bvh")


# --------------------------------------------------------------------------- option groups

def _rank(text: str):
    """A mode rank on the command line: an integer count, a fraction in (0, 1], or 'full'."""
    if text.lower() in ("full", "none", "auto"):
        return None
    try:
        if text.isdigit():
            value = int(text)
            if value < 1:
                raise ValueError
            return value
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a rank: give a count (e.g. 4), a kept-energy fraction in (0, 1] "
            f"(e.g. 0.99) or 'full'") from None
    if not 0.0 < value <= 1.0:
        raise argparse.ArgumentTypeError(f"energy fraction {text} must be in (0, 1]")
    return value


#: A relative ridge: 'auto' (chosen by leave-one-out) or a finite value from 0 to 1e6.
_ridge = options.real_or("auto", 0, 1e6)


def _names(text: str) -> list[str]:
    return [name.strip() for name in text.split(",") if name.strip()]


def _add_corpus_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("corpus", nargs="?", metavar="CORPUS",
                        help="folder of trials named <person>_<action>[_anything].<c3d|csv|trc|"
                             "bvh|amc> (sub-folders are ignored); angle CSVs (from mocap angles) are "
                             "read as they are; an AMC needs <person>.asf beside it")
    parser.add_argument("--manifest", metavar="FILE.csv",
                        help="CSV with columns path,person,action listing the trials instead of "
                             "a folder (relative paths from the manifest's folder)")
    parser.add_argument("--markerset", "-m", metavar="SET",
                        help="marker set (preset name such as synthetic15, or a TOML file) that "
                             "turns marker trials into joint angles")
    parser.add_argument("--sequence", default="ZXY", metavar="SEQ",
                        help="Euler sequence of the joint angles, scipy convention "
                             "(default: ZXY)")
    parser.add_argument("--samples", type=options.whole(2, 100000), default=100, metavar="N",
                        help="frames of each time-normalised cycle (default: 100)")
    parser.add_argument("--cycles", action="store_true",
                        help="detect cycles in each trial and average them (BVH/ASF-AMC: one "
                             "leg signal for the whole corpus, cycles registered; a trial "
                             "without two repetitions is used whole with a warning; others: "
                             "maxima of the most-moving angle); default: each trial is one "
                             "cycle")
    parser.add_argument("--cycle-angle", metavar="COLUMN",
                        help="angle column whose maxima cut the cycles (e.g. r_thigh.Y); "
                             "default: the angle that moves most over the corpus")
    parser.add_argument("--fill-gaps", type=options.SECONDS_GAP, default=None, metavar="SECONDS",
                        help="fill marker gaps up to this long (seconds, as in mocap angles) "
                             "before the angles; the model remembers it for later trials")
    parser.add_argument("--lowpass", type=options.CUTOFF, default=None, metavar="HZ",
                        help="zero-lag Butterworth low-pass of the markers at HZ before the "
                             "angles (e.g. 6); the model remembers it for later trials")
    parser.add_argument("--people", type=_names, metavar="P1,P2,…",
                        help="use only these people (no other file is read)")
    parser.add_argument("--actions", type=_names, metavar="A1,A2,…",
                        help="use only these actions (no other file is read)")
    parser.add_argument("--body", action="store_true",
                        help="BVH/ASF-AMC corpora: map every trial onto the 15-segment body "
                             "model even when all share one skeleton (default: the rig's own "
                             "joints; mapped only when skeletons differ)")
    parser.add_argument("--joint-map", metavar="FILE.toml",
                        help="BVH/ASF-AMC trials mapped onto the body: which joint is which "
                             "body segment, for rigs whose joint names are not recognised "
                             "(lines such as l_thigh = \"MyLeftThigh\")")


def _add_model_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--people-rank", type=_rank, default=None, metavar="R",
                        help="signature dimensions kept: a count, a kept-energy fraction, or "
                             "'full' (default: numerical rank)")
    parser.add_argument("--action-rank", type=_rank, default=None, metavar="R",
                        help="action-parameter dimensions kept (count, fraction or 'full')")
    parser.add_argument("--feature-rank", type=_rank, default=None, metavar="R",
                        help="eigenmotions kept in the joint-angle mode (count, fraction or "
                             "'full')")
    parser.add_argument("--ridge", type=_ridge, default="auto", metavar="ALPHA",
                        help="relative ridge of signature fits, or 'auto' to choose it by "
                             "leave-one-out (default)")
    parser.add_argument("--method", choices=("auto",) + tuple(METHODS),
                        default="auto",
                        help="synthesis of a missing cell: interaction (the additive model, "
                             "action mean + the person's offset, corrected by the N-mode SVD "
                             "of the person x action interaction or by a ridge map across "
                             "actions, mode, rank and ridge chosen by leave-one-out; rank 0 "
                             "is the additive model), signature (the N-mode SVD alone: "
                             "the person's signature or person basis, shrunk; no ridge "
                             "map), transfer (the older action "
                             "transfer), or auto (= interaction; default)")


def _load_corpus(args: argparse.Namespace):
    if args.corpus is None and args.manifest is None:
        raise MocapError("give a corpus folder or --manifest FILE.csv")
    if args.corpus is not None and args.manifest is not None:
        raise MocapError("give either a corpus folder or --manifest, not both")
    if getattr(args, "cycle_angle", None) is not None and not args.cycles:
        # without --cycles each trial is one cycle: the column would be ignored
        raise MocapError(f"--cycle-angle {args.cycle_angle} applies with --cycles only")
    corpus = load_corpus(args.corpus, args.manifest, people=args.people, actions=args.actions,
                         markerset=args.markerset, sequence=args.sequence, samples=args.samples,
                         cycles=args.cycles, cycle_column=args.cycle_angle,
                         lowpass_hz=args.lowpass, max_gap_seconds=args.fill_gaps,
                         progress=progress, body=args.body, joint_map=args.joint_map)
    if corpus.representation == "rotvec":
        where = "the body model" if corpus.rig["on_body"] else "the rig itself"
        print(f"mocap {args.command}: {len(corpus.segments)} joints of {where}, rotation vectors "
              "about the corpus mean (heading removed)", file=sys.stderr)
    return corpus


def _hold_out_cells(corpus, cells: list[tuple[str, str]]):
    """The corpus without the ``--hold-out PERSON:ACTION`` cells (each must be captured)."""
    for person, action in cells:
        if person not in corpus.people:
            raise MocapError(f"--hold-out {person}:{action}: no person {person!r} in the corpus "
                             f"({', '.join(corpus.people)})")
        if action not in corpus.actions:
            raise MocapError(f"--hold-out {person}:{action}: no action {action!r} in the corpus "
                             f"({', '.join(corpus.actions)})")
        if not corpus.observed[corpus.people.index(person), corpus.actions.index(action)]:
            raise MocapError(f"--hold-out {person}:{action}: the corpus has no such trial")
        corpus = corpus.without_cell(person, action)
    return corpus


def _cell(text: str) -> tuple[str, str]:
    """``PERSON:ACTION`` of ``--hold-out``."""
    person, colon, action = text.partition(":")
    if not (colon and person.strip() and action.strip()):
        raise argparse.ArgumentTypeError(f"{text!r} is not PERSON:ACTION (e.g. ben:walk)")
    return person.strip(), action.strip()


def _model_options(args: argparse.Namespace) -> dict:
    return {"people_rank": args.people_rank, "action_rank": args.action_rank,
            "feature_rank": args.feature_rank, "ridge": args.ridge, "method": args.method}


def _plain(value):
    """JSON-safe copy: NaN and infinities become null (strict JSON has no NaN)."""
    if isinstance(value, dict):
        return {key: _plain(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(item) for item in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _print_json(value) -> None:
    print(json.dumps(_plain(value), indent=2, allow_nan=False))


def _check_output(path: str, suffixes=(".npz",)) -> None:
    if Path(path).suffix.lower() not in suffixes:
        raise MocapError(f"output must end in {' or '.join(suffixes)}", path)


# --------------------------------------------------------------------------- handlers

def decompose(args: argparse.Namespace) -> int:
    """``mocap decompose``: corpus → N-mode SVD motion model (.npz)."""

    _check_output(args.output)
    corpus = _load_corpus(args)
    if args.hold_out:
        corpus = _hold_out_cells(corpus, args.hold_out)
    rate = corpus_rate_hz(path for paths in corpus.sources.values() for path in paths)
    if rate is not None:
        corpus.cleaning[RATE_KEY] = rate      # saved with the model: synthesize's clip rate
    model = MotionModel(**_model_options(args)).fit(corpus)
    save_model(model, args.output)
    summary = model.summary()
    if args.json:
        _print_json(summary)
        return 0
    ranks = summary["ranks"]
    print(f"wrote {args.output}: {len(model.people)} people × {len(model.actions)} actions × "
          f"{model.samples} samples × {len(model.columns)} angles")
    if args.hold_out:
        print("  held out (not in the model): "
              + ", ".join(f"{person} {action}" for person, action in args.hold_out))
    print(f"  ranks people/actions/features: {ranks[0]}/{ranks[1]}/{ranks[2]} "
          f"(kept energy {', '.join(f'{100 * e:.1f} %' for e in summary['energy'])})")
    if summary["imputed_people_rank"]:
        print(f"  fewer than 2 complete people: missing cells imputed with a people rank of "
              f"{summary['imputed_people_rank']} (cross-validated) before the bases; missing "
              f"cells: {', '.join(summary['missing_cells'])}")
    else:
        print(f"  bases from {len(summary['basis_people'])} complete people; missing cells: "
              f"{', '.join(summary['missing_cells']) or 'none'}")
    filled = summary.get("missing_cells_filled_by", {})
    if filled:
        print("  missing cells filled by: " + "; ".join(f"{cell}: {how}"
                                                         for cell, how in filled.items()))
    if summary["method"] == "transfer":
        print("  missing cells are synthesised by action transfer (the person's other actions "
              "through a map learned across people); blends and new people by signatures")
    for action, chosen in summary.get("interaction", {}).items():
        if not chosen["rank"]:
            gain = "the additive model (no interaction earned its place)"
        else:
            kind = configuration_name(chosen["mode"], chosen["rank"])
            if chosen["mode"] == "regression":
                kind += " (" + ", ".join(f"{name} {round(weight, 2) + 0.0:.2f}"
                                         for name, weight in chosen["map_weights"].items()) + ")"
            gain = (f"{kind}: leave-one-out {chosen['loo_rms']:.2f} against the additive "
                    f"model's {chosen['additive_loo_rms']:.2f}")
        print(f"  {action} from the other actions: {gain}")
    loo = summary["loo_rms_deg"]
    caveat = " (optimistic: imputed cells saw everyone; use 'mocap evaluate')" \
        if summary["imputed_people_rank"] else ""
    print(f"  signature dimensions {ranks[0]}, ridge α = {summary['ridge_alpha']:g}; "
          "leave-one-out synthesis RMS "
          + (f"{loo:.2f}°{caveat}" if loo == loo else "n/a (too few people)"))
    return 0


def _trial_action(model, path: str, curve, duration, given: str | None) -> str:
    """The action of a --from trial: given, from its file name, or recognised."""
    if given is not None:
        model.action_index(given)
        return given
    parts = Path(path).stem.split("_")
    if len(parts) >= 2 and parts[1] in model.actions:
        return parts[1]
    action = model.recognize(curve).action
    print(f"mocap synthesize: {path}: action not given, recognised as {action!r} "
          f"(use --from-action to set it)", file=sys.stderr)
    return action


def synthesize(args: argparse.Namespace) -> int:
    """``mocap synthesize``: one cycle of a (known, blended or new) person doing an action."""

    suffix = Path(args.output).suffix.lower()
    if suffix not in OUTPUT_SUFFIXES:
        raise MocapError("output must be an angle CSV (.csv) or a BVH file (.bvh)", args.output)
    if (args.person is None) == (not args.trials):
        raise MocapError("give either --person P (optionally --to P2 --weight W) or "
                         "--from TRIAL for a new person")
    if args.to is not None and args.person is None:
        raise MocapError("--to blends two known people: give --person too")
    if args.weight is not None and args.to is None:
        raise MocapError("--weight is the blend weight of --to: give --to P2 too")
    if args.from_actions and not args.trials:
        raise MocapError("--from-action names the action of a --from trial: give --from too")
    if args.skeleton is not None and suffix != ".bvh":
        raise MocapError("--skeleton gives the body of a BVH output; an angle CSV has no body")
    if args.samples is not None and suffix == ".bvh":
        raise MocapError("--samples sets the frames of an angle CSV; a BVH clip is timed by "
                         "--fps")
    model = load_model(args.model)
    if model.representation == "rotvec":
        if args.skeleton is not None:
            raise MocapError("--skeleton applies to models of marker corpora: this model "
                             "writes on its corpus' own rig")
        if args.samples is not None:
            raise MocapError("--samples sets the frames of a joint-angle cycle: this model "
                             "writes clips on its corpus' rig, timed by --fps")
    elif suffix == ".csv":
        if args.cycles != 1:
            raise MocapError("--cycles repeats a BVH output: an angle CSV holds one cycle")
        if args.fps is not None and args.samples is not None:
            raise MocapError("give --samples or --fps, not both: both set the frames of the "
                             "cycle")
    if args.weight is None:
        args.weight = 0.5
    model.action_index(args.action)
    if args.person is not None:
        if args.to is not None:
            signature = model.interpolate(args.person, args.to, args.weight)
            who = f"{args.person}→{args.to} at {args.weight:g}"
        else:
            signature = model.signature(args.person)
            who = args.person
    else:
        actions = list(args.from_actions or [])
        if len(actions) > len(args.trials):
            raise MocapError("more --from-action than --from trials")
        observations = []
        for k, path in enumerate(args.trials):
            curve, duration, cut = read_trial_cycle(model, path)
            action = _trial_action(model, path, curve, duration,
                                   actions[k] if k < len(actions) else None)
            if cut:
                model.check_cycle_phase(curve, action, path)
            observations.append((action, curve, duration))
        signature = model.signature_from(observations)
        who = "new person from " + ", ".join(Path(p).name for p in args.trials)
    if model.representation == "rotvec":
        return _write_rig_cycle(model, args, signature, who, suffix)
    fps = _clip_rate(model, args)
    samples = args.samples
    if suffix == ".csv" and args.fps is not None:
        duration = float(model.synthesize_angles(None, args.action, signature=signature
                                                 ).times[-1])
        samples = max(2, int(np.floor(duration * args.fps + 1e-9)) + 1)
    angles = model.synthesize_angles(None, args.action, signature=signature, samples=samples)
    if suffix == ".csv":
        write_angles_csv(angles, args.output)
    else:
        # The cycle on the default body, its root path planted on the feet (the model
        # knows joint angles, not where the body is in the room). Imported here: its
        # start-up (Pinocchio's model module) was paid by every synthesize and recognize
        # before even a damaged model file was refused.
        from dynamics.humanoid.plant import motion_from_cycle

        skeleton = (read_motion(args.skeleton, markerset=model.markerset).skeleton
                    if args.skeleton else None)
        try:
            motion = motion_from_cycle(angles, skeleton, cycles=args.cycles, up="z")
        except MocapError as error:
            raise MocapError(f"cannot build a BVH skeleton for these segments: {error.problem}",
                             args.output) from None
        if fps is not None:
            motion = motion.resampled(fps)
        write_bvh(motion, args.output)
    if suffix == ".csv":
        print(f"wrote {args.output}: {who} doing {args.action}, {angles.frames} frames over "
              f"{angles.times[-1]:.3f} s")
    else:
        print(f"wrote {args.output}: {who} doing {args.action}, {args.cycles} cycle(s) of "
              f"{angles.times[-1]:.3f} s, {motion.frames} frames at {motion.rate:g} fps, feet "
              "planted")
    return 0


def _clip_rate(model, args: argparse.Namespace) -> float | None:
    """Frames per second of a synthesised clip: ``--fps``, else the rate the model's corpus
    was captured at (recorded by decompose), else None (the model's own sampling)."""
    if args.fps is not None:
        return float(args.fps)
    rate = model.cleaning.get(RATE_KEY)
    return float(rate) if rate else None


def _write_rig_cycle(model, args: argparse.Namespace, signature, who: str, suffix: str) -> int:
    """Skeleton-corpus models: the cycle back on the corpus' rig, as BVH or Euler-angle CSV."""
    person = args.person if args.to is None and args.trials is None else None
    motion = model.synthesize_motion(person, args.action,
                                     signature=None if person is not None else signature,
                                     cycles=args.cycles)
    fps = _clip_rate(model, args)
    if fps is not None:
        motion = motion.resampled(fps)
    if suffix == ".bvh":
        write_bvh(motion, args.output)
        print(f"wrote {args.output}: {who} doing {args.action}, {args.cycles} cycle(s), "
              f"{motion.frames} frames at {motion.rate:g} fps on the corpus' rig, root path "
              "from the synthesised root motion")
        return 0
    joints = feature_joints(motion.skeleton.parents)
    euler = Rotation.from_matrix(motion.rotations[:, joints].reshape(-1, 3, 3)).as_euler(
        "ZXY", degrees=True).reshape(motion.frames, len(joints), 3)
    angles = JointAngles(times=motion.times, values=np.unwrap(euler, period=360.0, axis=0),
                         segments=[motion.names[j] for j in joints], sequence="ZXY",
                         parents=[joints.index(motion.skeleton.parents[j])
                                  if motion.skeleton.parents[j] in joints else -1
                                  for j in joints])
    write_angles_csv(angles, args.output)
    print(f"wrote {args.output}: {who} doing {args.action}, {angles.frames} frames of local "
          "joint rotations (Euler ZXY, degrees) on the corpus' rig")
    return 0


def recognize(args: argparse.Namespace) -> int:
    """``mocap recognize``: most likely person (and action) of a trial."""

    model = load_model(args.model)
    curve, duration, cut = read_trial_cycle(model, args.trial)
    result = model.recognize(curve, args.action)
    if cut:
        model.check_cycle_phase(curve, result.action, args.trial)
    limit = args.max_distance if args.max_distance is not None else \
        model.unknown_limit(result.action)
    person, nearest = open_set_person(result.person, result.distances, limit)
    ranking = sorted(result.distances, key=lambda name: result.distances[name])
    margin = (result.distances[ranking[1]] - result.distances[ranking[0]]
              if len(ranking) > 1 else math.nan)
    if args.json:
        _print_json({**result.to_json(), "person": person, "nearest_person": nearest,
                     "max_distance_deg": limit, "margin_deg": margin,
                     "ranking": [{"person": name, "distance_deg": result.distances[name]}
                                 for name in ranking]})
        return 0
    if person == UNKNOWN:
        print(f"{args.trial}: unknown person doing {result.action} (nearest {nearest} at "
              f"{result.distances[nearest]:.2f}°, beyond the {limit:.2f}° limit)")
    else:
        print(f"{args.trial}: {person} doing {result.action}"
              + (f", {margin:.2f}° nearer than {ranking[1]}" if len(ranking) > 1 else ""))
    print("  weighted mean absolute difference between the trial and each person's nearest "
          "template (their capture, or their motion modelled from their other actions), and "
          "each person's score (summing to 1):")
    for name in ranking:
        behind = result.distances[name] - result.distances[ranking[0]]
        print(f"  {name:<16} {result.distances[name]:6.2f}°  {result.scores[name]:5.3f}"
              + (f"   +{behind:.2f}°" if name != ranking[0] else ""))
    return 0


#: The answer of ``recognize`` for a trial farther from every known person than the limit.
UNKNOWN = "unknown"


def open_set_person(best: str, distances: dict, limit: float) -> tuple[str, str]:
    """``(answer, nearest)``: the nearest person, or :data:`UNKNOWN` when even the nearest
    is farther than ``limit`` degrees (a stranger is not named). A limit that is not
    finite (a model too small for leave-one-out) accepts the nearest."""
    if math.isfinite(limit) and distances.get(best, math.inf) > limit:
        return UNKNOWN, best
    return best, best


def evaluate(args: argparse.Namespace) -> int:
    """``mocap evaluate``: leave-one-cell-out synthesis error and recognition accuracy."""
    if not args.leave_one_out:
        raise MocapError("choose an evaluation: --leave-one-out")
    if args.plot is not None:
        _check_output(args.plot, (".png", ".pdf", ".svg"))
    corpus = _load_corpus(args)
    result = leave_one_out(corpus, progress=progress, hold_out=args.hold_out,
                           **_model_options(args))
    if args.plot is not None:
        plot_evaluation(result, args.plot)
    if args.json:
        _print_json(result.to_json())
    else:
        print(result.table())
        if args.plot is not None:
            print(f"wrote {args.plot}")
    return 0


# --------------------------------------------------------------------------- registration

def register(subparsers: Subparsers) -> None:
    """Add this package's sub-commands to ``subparsers``."""
    parser = subparsers.add_parser(
        "decompose", help=summary("decompose"),
        description="Read a corpus of trials (one person doing one action each), time-normalise "
                    "every cycle, and decompose the people × actions × joint-angle tensor with "
                    "the N-mode SVD into motion signatures and action bases (Vasilescu 2002).")
    _add_corpus_options(parser)
    _add_model_options(parser)
    parser.add_argument("--hold-out", action="append", type=_cell, metavar="PERSON:ACTION",
                        help="leave this captured cell out of the model (repeat for several), "
                             "e.g. to compare 'mocap synthesize --person PERSON --action "
                             "ACTION' with the trial the model never saw")
    parser.add_argument("-o", "--output", required=True, metavar="MODEL.npz",
                        help="model file to write")
    parser.add_argument("--json", action="store_true", help="print the model summary as JSON")
    parser.set_defaults(func=decompose)

    parser = subparsers.add_parser(
        "synthesize", help=summary("synthesize"),
        description="Synthesise one cycle of joint angles whose time column spans the "
                    "predicted duration: a known person doing any action (also one never "
                    "captured), a blend of two people, or a new person from captured trials.")
    parser.add_argument("model", metavar="MODEL.npz", help="model from 'mocap decompose'")
    parser.add_argument("--person", metavar="P", help="known person whose signature to use")
    parser.add_argument("--to", metavar="P2",
                        help="second person: blend the signatures of --person and --to")
    parser.add_argument("--weight", type=options.real(0, 1), default=None, metavar="W",
                        help="blend weight of --to (0 = --person, 1 = --to; default 0.5)")
    parser.add_argument("--from", dest="trials", action="append", metavar="TRIAL",
                        help="captured trial of a new person (repeat for several actions); its "
                             "signature is fitted to it")
    parser.add_argument("--from-action", dest="from_actions", action="append", metavar="A",
                        help="action of each --from trial, in order (default: from its file "
                             "name <person>_<action>, else recognised)")
    parser.add_argument("--action", required=True, metavar="A", help="action to synthesise")
    parser.add_argument("--samples", type=options.whole(2, 100000), default=None, metavar="N",
                        help="angle CSV of a marker-corpus model: frames of the cycle written "
                             "(default: the model's sample count)")
    parser.add_argument("--fps", type=options.real(above=0, maximum=10000), default=None,
                        metavar="FPS",
                        help="frames per second of the clip written (default: the rate the "
                             "model's corpus was captured at, so a 30 fps corpus gives 30 fps "
                             "clips; an angle CSV of a marker-corpus model keeps --samples "
                             "unless --fps is given)")
    parser.add_argument("--cycles", type=options.whole(1, 1000), default=1, metavar="N",
                        help="BVH output: cycles to write, the root path planted on the feet "
                             "(default 1)")
    parser.add_argument("--skeleton", metavar="TRIAL",
                        help="BVH output: take the body (segment lengths) from this marker "
                             "trial (read with the model's marker set) or BVH file, e.g. a "
                             "trial of the same person; the angles only fit the body they "
                             "came from (default: a generic 1.75 m body)")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.csv|OUT.bvh",
                        help="joint-angle CSV (as mocap angles writes) or BVH file to write")
    parser.set_defaults(func=synthesize)

    parser = subparsers.add_parser(
        "recognize", help=summary("recognize"),
        description="Compare a trial with every person's model motion and print the people "
                    "ranked by distance in degrees (the weighted mean absolute difference "
                    "of the joint angles; nearest first) with each person's score (summing "
                    "to 1), and the margin by which the nearest beats the next.")
    parser.add_argument("model", metavar="MODEL.npz", help="model from 'mocap decompose'")
    parser.add_argument("trial", metavar="TRIAL",
                        help="marker trial (read with the model's marker set), angle CSV, "
                             "BVH or AMC")
    parser.add_argument("--action", metavar="A",
                        help="the trial's action when known (otherwise recognised too)")
    parser.add_argument("--max-distance", type=options.real(above=0, maximum=360),
                        metavar="DEG",
                        help="answer 'unknown' when the nearest person's model motion is "
                             "farther than this distance in degrees (default: half the "
                             "median distance between two people's captures of the action "
                             "when everyone was captured doing it; otherwise the largest "
                             "distance at which a known person's capture lay from the "
                             "model's held-out view of them)")
    parser.add_argument("--json", action="store_true",
                        help='print {"person": …, "action": …, "ranking": [{"person", '
                             '"distance_deg"} …], "margin_deg": …, "distances_deg": …, '
                             '"scores": …} as JSON')
    parser.set_defaults(func=recognize)

    parser = subparsers.add_parser(
        "evaluate", help=summary("evaluate"),
        description="Hold out each (person, action) cell in turn, synthesise it from the "
                    "person's other actions, and report the RMS joint-angle error per cell and "
                    "overall beside the baseline 'mean of the other people for that action', "
                    "plus person-recognition accuracy.")
    _add_corpus_options(parser)
    _add_model_options(parser)
    parser.add_argument("--leave-one-out", action="store_true",
                        help="hold out every captured cell in turn (the evaluation performed)")
    parser.add_argument("--hold-out", choices=("cell", "take"), default="cell",
                        help="score against the held-out cell's mean capture (cell, default) "
                             "or, with several takes per cell, fit on the other takes and "
                             "score each take the model never saw (take)")
    parser.add_argument("--plot", metavar="OUT.png",
                        help="draw synthesised vs captured curves of some cells")
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    parser.set_defaults(func=evaluate)
