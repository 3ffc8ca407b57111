"""Joint-angle CSV files (docs/formats/angles-csv.md): ``time`` then ``<segment>.<axis>``
columns in degrees, empty cells where a segment's markers were missing.  Clinical angles
(Plug-in Gait, docs/plugingait.md) name their axes ``flexion``, ``adduction``, ``rotation``
(Cardan YXZ)."""
from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np

from mocap.rotations.angles import CLINICAL_AXES, SEQUENCES, JointAngles, axis_names
from mocap.atomic import atomic_path
from mocap.errors import MocapError, MocapWarning
from mocap.io.text_table import check_label, check_times_increase, parse_table, read_text
from mocap.io.text_format import write_table
from mocap.markersets.model import MarkerSet


def write_angles_csv(angles: JointAngles, path: str | os.PathLike) -> None:
    """Write joint angles as CSV (docs/formats/angles-csv.md), all-or-nothing.

    Header ``time,<segment>.<axis>,…``; time in seconds, angles in degrees
    with 6 decimals (``%.6f``, vectorised: :func:`mocap.io.text_format.write_table`); a
    NaN angle is an empty cell.
    """
    frames, segments, _ = angles.values.shape
    for segment in angles.segments:
        check_label(segment, ',"', "segment", path)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            handle.write((",".join(angles.columns) + "\n").encode("utf-8"))
            write_table(handle, [angles.times, angles.values.reshape(frames, 3 * segments)],
                        6, ",", nan="")


def read_angles_csv(path: str | os.PathLike, markerset: MarkerSet | None = None
                    ) -> JointAngles:
    """Read a joint-angle CSV written by write_angles_csv (or to docs/formats/angles-csv.md).

    Parameters
    ----------
    path : path-like
    markerset : MarkerSet, optional
        Supplies ``parents`` (the CSV does not store them); otherwise -1 each.

    Raises
    ------
    MocapError
        Missing file, bad header, a time that is missing or not a number, a row of
        another width than the header, a cell that is no finite number (``inf``, a word).

    Warns
    -----
    MocapWarning
        A file ending inside a row (it may have been cut in its last number).
    """
    path = Path(path)
    text = read_text(path)
    header, _, body = text.partition("\n")
    columns = [c.strip() for c in header.strip().split(",")]
    if not columns or columns[0] != "time" or (len(columns) - 1) % 3 or len(columns) < 4:
        raise MocapError("not a joint-angle CSV: the header must be 'time' followed by "
                         "three '<segment>.<axis>' columns per segment", path)
    segments: list[str] = []
    letters: list[str] | None = None
    for k in range(1, len(columns), 3):
        parts = [c.rpartition(".") for c in columns[k:k + 3]]
        names = {p[0] for p in parts}
        if len(names) != 1 or not parts[0][0] or any(not p[1] for p in parts):
            raise MocapError(f"columns {', '.join(columns[k:k + 3])} are not three angles "
                             f"of one segment", path)
        axes = [p[2] for p in parts]
        if letters is None:
            letters = axes
        elif axes != letters:
            raise MocapError(f"segment '{parts[0][0]}' has axes {axes}, others {letters}",
                             path)
        segments.append(parts[0][0])
    axes = None
    if letters == list(CLINICAL_AXES):
        sequence, axes = "YXZ", list(CLINICAL_AXES)
    else:
        sequence = "".join(a.rstrip("2") for a in letters)
        if sequence not in SEQUENCES or axis_names(sequence) != letters:
            raise MocapError(f"axis columns {letters} name no Euler sequence (nor "
                             f"flexion, adduction, rotation)", path)
    # the text readers' numeric-cell rule, strictly: empty and NaN cells are missing
    # angles; a ragged row or a cell that is no finite number (inf, a word) is refused,
    # naming its line, as the CSV is written by programs only
    notes: list[str] = []
    raw = body.encode("utf-8")
    table = parse_table(raw, ",", len(columns), notes, first_line=2, path=path,
                        ends_file=True, strict=True)
    if not np.isfinite(table[:, 0]).all():
        check_times_increase(table[:, 0], raw, path, first_line=2)
    for note in notes:
        warnings.warn(f"{path}: {note}", MocapWarning, stacklevel=2)
    parents = markerset.parent_index if markerset is not None else [-1] * len(segments)
    if markerset is not None and markerset.segment_names != segments:
        raise MocapError(f"segments {segments} differ from marker set "
                         f"'{markerset.name}' ({markerset.segment_names})", path)
    return JointAngles(times=table[:, 0].copy(),
                       values=table[:, 1:].reshape(len(table), len(segments), 3).copy(),
                       segments=segments, sequence=sequence, parents=list(parents),
                       axes=axes)
