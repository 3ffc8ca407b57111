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
import errno
import importlib
import os
import re
import shlex
import signal
import sys
import threading
import warnings

from mocap.budget import READ_BUDGET_BYTES
from mocap.cli.commands import COMMANDS
from mocap.errors import MocapError, MocapWarning, one_line

def package_version() -> str:
    """The installed distribution's version (pyproject.toml holds the one string)."""
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("mocap-toolkit")
    except PackageNotFoundError:        # running from a source tree that is not installed
        return "unknown (not installed)"


class _Version(argparse.Action):
    """``--version``, looked up only when asked (importlib.metadata is slow to import)."""

    def __call__(self, parser, namespace, values, option_string=None):
        parser.exit(0, f"mocap {package_version()}\n")


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser: ``command``'s module registers its full parser, the other
    sub-commands are listed by name and summary only (their modules are not imported).
    ``None`` registers every command in full."""
    parser = _Parser(
        prog="mocap",
        description="Motion capture analysis, synthesis and dynamics. "
                    "Run 'mocap COMMAND --help' for the options of a command.",
        epilog=f"Files are checked before they are read: what a header declares (columns, "
               f"frames, particles, arrays) must fit the reading budget of "
               f"{READ_BUDGET_BYTES / 1e9:g} GB of numbers (MOCAP_READ_BUDGET_MB sets "
               f"another), else the file is refused in one line; see "
               f"docs/formats/limits.md.",
    )
    parser.add_argument("--version", action=_Version, nargs=0,
                        help="show the version and exit")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    subparsers.required = True
    wanted = ({COMMANDS[command][0]} if command in COMMANDS else
              set() if command is not None else {module for module, _ in COMMANDS.values()})
    # in the table's order: a wanted module registers all of its commands at its first one
    # (each module's commands stand together in the table), the others are listed by name
    for name, (module, text) in COMMANDS.items():
        if name in subparsers.choices:
            continue
        if module in wanted:
            importlib.import_module(module).register(subparsers)
        else:
            subparsers.add_parser(name, help=text)
    return parser


def as_flags(message: str, flags: dict[str, str]) -> str:
    """A library message in the command line's words: each ``name=`` that is an option in
    ``flags`` (destination -> flag, as :attr:`_Parser.flags` keeps them) becomes the flag.

    Examples
    --------
    >>> as_flags("give max_gap= or asf=", {"max_gap": "--max-gap"})
    'give --max-gap or asf='
    """

    def word(match: re.Match) -> str:
        return flags.get(match.group(1), match.group(0))

    return re.sub(r"(?<![\w-])([a-z_][a-z0-9_]*)=(?![\w\"'])", word, message)


def _command_of(argv: list[str]) -> str | None:
    """The sub-command named in ``argv`` (the first word that is one), if any."""
    return next((word for word in argv if word in COMMANDS), None)


#: Packages of this project: their warning classes are its findings about the user's input.
_OWN_PACKAGES = ("mocap", "synthesis", "dynamics")


def _warning_printer(command: str):
    """A ``warnings.showwarning`` that prints every warning as one line, each once.

    The project's own warnings (:class:`MocapWarning`, ``GimbalLockWarning`` … : a class
    defined in mocap, synthesis or dynamics) are its findings, ``mocap CMD: warning:
    <file>: <message>``. Any other (numpy's ``RuntimeWarning``, a library's
    ``UserWarning``) is not a finding about the input: it says its class and where it
    arose, ``mocap CMD: warning: RuntimeWarning in mocap/clean/filtering.py:88: <message>``,
    instead of Python's two lines with the source line.
    """
    seen: set[str] = set()

    def show(message, category, filename, lineno, file=None, line=None) -> None:
        text = str(message)
        if category.__module__.split(".")[0] not in _OWN_PACKAGES:
            text = f"{category.__name__} in {_source_of(filename)}:{lineno}: {text}"
        if text not in seen:
            seen.add(text)
            print(f"mocap {command}: warning: {one_line(text)}", file=sys.stderr)

    return show


def _source_of(filename: str) -> str:
    """A source file as a user can place it: inside its package (``numpy/linalg/…``,
    ``mocap/clean/filtering.py``), else its name.

    >>> _source_of("/venv/lib/python3.12/site-packages/scipy/signal/_filter_design.py")
    'scipy/signal/_filter_design.py'
    """
    parts = os.path.normpath(filename).split(os.sep)
    for anchor in ("site-packages", "dist-packages"):
        if anchor in parts:
            return "/".join(parts[len(parts) - parts[::-1].index(anchor):])
    for k in range(len(parts) - 1, -1, -1):
        if parts[k] in _OWN_PACKAGES:
            return "/".join(parts[k:])
    return os.path.basename(filename)


class _Parser(argparse.ArgumentParser):
    """An argument parser whose mistakes are one line: ``mocap CMD: error: … (see --help)``.

    It keeps its own table of its options and sub-commands (argparse offers no public one):
    :attr:`flags` maps each option's destination to its longest flag (``max_gap`` ->
    ``--max-gap``), :attr:`commands` each sub-command to its parser.
    """

    def __init__(self, *args, **kwargs):
        self.flags: dict[str, str] = {}
        self.commands: dict[str, argparse.ArgumentParser] = {}
        super().__init__(*args, **kwargs)

    def add_argument(self, *args, **kwargs):
        action = super().add_argument(*args, **kwargs)
        if action.option_strings:
            self.flags[action.dest] = max(action.option_strings, key=len)
        return action

    def add_subparsers(self, **kwargs):
        action = super().add_subparsers(**kwargs)
        self.commands = action.choices
        return action

    def error(self, message: str):  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {one_line(message)} (see '{self.prog} --help')\n")


#: Packages the commands import, by import name -> what ``pip install`` takes to bring it
#: (docs/install.md says which command needs which).
OPTIONAL_PACKAGES: dict[str, str] = {
    "pinocchio": "pin", "tensorly": "tensorly", "matplotlib": "matplotlib", "numba": "numba",
    "ezc3d": "ezc3d", "PIL": "pillow", "tqdm": "tqdm", "scipy": "scipy",
    "pandas": "'mocap-toolkit[tables]'", "dask": "'mocap-toolkit[distributed]'",
    "distributed": "'mocap-toolkit[distributed]'", "opensim": "'mocap-toolkit[interop]'",
    "bvhio": "'mocap-toolkit[interop]'",
}


def missing_package_line(error: ModuleNotFoundError) -> str | None:
    """The one line for a package a command needs but this installation lacks, or None
    when the missing module is none of :data:`OPTIONAL_PACKAGES` (a bug, shown whole).

    >>> missing_package_line(ModuleNotFoundError("No module named 'pinocchio'", name="pinocchio"))
    'this command needs pinocchio, which is not installed: pip install pin'
    """
    root = (error.name or "").split(".")[0]
    if root not in OPTIONAL_PACKAGES:
        return None
    return f"this command needs {root}, which is not installed: pip install {OPTIONAL_PACKAGES[root]}"


#: Refusals of a path the user gave, whether or not they name it.
_PATH_ERRORS = (PermissionError, IsADirectoryError, NotADirectoryError, FileExistsError,
                FileNotFoundError)
#: Refusals of the place itself that may come without a file name (a write that fails).
_PLACE_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EIO,
                 errno.ENAMETOOLONG, errno.ELOOP}


def _os_error_line(error: OSError) -> str:
    where = f"{error.filename}: " if getattr(error, "filename", None) else ""
    return one_line(f"{where}{error.strerror or error}")


def _user_cache_folders() -> None:
    """Point numba's compiled-kernel cache at the user's cache folder (unless the user chose
    one with NUMBA_CACHE_DIR), so the kernels compile once per user and machine, not on
    every first use in a fresh install or a read-only site-packages. Only the command line
    does this: it is process state, which library code leaves alone."""
    if "NUMBA_CACHE_DIR" not in os.environ:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        os.environ["NUMBA_CACHE_DIR"] = os.path.join(base, "mocap", "numba")


class _Interrupts:
    """Ctrl-C as KeyboardInterrupt, remembered: CPython swallows an exception raised inside
    some callbacks (an import lock's weakref callback prints "Exception ignored"), and the
    command must still end as interrupted."""

    def __init__(self):
        self.seen = False
        self.previous = None
        self.hook = None

    def __enter__(self):
        if (threading.current_thread() is threading.main_thread()
                and signal.getsignal(signal.SIGINT) is signal.default_int_handler):
            self.previous = signal.signal(signal.SIGINT, self._raise)
        self.hook = sys.unraisablehook
        sys.unraisablehook = self._unraisable
        return self

    def _unraisable(self, unraisable) -> None:
        """A Ctrl-C CPython could not raise (in a destructor, a weakref or GC callback)
        would print "Exception ignored in …" and its traceback: it is remembered instead
        (``seen``), and the command ends with its one line."""
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            self.seen = True
            return
        self.hook(unraisable)

    def arm(self) -> None:
        """Take over from the console script's start-up handler (which leaves at once,
        :func:`mocap.__main__.interrupted_at_start`) now that the command starts work."""
        current = signal.getsignal(signal.SIGINT)
        if (self.previous is None and getattr(current, "replaceable", False)
                and threading.current_thread() is threading.main_thread()):
            self.previous = signal.signal(signal.SIGINT, self._raise)

    def _raise(self, signum, frame):
        self.seen = True
        raise KeyboardInterrupt

    def __exit__(self, *exc):
        if self.previous is not None:
            signal.signal(signal.SIGINT, self.previous)
        if self.hook is not None:
            sys.unraisablehook = self.hook
        return False


def _stdout_to_devnull() -> None:
    """Send what is left of standard output nowhere: its reader has gone (a broken pipe),
    and Python's flush at exit would otherwise raise again."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``mocap`` console script; returns the exit status.

    A user's mistake (:class:`MocapError`, a file the system refuses) is one line and exit
    status 2; Ctrl-C is one line and 130, whenever it comes.
    """
    with _Interrupts() as interrupts:
        return _main(argv, interrupts)


def _main(argv: list[str] | None, interrupts: _Interrupts) -> int:
    command = "mocap"
    subparser = None
    try:
        words = sys.argv[1:] if argv is None else list(argv)
        _user_cache_folders()
        parser = build_parser(_command_of(words) or "")
        try:
            args = parser.parse_args(words)
        except SystemExit as done:              # --help, --version, or a one-line mistake
            return done.code if isinstance(done.code, int) else (0 if done.code is None else 2)
        command = args.command
        args.command_line = "mocap " + " ".join(shlex.quote(word) for word in words)
        interrupts.arm()
        subparser = parser.commands.get(command)
        from mocap.cli.paths import check_paths
        check_paths(command, args)
        from mocap.atomic import all_or_nothing
        with warnings.catch_warnings(), all_or_nothing() as outputs:
            warnings.simplefilter("always", MocapWarning)
            warnings.showwarning = _warning_printer(command)
            try:
                status = args.func(args)
            except BrokenPipeError:
                # the reader of our output went away (``mocap decompose … | head``): the
                # files already complete stay (the model was written before the summary)
                _stdout_to_devnull()
                status = 1
            if interrupts.seen:                 # an interrupt Python swallowed on the way
                raise KeyboardInterrupt
            if status not in (None, 0, 1):      # a refusal after some outputs: none stay
                outputs.undo()
    except MocapError as error:
        if interrupts.seen:                     # the mistake came after a swallowed Ctrl-C
            print(f"mocap {command}: interrupted", file=sys.stderr)
            return 130
        words = as_flags(str(error), subparser.flags) if subparser is not None else str(error)
        print(f"mocap {command}: error: {one_line(words)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"mocap {command}: interrupted" if command != "mocap" else "mocap: interrupted",
              file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader of our output went away (``mocap info … | head``): stop quietly
        _stdout_to_devnull()
        return 1
    except ModuleNotFoundError as error:
        line = missing_package_line(error)
        if line is None or interrupts.seen:
            raise
        name = command if command != "mocap" else _command_of(words)
        print(f"mocap {name}: error: {line}" if name else f"mocap: error: {line}",
              file=sys.stderr)
        return 2
    except OSError as error:
        # the system refused a path the user gave (no such file, permission, a folder, a
        # name too long for the file system, a symbolic-link loop, a full or read-only
        # disk): one line, like any user mistake
        if interrupts.seen:
            print(f"mocap {command}: interrupted", file=sys.stderr)
            return 130
        if not isinstance(error, _PATH_ERRORS) and error.errno not in _PLACE_ERRNOS \
                and getattr(error, "filename", None) is None:
            raise
        print(f"mocap {command}: error: {_os_error_line(error)}", file=sys.stderr)
        return 2
    except BaseException:
        # Ctrl-C inside an import or a C extension can surface as another exception
        # (numpy's "PyCapsule_Import could not import module", an ImportError): still Ctrl-C
        if interrupts.seen:
            print(f"mocap {command}: interrupted", file=sys.stderr)
            return 130
        raise
    return int(status or 0)


def run() -> None:
    """The console script: :func:`main`, with Ctrl-C during start-up one line too."""
    try:
        status = main()
        # the work is done (or refused): a Ctrl-C from here on cannot change the outcome
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    except KeyboardInterrupt:
        print("mocap: interrupted", file=sys.stderr)
        status = 130
    if status == 130:
        # An interrupt caught inside an import leaves CPython convinced it went unhandled
        # (under ``python -m`` it would then kill itself with SIGINT); our files are already
        # cleaned up by their ``finally`` blocks, so leave with the status we promised.
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        import atexit
        try:
            atexit._run_exitfuncs()         # what a normal exit runs (pools, semaphores)
        except BaseException:
            pass
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(130)
    sys.exit(status)


if __name__ == "__main__":
    run()
