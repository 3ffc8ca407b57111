"""``mocap check``: the physical plausibility of a motion, against force plates when asked.

MOTION may be a BVH file, an AMC file (its ASF found beside it or given with ``--asf``),
a joint-angle CSV (``docs/formats/angles-csv.md``, played on the default body) or a marker trial
(C3D/TRC/CSV) with ``--markerset``; with ``--forces plates`` a C3D file's force plates.
This module imports only what the check needs (no simulator, no numba, no scipy), so the
command starts quickly; the readers of BVH, AMC and angle CSV motions and the force-plate
comparison load when a file or ``--forces plates`` asks for them.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from dynamics.humanoid.check import DEFAULT_LOWPASS, Thresholds, check_motion
from dynamics.humanoid.model import JOINT_OF_SEGMENT, build_humanoid
from mocap.body.anthropometry import segment_kind
from mocap.body.retarget import motion_from_trial, reduce_to_segments
from mocap.cli import options
from mocap.cli.commands import Subparsers, summary
from mocap.errors import MocapError
from mocap.io import file_kind, read, suffixes
from mocap.markersets import load_markerset



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
                             "plugingait-lower, plugingait-full) or TOML file")
    parser.add_argument("--units", choices=("m", "cm", "mm", "in", "cmu"),
                        help="length unit of the input BVH (or ASF) file; detected from the "
                             "standing height of its first frame when not given (and printed)")
    parser.add_argument("--rate", type=options.RATE, default=None, metavar="HZ",
                        help="frame rate of an AMC motion, which does not store it "
                             f"(default {AMC_RATE_HZ:g}, as CMU and HDM05)")
    parser.add_argument("--joint-map", metavar="FILE.toml",
                        help="which joint is which body segment, for rigs whose joint names "
                             "are not recognised: lines such as l_thigh = \"MyLeftThigh\" "
                             "(segments: pelvis, thorax, head, l_/r_upperarm, forearm, hand, "
                             "thigh, shank, foot)")


#: Frame rate of an AMC motion when --rate is not given (CMU and HDM05 capture at 120 Hz).
AMC_RATE_HZ = 120.0


def refuse_unused_motion_options(args: argparse.Namespace) -> None:
    """Every motion option is used or refused: one that the input's kind ignores (``--asf``
    or ``--rate`` with anything but an AMC, ``--markerset`` with a skeleton motion,
    ``--units`` or ``--joint-map`` with a marker trial or angle CSV) is one line, exit 2.
    Sets ``args.rate`` to :data:`AMC_RATE_HZ` when not given."""
    suffix = Path(args.motion).suffix.lower()
    try:
        kind = file_kind(args.motion)
    except (MocapError, OSError):
        kind = None                             # the reader names the problem
    what = {"motion": f"a {suffix[1:].upper()} motion", "markers": "a marker trial",
            "angles": "a joint-angle CSV"}.get(kind, "this input")
    if kind is not None:
        if args.asf is not None and suffix != ".amc":
            raise MocapError(f"--asf gives the skeleton of an AMC motion; {args.motion} is "
                             f"{what}")
        if args.rate is not None and suffix != ".amc":
            raise MocapError(f"--rate gives the frame rate of an AMC motion (which does not "
                             f"store one); {args.motion} is {what}, which does")
        if args.markerset is not None and kind != "markers":
            raise MocapError(f"--markerset builds a skeleton from a marker trial; "
                             f"{args.motion} is {what}")
        if args.units is not None and kind in ("markers", "angles"):
            raise MocapError(f"--units is the length unit of a BVH or ASF file; "
                             f"{args.motion} is {what}")
        if args.joint_map is not None and kind in ("markers", "angles"):
            raise MocapError(f"--joint-map names a rig's joints; {args.motion} is {what}, "
                             "whose segments are the body's already")
    if args.rate is None:
        args.rate = AMC_RATE_HZ


def register(subparsers: Subparsers) -> None:
    """Add ``check`` to ``subparsers``."""
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
               "mocap check walk.c3d --markerset plugingait-full --forces plates")
    _motion_options(check)
    check.add_argument("--mass", type=options.MASS, metavar="KG",
                       help="body mass in kg (default: a C3D file's PROCESSING:BODYMASS, "
                            "else with --forces plates what the plates weigh, else 75)")
    check.add_argument("--sex", choices=("male", "female"), default="male",
                       help="which de Leva table of segment parameters (default male)")
    check.add_argument("--mu", type=options.real(0, 10), default=0.8,
                       help="floor friction coefficient (default 0.8)")
    check.add_argument("--max-residual", type=options.real(above=0, maximum=1000),
                       metavar="PCT",
                       help="RMS residual force above which the motion is implausible, in %% "
                            "of body weight (default: the trial's own limit, from its "
                            "measurement noise, filter and segment parameters; --json "
                            "'limits' shows it)")
    check.add_argument("--max-penetration", type=options.real(0, 10000), metavar="MM",
                       help="deepest floor penetration allowed beyond the 5 mm tolerance, "
                            "mm (default 25: heel pad and shoe sole compress)")
    check.add_argument("--floor", type=options.real_or("auto", -1000, 1000), default=0.0,
                       metavar="Y|auto",
                       help="height of the floor in the motion file, metres along the up "
                            "axis (default 0), or 'auto': where the feet stand still")
    check.add_argument("--lowpass", type=options.real(minimum=0, maximum=1e6), metavar="HZ",
                       help="low-pass the motion (zero-lag Butterworth) before inverse "
                            "dynamics; default 6 Hz (motions sampled at 12 Hz or less: "
                            "none); 0 turns it off")
    check.add_argument("--forces", choices=("plates",),
                       help="'plates': also read the C3D file's force plates, compare the "
                            "estimated ground reaction with them (r and RMS %% BW per plate "
                            "and foot, and in total) and run bottom-up inverse dynamics from "
                            "them")
    check.add_argument("--strict", action="store_true",
                       help="exit with status 1 when the verdict is not plausible "
                            "(implausible or not judged; for scripts)")
    check.add_argument("--json", action="store_true",
                       help="print one JSON object instead of text (keys as in the README), "
                            "with the estimated ground reaction and joint torque series")
    check.add_argument("--plot", metavar="OUT.png",
                       help="also plot over time the residual force and torque (each "
                            "with the RMS the verdict judges and its limit), the ground "
                            "reactions (and the measured plates with --forces plates), "
                            "joint torques and the floor penetration (.png, .pdf, .svg)")
    check.set_defaults(func=run_check)



def run_check(args: argparse.Namespace) -> int:
    """Handler of ``mocap check``."""
    if args.plot and Path(args.plot).suffix.lower() not in (".png", ".pdf", ".svg"):
        raise MocapError("the plot must be a .png, .pdf or .svg file", args.plot)
    refuse_unused_motion_options(args)
    if args.forces == "plates" and Path(args.motion).suffix.lower() != ".c3d":
        raise MocapError("--forces plates reads force plates from a C3D file", args.motion)
    floor: float | str = args.floor
    limits = Thresholds()
    if args.max_residual is not None:
        limits.residual_rms_pct_bw = args.max_residual
    if args.max_penetration is not None:
        limits.penetration_mm = args.max_penetration
    result = check_file(args.motion, markerset=args.markerset, asf=args.asf, units=args.units,
                        rate=args.rate, mass=args.mass, sex=args.sex, mu=args.mu,
                        thresholds=limits, floor=floor, lowpass=args.lowpass,
                        plates=args.forces == "plates", joint_map=args.joint_map)
    report, summary = result["report"], result["summary"]
    if result["note"]:                  # after success: the unit a BVH/ASF was read in
        print(f"{args.motion}: {result['note']}", file=sys.stderr)
    if args.plot:
        from dynamics.viz.animate import plot_check    # deferred: matplotlib
        plot_check(report, args.plot, plates=result.get("plates"))
    status = 1 if args.strict and report.verdict != "plausible" else 0
    if args.json:
        print(json.dumps({**summary, **result["series"]}, allow_nan=False,
                         default=_json_number))
        return status
    _print_check(args.motion, report, summary)
    return status


def _json_number(value):
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def check_file(path, markerset=None, asf=None, units=None, rate=120.0, mass=None,
               sex="male", mu=0.8, thresholds=None, floor=0.0, lowpass=None,
               plates=False, joint_map=None) -> dict:
    """Run the dynamics check on a motion file (the work of ``mocap check``).

    Marker trials are read once: the motion from their markers and, with ``plates``, the
    force plates. ``mass`` defaults to a C3D file's PROCESSING:BODYMASS, else 75 kg;
    ``lowpass`` to :data:`DEFAULT_LOWPASS` for every motion sampled above twice that
    (0: off), as customary for the inverse dynamics of captured walking.

    Returns
    -------
    dict
        ``report`` (CheckReport), ``summary`` (the JSON summary, with ``plates`` and
        ``bottom_up`` when asked) and ``series`` (``ground_reaction`` and
        ``joint_torques`` per frame, rounded) and ``note`` (the unit a BVH or ASF file
        was read in, "" for others).
    """
    trial, note = None, ""
    if Path(path).suffix.lower() in suffixes("markers") and _kind(path) == "markers":
        if not Path(path).exists():
            raise MocapError("file not found", path)
        if not markerset:
            raise MocapError("a marker trial needs --markerset (e.g. plugingait-full) to "
                         "build the skeleton", path)
        chosen = load_markerset(markerset)
        trial = read(path)
        if trial.frames < 3:
            raise MocapError(f"the dynamics check needs at least 3 frames, the trial has "
                             f"{trial.frames}", path)
        motion = motion_from_trial(trial, chosen)
    else:
        from mocap.io.bvh import units_note      # deferred: the motion readers (scipy)
        from mocap.io.motion import read_motion
        motion = read_motion(path, asf=asf, units=units, rate=rate, joint_map=joint_map)
        note = (units_note(motion) or "").replace("units=", "--units")
    if lowpass is None:                 # the library's default (check_motion's)
        lowpass = DEFAULT_LOWPASS
    elif lowpass and not 0 < lowpass < motion.rate / 2:
        raise MocapError(f"--lowpass must be between 0 and half the frame rate "
                         f"({motion.rate / 2:g} Hz), got {lowpass:g}", path)
    mass_source = "given"
    if mass is None:
        stored = _stored_mass(trial)
        mass, mass_source = (stored, "PROCESSING:BODYMASS") if stored else (75.0, "default")
    body = reduce_to_segments(motion, partial=True)
    feet = [n for n in ("l_foot", "r_foot") if n in body.skeleton.names]
    if len(feet) < 2:
        raise MocapError("the dynamics check needs both feet in the motion", path)
    def run(mass: float):
        humanoid = build_humanoid(body.skeleton, mass, sex)
        try:
            return humanoid, check_motion(body, body_mass=mass, sex=sex, mu=mu,
                                          thresholds=thresholds, floor=floor,
                                          lowpass=lowpass or None, humanoid=humanoid)
        except MocapError as error:
            raise MocapError(error.problem, error.path or path) from None

    humanoid, report = run(mass)
    lowpass = report.lowpass_hz         # what the check used (none at 12 Hz or less)
    if plates and mass_source == "default":
        weighed = _weigh_on_plates(trial, report, lowpass)
        if weighed:
            mass, mass_source = weighed, "force plates"
            humanoid, report = run(mass)
    summary = {"path": str(path), **report.summary(), "mass_source": mass_source,
               "lowpass_hz": lowpass or None}
    series = {
        "ground_reaction": ground_reaction_series(report),
        "joint_torques": {
            "names": list(report.joint_names), "frame": "each joint's (child segment's)",
            "torque_Nm": np.round(report.joint_torques, 2).tolist()},
    }
    if plates:
        from dynamics.humanoid.plates import (compare_with_plates, measured_plates,
                                              plate_joint_torques)
        measured = measured_plates(trial, floor=report.floor_m, lowpass=lowpass or None)
        summary["plates"] = compare_with_plates(report, measured)
        torques, valid, loaded = plate_joint_torques(report, humanoid, measured)
        summary["bottom_up"] = _bottom_up_summary(report, torques, loaded)
        series["measured_ground_reaction"] = {
            "plates": measured.names,
            "force_N": np.round(measured.force.sum(axis=0), 2).tolist()}
        series["bottom_up_joint_torques"] = {
            "names": list(report.joint_names),
            "torque_Nm": np.round(np.where(valid[..., None], torques, np.nan), 2).tolist()}
        series = _nan_to_none(series)
    return {"report": report, "summary": summary, "series": series, "note": note,
            "plates": measured if plates else None}


def ground_reaction_series(report) -> dict:
    """The estimated ground reaction per frame, as ``--json`` writes it: ``times_s``,
    ``force_N`` (the total over the contacts, N, Y up), ``point_m`` (where it acts: the
    centre of pressure of the contacts' vertical forces, metres in the motion file's world,
    null while nothing pushes up) and ``feet`` (the same two per foot: ``l_foot``, ``r_foot``)."""
    forces, positions = report.contact_forces, report.contact_positions
    series = {"times_s": np.round(report.times, 5).tolist(), "frame": "world, Y up",
              "force_N": np.round(forces.sum(axis=1), 2).tolist()}
    if positions is None:
        return series
    series["point_m"] = _pressure_centres(forces, positions, report.floor_m)
    feet = [name.split(".")[0] for name in report.contact_names]
    series["feet"] = {
        foot: {"force_N": np.round(forces[:, which].sum(axis=1), 2).tolist(),
               "point_m": _pressure_centres(forces[:, which], positions[:, which],
                                            report.floor_m)}
        for foot in dict.fromkeys(feet)
        for which in [[k for k, name in enumerate(feet) if name == foot]]}
    return series


def _pressure_centres(forces: np.ndarray, positions: np.ndarray, floor: float) -> list:
    """Per frame, the centre of pressure of contact forces (F, P, 3) at points (F, P, 3) in
    the check's world (floor at 0), moved back to the motion's (floor at ``floor`` m); None
    where less than 1 N pushes up."""
    vertical = np.clip(forces[..., 1], 0.0, None)
    total = vertical.sum(axis=1)
    point = np.einsum("fp,fpk->fk", vertical, positions) / np.where(total > 1.0, total, 1.0)[:, None]
    point[:, 1] += floor
    return [np.round(p, 4).tolist() if pushed else None for p, pushed in zip(point, total > 1.0)]


def _nan_to_none(value):
    if isinstance(value, list):
        return [_nan_to_none(v) for v in value]
    if isinstance(value, dict):
        return {k: _nan_to_none(v) for k, v in value.items()}
    if isinstance(value, float) and value != value:
        return None
    return value


def _bottom_up_summary(report, torques, loaded) -> dict:
    """Peak sagittal moments (N·m/kg, about each joint's X axis) of the leg joints while
    their foot stands on a plate: bottom-up from the plates and top-down from the check's
    contact forces, and the correlation of the two curves."""
    out = {}
    for k, name in enumerate(report.joint_names):
        frames = loaded[:, k]
        if not name.endswith(("thigh", "shank", "foot")) or frames.sum() < 3:
            continue
        bottom = torques[frames, k, 0] / report.mass_kg
        top = report.joint_torques[frames, k, 0] / report.mass_kg
        r = float(np.corrcoef(bottom, top)[0, 1]) if bottom.std() > 0 and top.std() > 0 \
            else float("nan")
        out[name] = {"peak_bottom_up_Nm_per_kg": round(float(np.abs(bottom).max()), 3),
                     "peak_top_down_Nm_per_kg": round(float(np.abs(top).max()), 3),
                     "r": None if r != r else round(r, 3), "frames": int(frames.sum())}
    return out


def _weigh_on_plates(trial, report, lowpass) -> float | None:
    """Body mass (kg) from the plates: the measured vertical impulse over the frames they
    carry the whole body, divided by the check's (whose forces scale with the mass it was
    given: the dynamics are linear in it); None without such frames."""
    from dynamics.humanoid.plates import carried_frames, measured_plates, plate_stances
    measured = measured_plates(trial, floor=report.floor_m, lowpass=lowpass or None)
    # Without the contact-lag guard: on the visible walks it moves the weighed masses
    # towards the stored ones (median 1.0 -> 0.8 %) but HC002D's turn, whose plates read
    # ~13 % under m (g + a) in single stance, from 8.0 to 8.7 % away (test_dynamics_plates).
    carried = carried_frames(report, plate_stances(report, measured)[0], lag=False)
    if carried.sum() < 10:
        return None
    estimated = report.contact_forces[carried].sum(axis=1)[:, 1].sum()
    weighed = measured.force[:, carried, 1].sum()
    mass = report.mass_kg * weighed / estimated if estimated > 0 else 0.0
    return float(mass) if 5.0 <= mass <= 300.0 else None


def _stored_mass(trial) -> float | None:
    """PROCESSING:BODYMASS of a C3D trial (kg), when stored and plausible."""
    if trial is None:
        return None
    value = trial.parameters.get("PROCESSING", {}).get("BODYMASS")
    try:
        mass = float(value.reshape(-1)[0])
    except (AttributeError, IndexError, TypeError, ValueError):
        return None
    return mass if 5.0 <= mass <= 300.0 else None


def _kind(path) -> str:
    """:func:`mocap.io.file_kind` of an existing file ("markers" for one not found, whose
    reader then names the problem)."""
    return file_kind(path) if Path(path).exists() else "markers"


def _print_check(path, report, summary) -> None:
    print(f"{path}: {summary['verdict']}  ({report.frames} frames at "
          f"{report.rate:g} Hz, {report.mass_kg:g} kg"
          + (f" from {summary['mass_source']}" if summary["mass_source"] != "given" else "")
          + (f", low-pass {summary['lowpass_hz']:g} Hz" if summary["lowpass_hz"] else "")
          + ")")
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
    plates = summary.get("plates")
    if plates is not None:
        print("  estimated vs measured ground reaction (vertical r, RMS % BW; AP r):")
        for stance in plates["stances"]:
            v, ap = stance["vertical"], stance["antero_posterior"]
            print(f"    {stance['plate']} {stance['foot']:7s} "
                  f"at {stance['start_s']:.2f} s: r {v['r']:.2f}, RMS {v['rms_pct_bw']:.1f} %"
                  f"; AP r {ap['r']:.2f}")
        if not plates["stances"]:
            print("    no clean single-foot stance on a plate")
        total = plates["total"]
        if total["frames"]:
            print(f"    total ({total['frames']} frames on the plates): r "
                  f"{total['vertical']['r']:.2f}, RMS {total['vertical']['rms_pct_bw']:.1f} %; "
                  f"AP r {total['antero_posterior']['r']:.2f}")
        for name, row in summary.get("bottom_up", {}).items():
            print(f"    {joint(name):15s} peak sagittal moment {row['peak_bottom_up_Nm_per_kg']:.2f} "
                  f"N·m/kg bottom-up, {row['peak_top_down_Nm_per_kg']:.2f} top-down "
                  f"(r {row['r'] if row['r'] is not None else float('nan'):.2f})")
    for reason in summary["reasons"]:
        print(f"  - {reason}")
    for part in summary["not_judged"]:
        print(f"  - not judged: {part}")
