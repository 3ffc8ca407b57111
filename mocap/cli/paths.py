"""The one check of a command's files before any work: inputs readable, outputs not inputs.

:func:`check_paths` runs in :func:`mocap.cli.main` for every command, after parsing and
before the handler, on the options named in :data:`INPUTS` and :data:`OUTPUTS`:

- an input that exists but is not a regular file or folder (a FIFO, a device) is refused,
  because reading it could block forever;
- an output that names an input (or the same file as another output) is refused, so no
  command overwrites what it reads;
- an output that is an existing folder where a file is written is refused, and so is one
  that is a FIFO or a device (finishing the output would replace the device itself).

Commands that expand folders into many outputs call :func:`refuse_overwrite` per file.
"""
from __future__ import annotations

import argparse
import os
import stat
from pathlib import Path
from typing import Iterable

from mocap.atomic import refuse_special
from mocap.errors import MocapError

#: Option destinations that name files or folders a command reads.
INPUTS = ("input", "inputs", "files", "motion", "scene", "corpus", "model", "trial", "trials",
          "data", "asf", "manifest", "skeleton", "markerset")
#: Option destinations that name files a command writes.
FILE_OUTPUTS = ("plot", "gif", "mp4")
#: Option destinations that may be a file or, for some commands, a folder.
OUTPUTS = ("output", "out") + FILE_OUTPUTS
#: Commands whose ``-o`` is a folder (or may be, with several inputs).
FOLDER_OUTPUT_COMMANDS = ("angles", "generate", "demo")


def _as_list(value) -> list[str]:
    if value is None or isinstance(value, bool):
        return []
    if isinstance(value, (list, tuple)):
        return [str(v) for v in value if v is not None]
    return [str(value)]


def _same(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def check_input(path: str | os.PathLike) -> None:
    """Refuse an existing input that is neither a regular file nor a folder."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return                       # missing: the reader names it
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        raise MocapError("not a regular file (a pipe, socket or device cannot be read as "
                         "motion data)", path)


def refuse_overwrite(output: str | os.PathLike, inputs: Iterable[str | os.PathLike]) -> None:
    """MocapError when ``output`` is one of ``inputs`` (the same file, by any name)."""
    target = Path(output)
    for item in inputs:
        source = Path(item)
        if _same(target, source) or target.absolute() == source.absolute():
            raise MocapError(f"the output would overwrite the input {source}; choose "
                             "another name", target)


def output_format(path: str | os.PathLike, suffixes: dict[str, str],
                  asked: str | None = None, flag: str = "") -> str:
    """The format an output is written in, by the one rule of every command: the output's
    suffix names its format, and a flag that asks for another is refused (so ``batch --json
    -o table.csv`` or ``export --format bvh -o walk.csv`` never writes one format under
    another's name). An output without a suffix takes the format asked for.

    Parameters
    ----------
    path : path-like
        The output.
    suffixes : dict
        Suffix (lower case, with the dot) -> format, of every format the command writes.
    asked : str, optional
        The format a flag asks for (None: the suffix decides).
    flag : str
        That flag, for the message.

    Examples
    --------
    >>> output_format("rows.JSON", {".csv": "csv", ".json": "json"})
    'json'
    >>> output_format("rows.csv", {".csv": "csv", ".json": "json"}, "json", "--json")
    Traceback (most recent call last):
    ...
    mocap.errors.MocapError: rows.csv: --json writes json, but the name says .csv; name it .json (or leave --json out)
    """
    suffix = Path(path).suffix.lower()
    if not suffix and asked is not None:
        return asked
    named = suffixes.get(suffix)
    if named is None:
        raise MocapError(f"the output must be a {' or '.join(dict.fromkeys(suffixes))} file",
                         path)
    if asked is not None and named != asked:
        wanted = next(s for s, f in suffixes.items() if f == asked)
        raise MocapError(f"{flag} writes {asked}, but the name says {suffix}; name it "
                         f"{wanted} (or leave {flag} out)", path)
    return named


def check_paths(command: str, args: argparse.Namespace) -> None:
    """The checks above on the parsed ``args`` of ``command`` (see the module docstring)."""
    inputs = [p for name in INPUTS for p in _as_list(getattr(args, name, None))]
    outputs = [(name, p) for name in OUTPUTS for p in _as_list(getattr(args, name, None))]
    for path in inputs + [p for _, p in outputs]:
        if not path.strip():
            raise MocapError(f"an empty name {path!r} is not a file or folder; give a path")
        if path == "-":
            # the usual spelling of standard input/output, which no command reads or
            # writes: it would be taken as a file named '-' in the working folder
            raise MocapError("'-' (standard input or output) is not supported; give a file "
                             "name")
    for path in inputs:
        check_input(path)
    files_only = [p for p in inputs if not Path(p).is_dir()]
    seen: list[str] = []
    for name, path in outputs:
        refuse_overwrite(path, files_only)
        refuse_special(path)
        if any(Path(path).absolute() == Path(other).absolute() for other in seen):
            raise MocapError("two outputs name the same file", path)
        seen.append(path)
        folder_ok = command in FOLDER_OUTPUT_COMMANDS and name in ("output", "out")
        if Path(path).is_dir() and not folder_ok and not (command == "angles"):
            raise MocapError("is a folder; give a file name for the output", path)
