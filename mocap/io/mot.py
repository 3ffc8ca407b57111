"""OpenSim ``.mot`` / ``.sto`` files (storage files of joint coordinates over time).

The header OpenSim reads::

    <name>
    version=1
    nRows=<frames>
    nColumns=<columns including time>
    inDegrees=yes
    endheader
    time<TAB>col1<TAB>col2 …

followed by tab-separated rows. Angles are written in degrees (``inDegrees=yes``),
translations in metres. :func:`read_mot` reads them back (OpenSim's own ``.mot`` and
``.sto`` files too, tab- or space-separated), angles in degrees.
"""
from __future__ import annotations

import io
import os
import re
from dataclasses import dataclass, field

import numpy as np

from mocap.atomic import atomic_path
from mocap.body.angles import motion_joint_angles
from mocap.body.retarget import motion_to_lab
from mocap.errors import MocapError


def write_mot(path: str | os.PathLike, times: np.ndarray, labels: list[str],
              values: np.ndarray, name: str = "mocap", in_degrees: bool = True,
              precision: int = 8) -> None:
    """Write a table of coordinates as an OpenSim ``.mot`` file (all-or-nothing).

    Parameters
    ----------
    path : str or PathLike
    times : ndarray, shape (frames,), seconds
    labels : list of str
        Column names (without ``time``); OpenSim matches them to model coordinates.
    values : ndarray, shape (frames, len(labels))
        Degrees for angles when ``in_degrees``; metres for translations.
    name : str
        First header line (the storage's name).
    """
    times = np.asarray(times, float).reshape(-1)
    values = np.asarray(values, float).reshape(times.size, -1)
    if values.shape[1] != len(labels):
        raise MocapError(f"{len(labels)} labels for {values.shape[1]} columns")
    bad = [label for label in labels if not label or any(c.isspace() for c in label)]
    if bad:
        raise MocapError(f".mot column labels may not be empty or hold spaces: {bad}")
    table = np.column_stack([times, values])
    buffer = io.StringIO()
    buffer.write(f"{name}\nversion=1\nnRows={table.shape[0]}\nnColumns={table.shape[1]}\n"
                 f"inDegrees={'yes' if in_degrees else 'no'}\nendheader\n")
    buffer.write("\t".join(["time"] + list(labels)) + "\n")
    np.savetxt(buffer, table, fmt=f"%.{precision}f", delimiter="\t")
    with atomic_path(path) as tmp:
        # surrogateescape: a name that is not valid UTF-8 is written as its own bytes
        tmp.write_text(buffer.getvalue(), encoding="utf-8", errors="surrogateescape")


def write_motion_mot(motion, path: str | os.PathLike, sequence: str = "ZXY") -> None:
    """Write a :class:`~mocap.skeleton.Motion` as joint coordinates in a ``.mot`` file.

    Times are the motion's own clock (``start_time`` onwards, as the trial's TRC).
    Columns: ``<root>_tx``, ``_ty``, ``_tz`` (root origin, metres, in the Z-up lab: X
    anterior, Y left, Z up) then ``<joint>_<axis>`` for every joint: the joint angles of
    :func:`mocap.body.angles.motion_joint_angles` (rotation relative to the parent in the lab's
    axes, Euler ``sequence`` in degrees, unwrapped), the same numbers as an angle CSV export.

    Parameters
    ----------
    motion : Motion
        Frames (frames,) of a skeleton with ``segments`` joints; Y up, metres.
    path : str or PathLike
    sequence : str
        scipy Euler sequence.
    """
    sk = motion.skeleton
    _, root = motion_to_lab(motion)                                   # (frames, 3), metres
    angles = motion_joint_angles(motion, sequence, body=False).values  # (frames, segments, 3)
    letters = _axis_labels(sequence)
    labels = [f"{sk.names[0]}_t{a}" for a in "xyz"]
    labels += [f"{_safe(n)}_{letter}" for n in sk.names for letter in letters]
    values = np.column_stack([root, angles.reshape(motion.frames, -1)])
    write_mot(path, motion.start_time + motion.times, labels, values,
              name=os.path.splitext(os.path.basename(os.fspath(path)))[0])


def _axis_labels(sequence: str) -> list[str]:
    seen: dict[str, int] = {}
    result = []
    for letter in sequence:
        seen[letter.upper()] = seen.get(letter.upper(), 0) + 1
        result.append(letter.upper() + ("2" if seen[letter.upper()] > 1 else ""))
    return result


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "_-." else "_" for c in name)


@dataclass
class Storage:
    """The columns of a ``.mot`` / ``.sto`` file.

    Attributes
    ----------
    times : ndarray, shape (frames,), seconds
    labels : list of str
        Column names after ``time`` (model coordinates in a motion file).
    values : ndarray, shape (frames, len(labels))
        Rotations in degrees (converted when the file says ``inDegrees=no``),
        translations in metres; NaN where empty.
    name : str
        The file's first header line.
    header : dict
        ``key=value`` header lines.
    """

    times: np.ndarray
    labels: list[str]
    values: np.ndarray
    name: str = ""
    header: dict = field(default_factory=dict)

    def column(self, label: str) -> np.ndarray:
        """One column by name, shape (frames,)."""
        try:
            return self.values[:, self.labels.index(label)]
        except ValueError:
            raise KeyError(label) from None


def read_mot(path: str | os.PathLike, rotational: set[str] | None = None) -> Storage:
    """Read an OpenSim ``.mot`` or ``.sto`` file.

    Parameters
    ----------
    path : str or PathLike
    rotational : set of str, optional
        Columns that are angles, converted from radians when ``inDegrees=no``; by
        default every column except ``*_tx``, ``*_ty``, ``*_tz`` and forces.

    Raises
    ------
    MocapError
        Missing file, no ``endheader`` line, or no ``time`` column.
    """
    from mocap.io.text_table import parse_table, read_head

    head, _ = read_head(path, 400)
    end = next((i for i, line in enumerate(head) if line.strip().lower() == "endheader"), None)
    if end is None or end + 1 >= len(head):
        raise MocapError("not an OpenSim storage file (no 'endheader' line followed by "
                         "column labels)", path)
    header = {}
    for line in head[1:end]:
        key, sep, value = line.partition("=")
        if sep:
            header[key.strip()] = value.strip()
    columns = [c for c in re.split(r"\t" if "\t" in head[end + 1] else r"\s+",
                                   head[end + 1].strip()) if c]
    if not columns or columns[0].lower() != "time":
        raise MocapError("the first column of an OpenSim storage file must be 'time'", path)
    _, body = read_head(path, end + 2)
    text = body.decode("utf-8", errors="replace")
    if "\t" not in text[:10000]:
        text = re.sub(r"[ ]+", "\t", text)
    table = parse_table(re.sub(r"(?m)^[ \t]+", "", text), "\t", len(columns))
    values = table[:, 1:]
    if header.get("inDegrees", "yes").lower() == "no":
        for k, label in enumerate(columns[1:]):
            angle = label in rotational if rotational is not None else \
                not re.search(r"_t[xyz]$|force|_f[xyz]$|_p[xyz]$|moment|torque", label)
            if angle:
                values[:, k] = np.degrees(values[:, k])
    return Storage(table[:, 0], columns[1:], values, head[0].strip(), header)
