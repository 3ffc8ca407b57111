"""``mocap forces``: the force plates of a C3D trial as ground reaction data."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from mocap.atomic import atomic_path
from mocap.cli import options
from mocap.cli.commands import Subparsers, summary
from mocap.errors import MocapError, one_line
from mocap.io import read
from mocap.io.c3d.forceplates import plate_forces, total_forces
from mocap.io.external_loads import (FEET, assign_feet, foot_reactions, write_external_loads,
                                     write_grf_mot)
from mocap.io.text_format import format_table
from mocap.plot import save_figure


def register(subparsers: Subparsers) -> None:
    """Add ``forces`` to the ``mocap`` command line."""
    forces = subparsers.add_parser(
        "forces", help=summary("forces"),
        description="Read FORCE_PLATFORM (plate types 1-4: corners, origin, CAL_MATRIX) and "
                    "the analog channels into the ground reaction force (N), centre of "
                    "pressure (m) and free moment (N·m) of each plate and of all plates "
                    "together, in the lab frame. Without -o, print one line per plate.",
        epilog="Examples: mocap forces walk.c3d;  mocap forces walk.c3d -o grf.csv --rate "
               "marker;  mocap forces walk.c3d --plot grf.png;  mocap forces walk.c3d -o "
               "grf.mot --external-loads loads.xml (OpenSim, docs/opensim.md)")
    forces.add_argument("trial", metavar="TRIAL.c3d", help="a C3D file with force plates")
    forces.add_argument("-o", "--output", metavar="GRF.csv|GRF.mot",
                        help="write a CSV: time_s from the first frame, then per plate and "
                             "for the total Fx Fy Fz (N), COPx COPy COPz (m), Tx Ty Tz (N·m, "
                             "free moment); an unloaded plate's COP is an empty cell. Or a "
                             ".mot: OpenSim's external loads (per foot r_/l_ ground_force_v*, "
                             "_p*, ground_torque_*; Y up, the trial's own times)")
    forces.add_argument("--external-loads", metavar="LOADS.xml",
                        help="with -o GRF.mot: also write OpenSim's ExternalLoads XML "
                             "applying each foot's reaction to calcn_r / calcn_l")
    forces.add_argument("--rate", choices=("analog", "marker"), default="analog",
                        help="samples of the output: the analog rate (default) or the "
                             "marker frames")
    forces.add_argument("--baseline", action="store_true",
                        help="take off each channel's unloaded offset (FORCE_PLATFORM:ZERO, "
                             "else the plate's quietest 0.1 s)")
    forces.add_argument("--threshold", type=options.real(0, 1e6), default=20.0, metavar="N",
                        help="vertical force below which a plate is unloaded (no COP), "
                             "default 20 N")
    forces.add_argument("--plot", metavar="OUT.png",
                        help="plot the three force components of each plate (.png, .pdf, "
                             ".svg)")
    forces.set_defaults(func=run_forces)


def load_plates(path: str | Path, rate: str = "analog", baseline: bool = False,
                threshold: float = 20.0):
    """Trial, per-plate and total reactions of a C3D file (MocapError without plates)."""
    if Path(path).suffix.lower() != ".c3d":
        raise MocapError("force plates are read from C3D files only", path)
    trial = read(path)
    return (trial, *_reactions(trial, path, rate, baseline, threshold))


def _reactions(trial, path: str | Path, rate: str, baseline: bool, threshold: float):
    """Per-plate and total reactions of a trial already read (MocapError without plates)."""
    plates = plate_forces(trial, rate=rate, baseline=baseline, threshold=threshold)
    if not plates:
        raise MocapError("no force plates (FORCE_PLATFORM:USED is 0 or absent)", path)
    if trial.analogs is None or plates[0].samples == 0:
        raise MocapError("the force plates have no analog samples", path)
    usable = [p for p in plates if not p.plate.problem]
    if not usable:
        raise MocapError("no force plate has believable corners: "
                         + "; ".join(p.plate.problem for p in plates), path)
    return plates, total_forces(usable, threshold)


def run_forces(args: argparse.Namespace) -> int:
    """Handler of ``mocap forces``."""
    for option, suffixes in ((args.output, (".csv", ".mot")), (args.external_loads, (".xml",)),
                             (args.plot, (".png", ".pdf", ".svg"))):
        if option and Path(option).suffix.lower() not in suffixes:
            raise MocapError("must be a " + " or ".join(suffixes) + " file", option)
    opensim = bool(args.output) and Path(args.output).suffix.lower() == ".mot"
    if args.external_loads and not opensim:
        raise MocapError("--external-loads goes with -o GRF.mot (the file it applies)")
    trial, plates, total = load_plates(args.trial, args.rate, args.baseline, args.threshold)
    parts = [(f"plate{p.plate.index + 1}", p) for p in plates] + [("total", total)]
    if opensim:
        reactions, bodies = foot_reactions(trial, plates)
        if args.external_loads and not bodies:
            raise MocapError("--external-loads needs the feet (RHEE, RTOE, LHEE, LTOE) to "
                             "say which foot stands on which plate", args.trial)
        write_grf_mot(args.output, reactions, start_time=float(trial.time_base()[1][0]))
        if args.external_loads:
            write_external_loads(args.external_loads, args.output, bodies)
    elif args.output:
        write_forces_csv(parts, args.output)
    if args.plot:
        save_figure(plot_forces(parts, title=one_line(Path(args.trial).name)), args.plot, format=Path(args.plot).suffix[1:].lower())
    print(f"{args.trial}: {len(plates)} force plates, {total.samples} samples at "
          f"{total.rate:g} Hz")
    for name, part in parts:
        fz = part.force[:, 2]
        loaded = np.isfinite(part.cop).all(axis=1)
        ignored = f"  (ignored: {part.plate.problem})" if part.plate and part.plate.problem \
            else ""
        print(f"  {name:7s} peak Fz {np.abs(fz).max():7.1f} N, loaded "
              f"{loaded.sum() / part.rate:.2f} s, impulse {np.sum(fz) / part.rate:7.1f} N·s"
              + ignored)
    if args.rate == "marker" and total.rate < (trial.analog_rate or total.rate):
        # averaging each frame's analog samples flattens the heel-strike transient
        measured = _reactions(trial, args.trial, "analog", args.baseline, args.threshold)[1]
        peak, kept = np.abs(measured.force[:, 2]).max(), np.abs(total.force[:, 2]).max()
        if peak > 0 and kept < 0.99 * peak:
            print(f"note: at the marker rate ({total.rate:g} Hz, each frame the mean of its "
                  f"analog samples) the total peak Fz is {kept:.0f} N; at the plates' "
                  f"{measured.rate:g} Hz it is {peak:.0f} N ({100 * (1 - kept / peak):.0f} % "
                  f"lower: the heel-strike transient is averaged away)", file=sys.stderr)
    if opensim:
        feet = ", ".join(f"{body}: " + (", ".join(f"plate{p.plate.index + 1}" for p in own)
                                        or "no plate")
                         for body, own in _feet_plates(trial, plates).items())
        print(f"{args.output}: " + (feet or "one force per plate (no foot markers)"))
    for written in (args.output, args.external_loads):
        if written:
            print(f"wrote {written}")
    return 0


def _feet_plates(trial, plates: list) -> dict:
    """OpenSim body -> the plates assigned to it (empty without foot markers)."""
    feet = assign_feet(trial, [p for p in plates if not p.plate.problem]) or {}
    return {FEET[side][0]: own for side, own in feet.items()}


def write_forces_csv(parts: list, path: str | Path) -> None:
    """Write (name, PlateForces) pairs side by side to a CSV (all-or-nothing).

    Like the project's other CSV files, a value that does not exist is an empty cell: the
    centre of pressure (and free moment) of an unloaded plate. Time to 1 µs, forces to
    1 mN, positions to 1 µm, moments to 0.1 mN·m.
    """
    columns, header = [parts[0][1].times[:, None]], ["time_s"]
    for name, part in parts:
        columns += [part.force, part.cop, part.free_moment]
        header += [f"{name}_{q}" for q in ("Fx_N", "Fy_N", "Fz_N", "COPx_m", "COPy_m",
                                           "COPz_m", "Tx_Nm", "Ty_Nm", "Tz_Nm")]
    table = np.concatenate(columns, axis=1)
    places = [6] + [3, 3, 3, 6, 6, 6, 4, 4, 4] * len(parts)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            handle.write((",".join(header) + "\n").encode("ascii"))
            handle.write(format_table(table, places, ",", nan="", as_bytes=True))


def plot_forces(parts: list, figure=None, title: str | None = None):
    """Force components over time, one panel per plate and one for the total; a Figure.

    Every panel has its own time ticks and label, and its force axis names the plate and
    the unit; ``title`` (the trial's name) goes above them.
    """
    from matplotlib.figure import Figure

    figure = figure or Figure(figsize=(8, 2.2 * len(parts) + 0.3), layout="constrained")
    axes = figure.subplots(len(parts), 1, sharex=True, squeeze=False)[:, 0]
    for ax, (name, part) in zip(axes, parts):
        for k, label in enumerate(("Fx", "Fy", "Fz")):
            ax.plot(part.times, part.force[:, k], label=label, lw=1)
        ax.set_ylabel(f"{name} force (N)")
        ax.legend(loc="upper right", fontsize="small")
        ax.tick_params(labelbottom=True)    # time ticks on every panel, not only the last
        ax.set_xlabel("time (s)", fontsize="small")
        ax.grid(alpha=0.3)
    figure.suptitle((f"{title}: " if title else "") + "ground reaction force, lab frame",
                    fontsize="medium")
    return figure
