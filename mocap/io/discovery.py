"""Finding trial files: folders searched for files of a kind, corpus trial names
(``<person>_<action>[_<anything>].<suffix>``), an AMC motion's ASF skeleton, and whether a
CSV holds joint angles (``docs/formats/angles-csv.md``) rather than markers.

Every command that takes "files or folders" lists them through :func:`find_files`, so a
folder means the same thing everywhere: the matching files directly inside it, sorted, hidden
files skipped; sub-folders are not searched (a generated corpus keeps its ground truth in
``truth/``, and a corpus's trials sit side by side). Give ``dir/*/`` to take sub-folders.
"""
from __future__ import annotations

import csv
import os
import re
from pathlib import Path
from typing import Iterable

from mocap.errors import MocapError

#: A joint-angle CSV column: ``<segment>.<axis>`` with an optional ``2`` (``docs/formats/angles-csv.md``).
_ANGLE_COLUMN = re.compile(r"^(?P<segment>.+)\.(?P<axis>[XYZxyz])(?P<repeat>2?)$")


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
                         "(or list the trials in a manifest= CSV with columns path,person,action)", path)
    return parts[0], parts[1]


def find_files(inputs: Iterable[str | os.PathLike], suffixes: Iterable[str],
               missing: str = "error", recursive: bool = False) -> list[Path]:
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
        Search sub-folders too (default: only the folder's own files, as every command).

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
                nested = not recursive and any(p.is_dir() and not p.name.startswith(".")
                                               for p in path.iterdir())
                raise MocapError(f"folder holds no {', '.join(sorted(wanted))} files"
                                 + (" directly inside it (sub-folders are not searched: name "
                                    "them, e.g. FOLDER/*/)" if nested else ""), path)
            files.extend(found)
        elif path.exists() or missing == "keep":
            files.append(path)
        else:
            raise MocapError("file not found", path)
    return files


def is_static(path: str | os.PathLike) -> bool:
    """Whether a trial is a standing (static) trial by its name: ``static`` in the file's
    name or its folder's (``HC002D/Static/HC002D02.c3d``, ``ana_static.c3d``)."""
    path = Path(path)
    return "static" in path.stem.lower() or "static" in path.parent.name.lower()


def find_asf(amc: str | Path) -> Path:
    """The ASF skeleton of an AMC motion, found beside it.

    Looks for ``<name>.asf`` (``walk.amc`` → ``walk.asf``), then the longest prefix of the
    name cut at ``_`` or ``-`` (CMU ``02_01.amc`` → ``02.asf``; HDM05
    ``HDM_bd_01-01_01_120.amc`` → ``HDM_bd.asf``), either in any letter case, then the only
    ``.asf`` of the folder.

    Raises
    ------
    MocapError
        When none (or several candidates of the folder) are found; the names tried are listed.
    """
    amc = Path(amc)
    stem = amc.stem
    cuts = [m.start() for m in re.finditer(r"[_-]", stem)]
    tried = [stem] + [stem[:k] for k in reversed(cuts) if k > 0]
    for name in tried:
        for suffix in (".asf", ".ASF"):
            candidate = amc.with_name(name + suffix)
            if candidate.is_file():
                return candidate
    found = sorted(amc.parent.glob("*.[aA][sS][fF]"))
    if len(found) == 1:
        return found[0]
    raise MocapError("no ASF skeleton found beside this AMC motion (tried "
                     + ", ".join(n + ".asf" for n in tried) + "); pass asf=", amc)


def is_angle_csv(path: str | Path) -> bool:
    """True when ``path`` is a joint-angle CSV (``docs/formats/angles-csv.md``): ``time`` then ``<segment>.<axis>``
    columns in whole triples whose axis letters form the same rotation sequence."""
    path = Path(path)
    if path.suffix.lower() != ".csv":
        return False
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            header = next(csv.reader(handle), [])
    except (OSError, UnicodeDecodeError, csv.Error):
        return False
    # column by column, stopping at the first that does not fit: a marker CSV's header of
    # millions of columns is refused by its reader's size check, not matched here whole
    if len(header) < 4 or header[0].strip().lower() != "time" or (len(header) - 1) % 3:
        return False
    first = None
    for start in range(1, len(header), 3):
        triple = [_ANGLE_COLUMN.match(name.strip()) for name in header[start:start + 3]]
        if not all(triple) or len({m.group("segment") for m in triple}) != 1:
            return False
        axes = "".join(m.group("axis") for m in triple)
        if first is None:
            first = axes
        elif axes != first:
            return False
    return True
