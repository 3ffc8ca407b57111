"""Marker-file readers and writers, chosen by file suffix.

``read(path)`` and ``write(trial, path)`` dispatch on the suffix, case-insensitive
(``.c3d``/``.C3D``, ``.csv``, ``.trc``). Other formats plug in with
:func:`register_format`, for example the BVH module::

    register_format(".bvh", reader=read_bvh, writer=write_bvh, description="BVH motion")

A format's reader takes a path and returns a :class:`~mocap.trial.Trial` (or
another object for non-marker formats such as BVH); a writer takes
``(obj, path, **options)``. Modules are imported only when a file of their kind is
read or written, so ``import mocap.io`` stays light.

Examples
--------
>>> from mocap.io import read, write                  # doctest: +SKIP
>>> trial = read("walk.c3d")                          # doctest: +SKIP
>>> write(trial, "walk.trc")                         # doctest: +SKIP
"""
from __future__ import annotations

import importlib
import math
import os
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from mocap.errors import MocapError, MocapWarning


@dataclass(frozen=True)
class FileFormat:
    """One registered file format.

    Attributes
    ----------
    suffix : str
        Lower-case suffix with the dot (``".c3d"``).
    name : str
        Short name stored in ``Trial.format`` (``"c3d"``).
    reader, writer : str or callable or None
        ``"module:function"`` (imported on first use) or the function itself.
    description : str
    kind : str
        ``"markers"`` (reads to a Trial) or ``"motion"`` (a skeleton's joint motion).
    """

    suffix: str
    name: str
    reader: str | Callable | None
    writer: str | Callable | None
    description: str = ""
    kind: str = "markers"


_FORMATS: dict[str, FileFormat] = {}


def register_format(suffix: str, reader: str | Callable | None = None,
                    writer: str | Callable | None = None, name: str | None = None,
                    description: str = "", kind: str = "markers") -> None:
    """Make ``read``/``write`` handle files ending in ``suffix``.

    Parameters
    ----------
    suffix : str
        With or without the dot; matched case-insensitively.
    reader, writer : callable or "module:function", optional
        ``reader(path) -> object``; ``writer(obj, path, **options)``.
    name : str, optional
        Format name; defaults to the suffix without the dot.
    description : str, optional
        Shown in error messages and ``--help`` texts.
    kind : {"markers", "motion"}, optional
        What the reader returns: a marker Trial or a skeleton Motion.
    """
    suffix = suffix.lower()
    if not suffix.startswith("."):
        suffix = "." + suffix
    _FORMATS[suffix] = FileFormat(suffix, name or suffix[1:], reader, writer, description, kind)


register_format(".c3d", "mocap.io.c3d.read:read_c3d", "mocap.io.c3d.write:write_c3d",
                description="C3D marker file")
register_format(".csv", "mocap.io.csv:read_csv", "mocap.io.csv:write_csv",
                description="marker CSV (time,<label>_x,<label>_y,<label>_z… in metres)")
register_format(".trc", "mocap.io.trc:read_trc", "mocap.io.trc:write_trc",
                description="OpenSim / Motion Analysis TRC")
register_format(".bvh", "mocap.io.bvh:read_bvh", "mocap.io.bvh:write_bvh",
                description="BVH skeleton motion", kind="motion")
register_format(".mot", None, "mocap.io.mot:write_motion_mot",
                description="OpenSim motion (joint angles)", kind="motion")


def formats() -> dict[str, FileFormat]:
    """Registered formats by suffix (a copy)."""
    return dict(_FORMATS)


def suffixes(kind: str | None = None) -> tuple[str, ...]:
    """Registered readable suffixes (with the dot), of one ``kind`` or all, sorted.

    Examples
    --------
    >>> [s for s in (".c3d", ".bvh") if s in suffixes("markers")]
    ['.c3d']
    """
    return tuple(sorted(s for s, f in _FORMATS.items()
                        if f.reader is not None and (kind is None or f.kind == kind)))


def motion_suffixes() -> tuple[str, ...]:
    """Suffixes (with the dot) of files holding a skeleton's joint motion, sorted.

    >>> motion_suffixes()
    ('.amc', '.bvh')
    """
    return tuple(sorted({*suffixes("motion"), ".amc"}))


def file_kind(path: str | os.PathLike) -> str:
    """What a file holds, decided once for every command: by its suffix, and for a
    ``.csv`` by its header (a joint-angle CSV, ``docs/formats/angles-csv.md``, or markers).

    Returns
    -------
    str
        ``"markers"`` (a marker trial: :func:`read` gives a Trial), ``"motion"`` (a BVH or
        AMC skeleton motion), ``"angles"`` (a joint-angle CSV) or ``"skeleton"`` (an ASF
        skeleton without motion).

    Raises
    ------
    MocapError
        For a suffix no reader knows.

    Examples
    --------
    >>> file_kind("walk.C3D"), file_kind("dance.bvh"), file_kind("run.amc")
    ('markers', 'motion', 'motion')
    """
    suffix = Path(path).suffix.lower()
    if suffix in motion_suffixes():
        return "motion"
    if suffix == ".asf":
        return "skeleton"
    if suffix == ".csv":
        from mocap.io.discovery import is_angle_csv    # deferred: csv, re
        if is_angle_csv(path):
            return "angles"
    if suffix in suffixes("markers"):
        return "markers"
    known = sorted({*suffixes(), ".amc", ".asf"})
    what = f"suffix {suffix!r}" if suffix else "no suffix"
    raise MocapError(f"cannot read files with {what} (known: {', '.join(known)})", path)


