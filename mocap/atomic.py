"""Write output files and folders all-or-nothing: to a temporary name, then rename.

The temporary names carry the writing process's id (``.walk.csv.<pid>-<random>.part.csv``,
``.corpus.<pid>-<random>.part``), so a run killed outright (SIGKILL, power loss) leaves a
leftover that the next write of the same output recognises as dead and removes.
Problems with the place itself (a folder where a file should go, a folder without write
permission) are :class:`~mocap.errors.MocapError`, one line naming the path.
"""
from __future__ import annotations

import contextlib
import errno
import glob
import os
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

from mocap.errors import MocapError


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:          # someone else's live process
        return True
    return True


def _remove_dead_leftovers(parent: Path, pattern: str, prefix: str) -> None:
    """Remove ``pattern`` matches in ``parent`` whose writer (the pid after ``prefix`` in
    the name) is gone."""
    try:
        candidates = list(parent.glob(pattern))
    except OSError:
        return
    for leftover in candidates:
        tag = leftover.name[len(prefix):].split("-", 1)[0]
        if not tag.isdigit() or _alive(int(tag)):
            continue
        with contextlib.suppress(OSError):
            if leftover.is_dir() and not leftover.is_symlink():
                shutil.rmtree(leftover)
            else:
                leftover.unlink()


def _writable_parent(target: Path) -> Path:
    parent = target.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise MocapError("cannot write here: a file is in the way of the folder "
                         f"{parent}", target) from None
    except PermissionError:
        raise MocapError(f"cannot create the folder {parent}: permission denied",
                         target) from None
    if not os.access(parent, os.W_OK | os.X_OK):
        raise MocapError(f"cannot write into {parent}: permission denied", target)
    return parent


def _os_error(error: OSError, target: Path) -> MocapError:
    reason = error.strerror or str(error)
    if error.errno == errno.ENOSPC:
        reason = "no space left on the device"
    return MocapError(f"cannot write: {reason}", target)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it onto ``path`` on success.

    If the body raises, the temporary file is removed and ``path`` is left
    untouched, so a failed command never leaves a half-written file.

    Raises
    ------
    MocapError
        ``path`` is an existing folder, or its folder cannot be created or written.

    Examples
    --------
    >>> with atomic_path("out.csv") as tmp:          # doctest: +SKIP
    ...     tmp.write_text("time\\n0\\n")
    """
    target = Path(path)
    if target.is_dir():
        raise MocapError("is a folder; give a file name for the output", target)
    parent = _writable_parent(target)
    prefix = f".{target.name}."
    _remove_dead_leftovers(parent, f"{glob.escape(prefix)}*.part{glob.escape(target.suffix)}", prefix)
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f"{prefix}{os.getpid()}-",
                                        suffix=".part" + target.suffix, dir=parent)
    except OSError as error:
        raise _os_error(error, target) from None
    os.close(fd)
    tmp = Path(tmp_name)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)          # mkstemp's 0600 would outlive the rename
    try:
        yield tmp
        os.replace(tmp, target)
    except BaseException as error:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        if isinstance(error, (PermissionError, IsADirectoryError)) or (
                isinstance(error, OSError) and error.errno == errno.ENOSPC):
            raise _os_error(error, target) from None
        raise


def folder_in_use(path: str | os.PathLike) -> bool:
    """True when ``path`` is a folder holding anything but hidden leftovers."""
    folder = Path(path)
    return folder.is_dir() and any(not p.name.startswith(".") for p in folder.iterdir())


@contextlib.contextmanager
def atomic_folder(path: str | os.PathLike, replace: bool = False) -> Iterator[Path]:
    """Yield a temporary folder beside ``path``; it becomes ``path`` on success.

    A failure (an error, Ctrl-C) removes the temporary folder, so no half-written
    collection of files is ever left at ``path``.

    Parameters
    ----------
    path : path-like
        The folder to produce.
    replace : bool
        When ``path`` already holds files: replace them (``True``) or refuse (MocapError).

    Raises
    ------
    MocapError
        ``path`` is a file, holds files and ``replace`` is false, or cannot be written.
    """
    target = Path(path)
    if target.exists() and not target.is_dir():
        raise MocapError("is a file, not a folder", target)
    if folder_in_use(target) and not replace:
        raise MocapError("folder exists and holds files; choose a new folder (or "
                         "replace it with force=)", target)
    parent = _writable_parent(target)
    prefix = f".{target.name}."
    _remove_dead_leftovers(parent, f"{glob.escape(prefix)}*.part", prefix)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=f"{prefix}{os.getpid()}-", suffix=".part",
                                    dir=parent))
    except OSError as error:
        raise _os_error(error, target) from None
    os.chmod(tmp, 0o777 & ~_umask())
    try:
        yield tmp
        if target.exists():
            old = Path(tempfile.mkdtemp(prefix=f"{prefix}{os.getpid()}-old-", suffix=".part",
                                        dir=parent))
            os.replace(target, old / "x")
            os.replace(tmp, target)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask
