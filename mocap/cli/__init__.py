"""The ``mocap`` command: a thin shell over the mocap, synthesis and dynamics packages.

Each package adds its sub-commands through a ``register(subparsers)`` function in its
command module; the modules import their heavy dependencies (Pinocchio, matplotlib)
only inside the command that needs them, so ``mocap --help`` stays fast.
"""
from __future__ import annotations

import argparse
import importlib
import os
import sys
import warnings
from importlib.metadata import PackageNotFoundError, version

from mocap.errors import MocapError, MocapWarning

_default_showwarning = warnings.showwarning

#: Modules that add sub-commands, in the order they appear in ``mocap --help``.
COMMAND_MODULES = [
    "mocap.cli.io",
    "mocap.cli.angles",
    "mocap.cli.synthesis",
    "mocap.cli.simulate",
    "mocap.cli.humanoid",
    "mocap.cli.product",
]


def package_version() -> str:
    """The installed distribution's version (pyproject.toml holds the one string)."""
    try:
        return version("mocap-toolkit")
    except PackageNotFoundError:        # running from a source tree that is not installed
        return "unknown (not installed)"


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command registered."""
    parser = argparse.ArgumentParser(
        prog="mocap",
        description="Motion capture analysis, synthesis and dynamics. "
                    "Run 'mocap COMMAND --help' for the options of a command.",
    )
    parser.add_argument("--version", action="version", version=f"mocap {package_version()}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    return parser


def _warning_printer(command: str):
    """A ``warnings.showwarning`` that prints a user's warning as one line (each once)."""
    seen: set[str] = set()

    def show(message, category, filename, lineno, file=None, line=None) -> None:
        text = str(message)
        if issubclass(category, (MocapWarning, UserWarning)) and text not in seen:
            seen.add(text)
            print(f"mocap {command}: warning: {text}", file=sys.stderr)
        elif not issubclass(category, (MocapWarning, UserWarning)):
            _default_showwarning(message, category, filename, lineno, file, line)

    return show


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``mocap`` console script; returns the exit status."""
    command = "mocap"
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        command = args.command
        with warnings.catch_warnings():
            warnings.simplefilter("always", MocapWarning)
            warnings.showwarning = _warning_printer(command)
            status = args.func(args)
    except MocapError as error:
        print(f"mocap {command}: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("mocap: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader of our output went away (``mocap info … | head``): stop quietly
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1
    return int(status or 0)


if __name__ == "__main__":
    sys.exit(main())