def _resolve(function: str | Callable) -> Callable:
    if callable(function):
        return function
    module, _, name = function.partition(":")
    return getattr(importlib.import_module(module), name)


def format_of(path: str | os.PathLike, for_writing: bool = False) -> FileFormat:
    """The registered format of ``path`` by its suffix (MocapError if none)."""
    suffix = Path(path).suffix.lower()
    file_format = _FORMATS.get(suffix)
    needed = "writer" if for_writing else "reader"
    if file_format is None or getattr(file_format, needed) is None:
        known = sorted(s for s, f in _FORMATS.items() if getattr(f, needed) is not None)
        what = f"suffix {suffix!r}" if suffix else "no suffix"
        verb = "write" if for_writing else "read"
        raise MocapError(f"cannot {verb} files with {what} (known: {', '.join(known)})",
                         path)
    return file_format


def read(path: str | os.PathLike) -> Any:
    """Read a marker file (or another registered format) chosen by its suffix.

    Parameters
    ----------
    path : str or PathLike
        ``.c3d``, ``.csv``, ``.trc`` or any registered suffix (case-insensitive).

    Returns
    -------
    Trial
        For marker formats: points (frames, markers, 3) in metres, NaN where missing.

    Raises
    ------
    MocapError
        Unknown suffix, missing file, or a file that is damaged or not of its kind.

    Warns
    -----
    MocapWarning
        One per note the reader left in ``metadata["warnings"]``.
    """
    file_format = format_of(path)
    if not Path(path).exists():
        raise MocapError("no such file", path)
    if Path(path).is_dir():
        raise MocapError("is a directory, not a file", path)
    if not Path(path).is_file():
        raise MocapError("not a regular file (a pipe or device cannot be read)", path)
    result = _resolve(file_format.reader)(path)
    if file_format.kind == "markers" and hasattr(result, "rate") and hasattr(result, "frames"):
        check_rate(result.rate, result.frames, len(result.labels), path)
    metadata = getattr(result, "metadata", None)
    for note in (metadata or {}).get("warnings", []):
        warnings.warn(f"{os.fspath(path)}: {note}", MocapWarning, stacklevel=2)
    return result


#: Plausible sampling rates of a marker trial, Hz: one frame per 1000 s to a million per second.
MIN_RATE_HZ = 1e-3
MAX_RATE_HZ = 1e6


def check_rate(rate: float, frames: int, markers: int, path: str | os.PathLike) -> None:
    """MocapError unless ``rate`` is a plausible sampling rate for what a reader found.

    Every marker reader's result passes here (from :func:`read`), so no format lets a rate
    of 0, a negative, NaN, infinite or absurd rate through to the angles and the writers.
    A rate of 0 is allowed only where there is nothing to time: one frame, or no markers
    (it is then reported by the reader as a warning).
    """
    nothing_to_time = frames <= 1 or markers == 0
    if not (math.isfinite(rate) and ((rate == 0 and nothing_to_time)
                                     or MIN_RATE_HZ <= rate <= MAX_RATE_HZ)):
        raise MocapError(f"sampling rate {rate:g} Hz is not plausible (it must be from "
                         f"{MIN_RATE_HZ:g} to {MAX_RATE_HZ:g} Hz)", path)


def require_rate(trial: Any, path: str | os.PathLike, what: str) -> None:
    """MocapError unless ``trial`` has a sampling rate, for a format that stores one (a
    TRC's DataRate, a C3D's POINT:RATE): a trial read without one (a one-row CSV, a C3D
    whose rates are 0) cannot be written as such a file without making one up."""
    if not (math.isfinite(trial.rate) and trial.rate > 0):
        source = f" ({trial.path})" if getattr(trial, "path", None) else ""
        raise MocapError(f"a {what} needs a sampling rate, and the trial{source} has none",
                         path)


def write(obj: Any, path: str | os.PathLike, **options: Any) -> Any:
    """Write ``obj`` (a Trial for marker formats) to ``path`` by its suffix.

    The file appears all-or-nothing (temporary name, then rename). ``options``
    go to the format's writer (e.g. ``units="mm"`` for C3D and TRC). Returns what
    the writer returns: for C3D, the list of source parameters it could not keep.
    """
    file_format = format_of(path, for_writing=True)
    return _resolve(file_format.writer)(obj, path, **options)


__all__ = ["read", "write", "check_rate", "require_rate", "register_format", "formats", "format_of", "suffixes", "FileFormat"]
