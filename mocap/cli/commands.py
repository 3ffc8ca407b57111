"""The table of ``mocap`` sub-commands: which module defines each and its one-line summary.

``mocap --help`` lists the commands from this table without importing their modules, and
``mocap COMMAND`` imports only the module of that command, so start-up stays quick (the
dynamics commands alone would pull in Pinocchio).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    import argparse


class Subparsers(Protocol):
    """What a command module's ``register(subparsers)`` is given: the object
    ``ArgumentParser.add_subparsers()`` returns, of which only ``add_parser`` is used."""

    def add_parser(self, name: str, **kwargs: Any) -> "argparse.ArgumentParser": ...

#: Sub-command -> (module whose ``register(subparsers)`` adds it, one-line summary), in the
#: order of ``mocap --help``.
COMMANDS: dict[str, tuple[str, str]] = {
    "info": ("mocap.cli.io", "summarise marker files: rate, frames, duration, markers, units, gaps"),
    "convert": ("mocap.cli.io", "convert a marker file between C3D, CSV and TRC"),
    "forces": ("mocap.cli.forces", "force plates of a C3D trial: ground reaction, centre of pressure"),
    "angles": ("mocap.cli.angles", "joint angles from marker files, as CSV (time, <segment>.<axis> in degrees)"),
    "plugingait": ("mocap.cli.plugingait", "the whole Plug-in Gait of a walk (angles, kinetics, gait parameters) as Vicon Nexus writes it"),
    "generate": ("mocap.cli.generate", "write a synthetic people × actions marker corpus with ground truth"),
    "decompose": ("mocap.cli.synthesis", "build an N-mode SVD motion model from a people × actions corpus"),
    "synthesize": ("mocap.cli.synthesis", "synthesise one cycle of a person doing an action"),
    "recognize": ("mocap.cli.synthesis", "recognise the person (and action) of a trial"),
    "evaluate": ("mocap.cli.synthesis", "leave-one-out synthesis error and recognition accuracy of a corpus"),
    "simulate": ("mocap.cli.simulate", "run a particle / mass-spring / rigid-body scene (TOML) and save the frames"),
    "check": ("mocap.cli.check", "physical plausibility of a motion (Pinocchio inverse dynamics)"),
    "export": ("mocap.cli.humanoid", "write a motion as BVH, angle CSV, C3D/TRC joint markers, .mot or JSON"),
    "animate": ("mocap.cli.humanoid", "stick-figure animation of a motion (cape, rope, physics)"),
    "normative": ("mocap.cli.report", "a lab's normative reference (mean ± SD per gait variable) from its normal walks"),
    "report": ("mocap.cli.report", "one HTML gait report of a subject's walks: curves over the normative band, GPS, parameters"),
    "view": ("mocap.cli.view", "interactive 3-D viewer of trials and motions in one HTML file"),
    "demo": ("mocap.cli.product", "run the whole pipeline on generated data and write an HTML report"),
    "batch": ("mocap.cli.product", "analyse every trial of a corpus in parallel into one table"),
}


def summary(command: str) -> str:
    """The one-line summary of ``command`` shown by ``mocap --help``."""
    return COMMANDS[command][1]
