"""The ``mocap`` command: a thin shell over the mocap, synthesis and dynamics packages.

One module per command group (``mocap.cli.io``, ``angles``, ``generate``, ``synthesis``,
``simulate``, ``humanoid``, ``product``), each adding its sub-commands through a
``register(subparsers)`` function. ``mocap --help`` lists them from the table in
:mod:`mocap.cli.commands` without importing them; ``mocap COMMAND`` imports only that
command's module. This package is the only code that imports ``synthesis`` and
``dynamics``, and nothing imports it.
"""
from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
import warnings
from importlib.metadata import PackageNotFoundError, version

from mocap.cli.commands import COMMANDS
from mocap.errors import MocapError, MocapWarning

_default_showwarning = warnings.showwarning

def package_version() -> str:
    """The installed distribution's version (pyproject.toml holds the one string)."""
    try:
        return version("mocap-toolkit")
    except PackageNotFoundError:        # running from a source tree that is not installed
        return "unknown (not installed)"


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser: ``command``'s module registers its full parser, the other
    sub-commands are listed by name and summary only (their modules are not imported).
    ``None`` registers every command in full."""
    parser = argparse.ArgumentParser(
        prog="mocap",
        description="Motion capture analysis, synthesis and dynamics. "
                    "Run 'mocap COMMAND --help' for the options of a command.",
    )
    parser.add_argument("--version", action="version", version=f"mocap {package_version()}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    modules = [module for module, _ in COMMANDS.values()]
    wanted = [COMMANDS[command][0]] if command in COMMANDS else (
        [] if command is not None else list(dict.fromkeys(modules)))
    for module in wanted:
        importlib.import_module(module).register(subparsers)
    registered = set(subparsers.choices)
    for name, (_, text) in COMMANDS.items():
        if name not in registered:
            subparsers.add_parser(name, help=text)
    # keep ``mocap --help`` in the table's order whatever was registered first
    subparsers._choices_actions.sort(key=lambda action: list(COMMANDS).index(action.dest))
    return parser


def as_flags(message: str, parser: argparse.ArgumentParser) -> str:
    """A library message in the command line's words: each ``name=`` that is an option of
    ``parser`` (``markerset=``) becomes the flag (``--markerset``).

    Examples
    --------
    >>> p = argparse.ArgumentParser(); _ = p.add_argument("--max-gap")
    >>> as_flags("give max_gap= or asf=", p)
    'give --max-gap or asf='
    """
    flags = {action.dest: max(action.option_strings, key=len)
             for action in parser._actions if action.option_strings}

    def word(match: re.Match) -> str:
        return flags.get(match.group(1), match.group(0))

    return re.sub(r"(?<![\w-])([a-z_][a-z0-9_]*)=(?![\w\"'])", word, message)


def _command_of(argv: list[str]) -> str | None:
    """The sub-command named in ``argv`` (the first word that is one), if any."""
    return next((word for word in argv if word in COMMANDS), None)


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
    subparser = None
    try:
        words = sys.argv[1:] if argv is None else list(argv)
        parser = build_parser(_command_of(words) or "")
        args = parser.parse_args(words)
        command = args.command
        subparser = parser._subparsers._group_actions[0].choices.get(command)
        with warnings.catch_warnings():
            warnings.simplefilter("always", MocapWarning)
            warnings.showwarning = _warning_printer(command)
            status = args.func(args)
    except MocapError as error:
        words = as_flags(str(error), subparser) if subparser is not None else str(error)
        print(f"mocap {command}: error: {words}", file=sys.stderr)
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
