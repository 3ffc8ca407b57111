"""``mocap plugingait``: the whole Plug-in Gait of a walk, written as Vicon Nexus writes it."""
from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np

from mocap.cli import options
from mocap.cli.commands import Subparsers, summary
from mocap.errors import MocapError, MocapWarning
from mocap.io import read


def register(subparsers: Subparsers) -> None:
    """Add ``plugingait`` to the ``mocap`` command line."""
    parser = subparsers.add_parser(
        "plugingait", help=summary("plugingait"),
        description="Run Plug-in Gait on a walk: joint angles (lower body with the foot "
                    "progression; the upper body when its markers are there), joint "
                    "moments, powers "
                    "and forces from the force plates, gait events and gait-cycle "
                    "parameters. OUT.c3d holds the markers, the joint centres (LHJC, LKJC, "
                    "LAJC …) and every output under Vicon's labels and units (LHipAngles "
                    "deg; LHipMoment N·mm/kg; LHipPower W/kg in Z; LHipForce, "
                    "LGroundReactionForce N/kg) listed in POINT:ANGLES/FORCES/MOMENTS/"
                    "POWERS, the events, and an ANALYSIS group of the gait parameters per "
                    "side. A trial without force plates (or body mass) gives the "
                    "kinematics and one line saying kinetics were skipped.",
        epilog="Example: mocap plugingait walk.c3d --static static.c3d -o walk_pig.c3d "
               "--csv walk_pig.csv")
    parser.add_argument("trial", metavar="TRIAL.c3d", help="the walk (C3D, Plug-in Gait markers)")
    parser.add_argument("--static", metavar="STATIC.c3d",
                        help="static (standing) trial of the same subject: calibrates the "
                             "offsets and gives the segment lengths; measurements from its "
                             "PROCESSING group, then the trial's, else estimates (with a "
                             "warning)")
    parser.add_argument("--body-mass", type=options.real(maximum=500, above=0), metavar="KG",
                        help="body mass in kg (default PROCESSING Bodymass of the static, "
                             "then the trial)")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.c3d",
                        help="the C3D to write")
    parser.add_argument("--csv", metavar="OUT.csv",
                        help="also the outputs as a tidy table: frame, time, label, kind, "
                             "component, value, unit")
    parser.set_defaults(func=run_plugingait)


def _check_suffixes(args: argparse.Namespace) -> None:
    for option, suffix in ((args.trial, ".c3d"), (args.static, ".c3d"),
                           (args.output, ".c3d"), (args.csv, ".csv")):
        if option and Path(option).suffix.lower() != suffix:
            raise MocapError(f"must be a {suffix} file", option)
    if args.static and not Path(args.static).is_file():
        raise MocapError("no such file", args.static)
    if args.csv and Path(args.csv).absolute() == Path(args.output).absolute():
        raise MocapError("--csv and -o name the same file", args.csv)


def _joint_centres(trial, kin) -> tuple[list[str], np.ndarray]:
    """Labels (LHJC …) and points (frames, n, 3), metres, of the model's joint centres
    (``kin``: the walk's :class:`~mocap.plugingait.model.Kinematics`)."""
    labels, points = [], []
    for side in ("l", "r"):
        for joint, short in (("hip", "HJC"), ("knee", "KJC"), ("ankle", "AJC")):
            if f"{side}_{joint}" in kin.centres:
                labels.append(f"{side.upper()}{short}")
                points.append(kin.centres[f"{side}_{joint}"])
    if not labels:
        return [], np.zeros((trial.frames, 0, 3))
    return labels, np.stack(points, axis=1)


def run_plugingait(args: argparse.Namespace) -> int:
    """Handler of ``mocap plugingait``."""
    from mocap.io.c3d.write import write_c3d
    from mocap.plugingait.clinical import plugingait_angles, plugingait_labels, prepare_subject
    from mocap.plugingait.events import events_from_file, gait_events
    from mocap.plugingait.kinetics import plugingait_kinetics
    from mocap.plugingait.model import MARKERS, kinematics, markers_from_trial
    from mocap.plugingait.outputs import analysis_group, model_outputs, write_outputs_csv
    from mocap.plugingait.parameters import gait_parameters
    from mocap.plugingait.upper import UPPER_MARKERS

    _check_suffixes(args)
    trial = read(args.trial)
    plugingait_labels(trial)                     # a non-Plug-in-Gait marker set: one line
    static = read(args.static) if args.static else None
    subject = prepare_subject(trial, static=static)
    upper = bool(markers_from_trial(trial, UPPER_MARKERS)[0])
    # one model of the walk for the angles, the kinetics and the joint centres
    kin = kinematics(markers_from_trial(trial, MARKERS)[0], subject, trial.path)
    with warnings.catch_warnings():
        # prepare_subject above has said what it had to
        warnings.filterwarnings("ignore", message=".*anatomical offsets are uncorrected")
        angles = plugingait_angles(trial, subject, upper_body=upper, walk_kinematics=kin)
    kinetics = None
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            kinetics = plugingait_kinetics(trial, subject, static=static,
                                           body_mass=args.body_mass, walk_kinematics=kin)
        for warning in caught:
            warnings.warn_explicit(warning.message, warning.category, warning.filename,
                                   warning.lineno)
    except MocapError as error:
        if "kinetics skipped" not in str(error):
            raise
        warnings.warn(str(error), MocapWarning, stacklevel=1)
    events = gait_events(trial)
    parameters = gait_parameters(trial, events)
    labels, centres = _joint_centres(trial, kin)
    taken = {label.rpartition(":")[2] for label in trial.labels}
    keep = [k for k, label in enumerate(labels) if label not in taken]
    out = trial.with_markers(list(trial.labels) + [labels[k] for k in keep],
                             np.concatenate([trial.points, centres[:, keep]], axis=1))
    if not events_from_file(trial) and events:
        # detected events replace an EVENT group that had none of them
        out.parameters = {g: v for g, v in trial.parameters.items() if g != "EVENT"}
        out.events = [{"label": e.label, "context": {"l": "Left", "r": "Right"}[e.side],
                       "frame": int(round(e.frame)), "time": e.frame / trial.rate}
                      for e in events]
    outputs = model_outputs(angles, kinetics)
    subject_name = trial.metadata.get("subjects_names") or ""
    if isinstance(subject_name, list):
        subject_name = subject_name[0] if subject_name else ""
    notes = write_c3d(out, args.output, outputs=outputs,
                      groups=analysis_group(parameters, str(subject_name).strip()))
    for note in notes:
        warnings.warn(f"{args.output}: not kept: {note}", MocapWarning, stacklevel=1)
    if args.csv:
        write_outputs_csv(args.csv, trial.times, outputs)
    kinds = {}
    for _, kind, _ in outputs:
        kinds[kind] = kinds.get(kind, 0) + 1
    cycles = ", ".join(f"{p.side.upper()} {p.cycles}" for p in parameters)
    print(f"{args.trial}: {trial.frames} frames; "
          + ", ".join(f"{n} {kind.lower()}" for kind, n in kinds.items())
          + (f"; kinetics on {int(np.isfinite(kinetics.powers).any(axis=1).sum())} frames"
             if kinetics is not None else "; no kinetics") + f"; gait cycles {cycles}")
    for written in (args.output, args.csv):
        if written:
            print(f"wrote {written}")
    return 0
