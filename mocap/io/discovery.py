"""Finding trial files: folders searched for files of a kind, and corpus trial names
(``<person>_<action>[_<anything>].<suffix>``).

Every command that takes "files or folders" lists them through :func:`find_files`, so a
folder means the same thing everywhere: every matching file below it, sub-folders included,
hidden files skipped, sorted.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Iterable

from mocap.errors import MocapError


def parse_trial_name(path: str | Path) -> tuple[str, str]:
    """``(person, action)`` from a file named ``<person>_<action>[_<anything>].<suffix>``.

    Raises
    ------
    MocapError
        When the name has no ``_`` separating a person from an action.

    Examples
    --------
    >>> parse_trial_name("data/ana_walk_02.c3d")
    ('ana', 'walk')
    """
    parts = Path(path).stem.split("_")
    if len(parts) < 2 or not parts[0] or not parts[1]:
        raise MocapError("trial name must be <person>_<action>[_anything].<suffix> "
                         "(or use --manifest FILE.csv with columns path,person,action)", path)
    return parts[0], parts[1]


def find_files(inputs: Iterable[str | os.PathLike], suffixes: Iterable[str],
               missing: str = "error", recursive: bool = True) -> list[Path]:
    """The files named by ``inputs``: files as given, folders expanded.

    Parameters
    ----------
    inputs : iterable of path-like
        Files and folders, in the order given.
    suffixes : iterable of str
        Lower-case suffixes with the dot (``".c3d"``) a folder is searched for; matched
        case-insensitively. Files named directly are kept whatever their suffix.
    missing : {"error", "keep"}
        A path that does not exist: raise, or keep it (the reader reports it later).
    recursive : bool
        Search sub-folders too (else only the folder's own files).

    Returns
    -------
    list of Path
        Folder contents sorted by path; hidden files and folders (``.name``) skipped.

    Raises
    ------
    MocapError
        A missing path (with ``missing="error"``), or a folder with no matching file.
    """
    wanted = {s.lower() for s in suffixes}
    files: list[Path] = []
    for item in inputs:
        path = Path(item)
        if path.is_dir():
            found = sorted(p for p in (path.rglob("*") if recursive else path.iterdir())
                           if p.is_file() and p.suffix.lower() in wanted
                           and not any(part.startswith(".") for part in p.relative_to(path).parts))
            if not found:
                raise MocapError(f"folder holds no {', '.join(sorted(wanted))} files", path)
            files.extend(found)
        elif path.exists() or missing == "keep":
            files.append(path)
        else:
            raise MocapError("file not found", path)
    return files
