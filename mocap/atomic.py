"""Write output files and folders all-or-nothing: to a temporary name, then rename.

The temporary names carry the writing process's id (``.walk.csv.<pid>-<random>.part.csv``,
``.corpus.<pid>-<random>.part``), so a run killed outright (SIGKILL, power loss) leaves a
leftover that the next write of the same output recognises as dead and removes.
Problems with the place itself (a folder where a file should go, a folder without write
permission) are :class:`~mocap.errors.MocapError`, one line naming the path.

A command that writes several outputs (a CSV and its plot, frames and their GIF) runs inside
:func:`all_or_nothing`: when it fails or is interrupted after some of them were renamed into
place, those are undone (a new file removed, a replaced one given back its previous content),
so a failed command leaves none of its outputs.
"""
from __future__ import annotations

import contextlib
import contextvars
import errno
import glob
import os
import shutil
import signal
import stat
import tempfile
import threading
from pathlib import Path
from typing import Iterator

from mocap.errors import MocapError


@contextlib.contextmanager
def interrupts_held(children: bool = False) -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) until the block ends, then let it act as it would have: for
    clean-up that must finish (taking back outputs, closing workers, removing a scratch
    folder) and for steps that must not be cut in two (creating a folder and remembering
    its name).

    Parameters
    ----------
    children : bool
        Also block SIGINT in this thread while the block runs, so processes started inside
        (directly or from threads started inside) inherit it blocked: a Ctrl-C typed at the
        terminal, which reaches every process of the group, then stops only this process,
        which closes its workers itself (their own KeyboardInterrupt tracebacks would
        otherwise flood the terminal).

    Only the main thread receives signals; elsewhere the block simply runs. The previous
    handler is restored on the way out, so the process's signal state is as it was.
    """
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is None):      # not Python's to handle
        yield
        return
    held: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: held.append(signum))
    mask = None
    if children and hasattr(signal, "pthread_sigmask"):
        mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        if mask is not None:     # a Ctrl-C pending while blocked arrives now, into ``held``
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        signal.signal(signal.SIGINT, previous)
        if held:         # act on it as the previous handler would (KeyboardInterrupt …)
            signal.raise_signal(signal.SIGINT)


class _Journal:
    """The outputs put in place inside one :func:`all_or_nothing` block: (target, backup of
    what it replaced or None)."""

    def __init__(self) -> None:
        self.entries: list[tuple[Path, Path | None]] = []
        #: Folders the block created for its outputs, outermost first.
        self.folders: list[Path] = []

    def undo(self) -> None:
        """Take back every output put in place so far (newest first), then the folders
        made for them (each only if nothing else was put in it meanwhile)."""
        self._undo_outputs()
        while self.folders:
            with contextlib.suppress(OSError):
                self.folders.pop().rmdir()

    def _undo_outputs(self) -> None:
        while self.entries:
            target, backup = self.entries.pop()
            with contextlib.suppress(OSError):
                if target.is_dir() and not target.is_symlink():
                    shutil.rmtree(target)
                else:
                    target.unlink()
            if backup is not None:
                with contextlib.suppress(OSError):
                    os.replace(backup, target)
                if backup.name == "x":
                    _remove_backup(backup)

    def settle(self) -> None:
        """Keep the outputs: drop the backups of what they replaced."""
        self.folders.clear()
        while self.entries:
            _, backup = self.entries.pop()
            if backup is not None:
                _remove_backup(backup)


_JOURNAL: contextvars.ContextVar[_Journal | None] = contextvars.ContextVar(
    "mocap_atomic_journal", default=None)


def _remove_backup(backup: Path) -> None:
    if backup.name == "x" and backup.parent.name.endswith(".part"):
        shutil.rmtree(backup.parent, ignore_errors=True)    # a folder's own .part holder
    else:
        with contextlib.suppress(OSError):
            backup.unlink()


@contextlib.contextmanager
def all_or_nothing() -> Iterator[_Journal]:
    """Outputs written with :func:`atomic_path` / :func:`atomic_folder` inside the block are
    undone when the block raises (an error, Ctrl-C), or when the caller calls ``undo()`` on
    the yielded journal: a new output is removed, a replaced one gets its old content back.
    A block inside another one joins the outer one.

    Examples
    --------
    >>> with all_or_nothing():                         # doctest: +SKIP
    ...     write(angles, "walk.csv"); plot(angles, "walk.png")   # both or neither
    """
    journal = _JOURNAL.get()
    if journal is not None:
        yield journal
        return
    journal = _Journal()
    token = _JOURNAL.set(journal)
    try:
        yield journal
    except BaseException:
        with interrupts_held():         # a second Ctrl-C must not cut the undo short
            journal.undo()
        raise
    else:
        with interrupts_held():
            journal.settle()
    finally:
        _JOURNAL.reset(token)


def _backup_of(target: Path, prefix: str) -> Path | None:
    """A hard link (else a copy) of an existing ``target`` under a leftover name the next
    write recognises, for :func:`all_or_nothing` to give back; None when nothing is there."""
    if not target.is_file():
        return None
    fd, name = tempfile.mkstemp(prefix=f"{prefix}{os.getpid()}-old-",
                                suffix=".part" + target.suffix, dir=target.parent)
    os.close(fd)
    backup = Path(name)
    try:
        os.unlink(backup)
        os.link(target, backup)
    except OSError:
        shutil.copy2(target, backup)
    return backup


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


def refuse_special(path: str | os.PathLike) -> None:
    """MocapError when ``path`` exists and is neither a regular file nor a folder (a FIFO, a
    device such as /dev/null or /dev/full, a socket): renaming a finished output onto it
    would replace the device itself."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        raise MocapError("is not a regular file (a pipe, socket or device); give a file "
                         "name for the output", path)


def make_folder(folder: str | os.PathLike) -> Path:
    """Create ``folder`` and any missing parents; inside :func:`all_or_nothing` the ones
    created here are removed again (when empty) if the block is undone.

    Raises
    ------
    FileExistsError, PermissionError, OSError
        As :meth:`pathlib.Path.mkdir`.
    """
    folder = Path(folder)
    missing = []
    for place in (folder, *folder.parents):
        if place.exists() or place.is_symlink():
            break
        missing.append(place)
    folder.mkdir(parents=True, exist_ok=True)
    journal = _JOURNAL.get()
    if journal is not None:
        journal.folders.extend(reversed(missing))
    return folder


def _writable_parent(target: Path) -> Path:
    parent = target.parent
    try:
        make_folder(parent)
    except FileExistsError:
        raise MocapError("cannot write here: a file is in the way of the folder "
                         f"{parent}", target) from None
    except PermissionError:
        raise MocapError(f"cannot create the folder {parent}: permission denied",
                         target) from None
    if not os.access(parent, os.W_OK | os.X_OK):
        raise MocapError(f"cannot write into {parent}: permission denied", target)
    return parent


#: Room a temporary name needs beside the output's own: ".", the pid, "-old-", mkstemp's
#: eight random characters, ".part" and the suffix.
_TEMPORARY_EXTRA = 40


def _leftover_prefix(target: Path, parent: Path) -> str:
    """The start of the temporary names beside ``target`` (``.<name>.``), cut so that a
    temporary name stays within the file system's name limit when the output's own name is
    near it (a legal 250-character name must not fail as "File name too long")."""
    try:
        limit = os.pathconf(parent, "PC_NAME_MAX")
    except (OSError, ValueError):
        limit = 255
    keep = max(1, limit - _TEMPORARY_EXTRA - 2 * len(target.suffix))
    # a name that is not valid UTF-8 (undecodable bytes as surrogates) gets U+FFFD in its
    # temporary sibling: libraries that take only UTF-8 paths (ezc3d) can write that one
    name = target.name.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    return f".{name[:keep]}."


#: A write the system stopped part way: the disk or a quota is full, the file is larger
#: than the process may write (ulimit -f), the device failed.
_FULL = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO}


def _os_error(error: OSError, target: Path) -> MocapError:
    reason = error.strerror or str(error)
    if error.errno == errno.ENOSPC:
        reason = "no space left on the device"
    elif error.errno == errno.EFBIG:
        reason = "the file would be larger than the system allows (a file-size limit)"
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
    refuse_special(target)
    parent = _writable_parent(target)
    prefix = _leftover_prefix(target, parent)
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
    journal = _JOURNAL.get()
    try:
        yield tmp
        with interrupts_held():         # in place and journaled, or neither
            backup = _backup_of(target, prefix) if journal is not None else None
            try:
                os.replace(tmp, target)
            except BaseException:       # the place refused it (an immutable file …)
                if backup is not None:
                    _remove_backup(backup)
                raise
            if journal is not None:
                journal.entries.append((target, backup))
    except BaseException as error:
        with interrupts_held(), contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        if isinstance(error, (PermissionError, IsADirectoryError)) or (
                isinstance(error, OSError) and error.errno in _FULL):
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
    prefix = _leftover_prefix(target, parent)
    _remove_dead_leftovers(parent, f"{glob.escape(prefix)}*.part", prefix)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=f"{prefix}{os.getpid()}-", suffix=".part",
                                    dir=parent))
    except OSError as error:
        raise _os_error(error, target) from None
    os.chmod(tmp, 0o777 & ~_umask())
    journal = _JOURNAL.get()
    try:
        yield tmp
        with interrupts_held():         # in place and journaled, or neither
            _folder_into_place(tmp, target, parent, prefix, journal)
    except BaseException:
        with interrupts_held():
            shutil.rmtree(tmp, ignore_errors=True)
        raise


def _folder_into_place(tmp: Path, target: Path, parent: Path, prefix: str,
                       journal: _Journal | None) -> None:
    if target.exists():
        old = Path(tempfile.mkdtemp(prefix=f"{prefix}{os.getpid()}-old-", suffix=".part",
                                    dir=parent))
        os.replace(target, old / "x")
        os.replace(tmp, target)
        if journal is not None:
            journal.entries.append((target, old / "x"))
        else:
            shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(tmp, target)
        if journal is not None:
            journal.entries.append((target, None))


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask
