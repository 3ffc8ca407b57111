"""Joint angles: relative segment rotations as continuous Euler/Cardan angles.

A joint rotation is ``R_parent⁻¹ R_child`` (a root segment's is its rotation in
the lab).  Angles follow scipy's ``Rotation.as_euler`` convention: an upper-case
sequence (``"ZXY"``) is intrinsic, a lower-case one (``"zxy"``) extrinsic; all 12
Tait-Bryan (three different axes) and 12 proper Euler (first axis repeated)
sequences are accepted.  Angles are in degrees and continuous (see
:func:`unwrap_angles`); frames with missing markers stay NaN, and become empty
cells in the CSV (DESIGN 3.2).
"""
from __future__ import annotations

import io
import os
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.atomic import atomic_path
from mocap.errors import MocapError
from mocap.markerset import MarkerSet
from mocap.trial import Trial

#: The 24 sequences accepted: 12 intrinsic (upper case) and 12 extrinsic.
SEQUENCES = tuple(
    s for s in (a + b + c for a in "XYZ" for b in "XYZ" for c in "XYZ")
    if s[0] != s[1] and s[1] != s[2]
) + tuple(
    s.lower() for s in (a + b + c for a in "XYZ" for b in "XYZ" for c in "XYZ")
    if s[0] != s[1] and s[1] != s[2]
)
#: Default sequence (DESIGN 3.2).
DEFAULT_SEQUENCE = "ZXY"
#: Degrees from gimbal lock at which joint_angles warns.
GIMBAL_TOLERANCE = 5.0


class GimbalLockWarning(UserWarning):
    """Some frames are within a few degrees of the sequence's gimbal lock.

    There the first and third angles are ill-defined (only their sum or
    difference is); choose a sequence whose middle axis is not the one the
    joint turns most about.
    """


@dataclass
class JointAngles:
    """Joint angles of every segment over a trial.

    Attributes
    ----------
    times : ndarray, shape (frames,)
        Seconds from the first frame.
    values : ndarray, shape (frames, segments, 3)
        Degrees, in the order of ``sequence``'s letters; NaN where unknown.
    segments : list of str
    sequence : str
        scipy Euler sequence (upper case intrinsic, lower case extrinsic).
    parents : list of int
        Parent of each segment (-1 for a root, or when unknown, as after
        reading a CSV without a marker set).
    """

    times: np.ndarray
    values: np.ndarray
    segments: list[str]
    sequence: str
    parents: list[int]

    @property
    def frames(self) -> int:
        """Number of frames."""
        return int(self.values.shape[0])

    @property
    def columns(self) -> list[str]:
        """CSV header: ``time`` then ``<segment>.<axis>`` (DESIGN 3.2)."""
        names = axis_names(self.sequence)
        return ["time"] + [f"{s}.{a}" for s in self.segments for a in names]

    def segment(self, name: str) -> np.ndarray:
        """Angles of one segment, shape (frames, 3), degrees."""
        try:
            return self.values[:, self.segments.index(name), :]
        except ValueError:
            raise KeyError(name) from None


def check_sequence(sequence: str) -> str:
    """Return ``sequence`` if scipy accepts it, else raise MocapError."""
    if sequence not in SEQUENCES:
        raise MocapError(
            f"unknown Euler sequence {sequence!r}: use three of X, Y, Z with no axis twice "
            f"in a row, all upper case (intrinsic, e.g. ZXY, ZYZ) or all lower case "
            f"(extrinsic, e.g. zxy)")
    return sequence


def is_proper_euler(sequence: str) -> bool:
    """True for proper Euler sequences (first and last axis the same)."""
    return sequence[0].lower() == sequence[2].lower()


def axis_names(sequence: str) -> list[str]:
    """Column suffixes of a sequence: its letters, a repeated one carrying a 2.

    Examples
    --------
    >>> axis_names("ZXY"), axis_names("ZYZ"), axis_names("xyx")
    (['Z', 'X', 'Y'], ['Z', 'Y', 'Z2'], ['x', 'y', 'x2'])
    """
    names: list[str] = []
    for letter in sequence:
        names.append(letter + "2" if letter in names else letter)
    return names


def relative_rotations(rotations: np.ndarray, parent_index: list[int] | np.ndarray
                       ) -> np.ndarray:
    """Joint rotations ``R_parent⁻¹ R_child``; a root keeps its lab rotation.

    Parameters
    ----------
    rotations : ndarray, shape (..., segments, 3, 3)
        Segment rotations (columns = axes in lab coordinates).
    parent_index : sequence of int, length segments
        -1 for a root.

    Returns
    -------
    ndarray, shape (..., segments, 3, 3)
        NaN wherever the segment's or its parent's rotation is NaN.
    """
    parents = np.asarray(parent_index, dtype=int)
    roots = parents < 0
    parent_rot = rotations[..., np.where(roots, 0, parents), :, :]
    relative = np.matmul(np.swapaxes(parent_rot, -1, -2), rotations)
    if roots.any():
        relative[..., roots, :, :] = rotations[..., roots, :, :]
    return relative


def matrices_to_angles(matrices: np.ndarray, sequence: str) -> np.ndarray:
    """Euler angles of rotation matrices, principal values, degrees.

    Parameters
    ----------
    matrices : ndarray, shape (..., 3, 3)
        Proper rotations (orthonormal to rounding, as from segment_frames), or
        NaN.
    sequence : str

    Returns
    -------
    ndarray, shape (..., 3)
        scipy's principal values: first and third angle in (-180, 180], middle
        in [-90, 90] (Tait-Bryan) or [0, 180] (proper Euler); NaN rows for NaN
        matrices.
    """
    check_sequence(sequence)
    shape = matrices.shape[:-2]
    flat = matrices.reshape(-1, 3, 3)
    valid = np.isfinite(flat).all(axis=(1, 2))
    out = np.full((flat.shape[0], 3), np.nan)
    if valid.any():
        chosen = flat[valid]
        try:
            # our matrices are orthonormal by construction: skip re-orthogonalising
            rotation = Rotation.from_matrix(chosen, assume_valid=True)
        except TypeError:  # scipy < 1.15
            rotation = Rotation.from_matrix(chosen)
        with warnings.catch_warnings():
            # scipy's gimbal warning names no frame; joint_angles gives a better one
            warnings.filterwarnings("ignore", message=".*[Gg]imbal lock.*")
            out[valid] = rotation.as_euler(sequence, degrees=True)
    return out.reshape(shape + (3,))


def angles_to_matrices(values_deg: np.ndarray, sequence: str) -> np.ndarray:
    """Rotation matrices of Euler angles (the inverse of matrices_to_angles).

    Parameters
    ----------
    values_deg : ndarray, shape (..., 3)
        Degrees, any branch or number of turns; NaN rows allowed.
    sequence : str

    Returns
    -------
    ndarray, shape (..., 3, 3)
        NaN where an angle is NaN.
    """
    check_sequence(sequence)
    values = np.asarray(values_deg, dtype=float)
    shape = values.shape[:-1]
    flat = values.reshape(-1, 3)
    valid = np.isfinite(flat).all(axis=1)
    out = np.full((flat.shape[0], 3, 3), np.nan)
    if valid.any():
        out[valid] = Rotation.from_euler(sequence, flat[valid], degrees=True).as_matrix()
    return out.reshape(shape + (3, 3))


def _wrap(x: np.ndarray) -> np.ndarray:
    """Angles wrapped into [-180, 180) degrees."""
    return (x + 180.0) % 360.0 - 180.0


def _other_branch(values: np.ndarray, proper: bool) -> np.ndarray:
    """The second Euler triple of the same rotation.

    Tait-Bryan: (a + 180, 180 - b, c + 180); proper Euler: (a + 180, -b, c + 180).
    """
    other = values.copy()
    other[..., 0] += 180.0
    other[..., 2] += 180.0
    other[..., 1] = (180.0 - values[..., 1]) if not proper else -values[..., 1]
    return other


def unwrap_angles(values: np.ndarray, sequence: str) -> np.ndarray:
    """Continuous angles from per-frame principal values, vectorised.

    Two things make principal Euler angles jump although the rotation moves
    smoothly: the ±180° wrap of each angle, and the switch between the two
    triples that give every rotation (scipy keeps the middle angle in
    [-90, 90] for Tait-Bryan, [0, 180] for proper Euler, so a joint passing
    that limit flips all three angles).  Per segment and frame this picks, of
    the two triples, the one nearer the previous valid frame, then removes
    360° jumps as ``np.unwrap`` does.  Missing frames (NaN) are skipped: the
    first valid frame after a gap continues from the last one before it.  The
    first valid frame of each segment keeps scipy's principal values.

    Parameters
    ----------
    values : ndarray, shape (frames, segments, 3)
        Principal values in degrees (matrices_to_angles), NaN rows allowed.
    sequence : str

    Returns
    -------
    ndarray, shape (frames, segments, 3)
        Same rotations (angles_to_matrices gives the same matrices), continuous.
    """
    frames = values.shape[0]
    if frames < 2:
        return values.copy()
    proper = is_proper_euler(sequence)
    valid = np.isfinite(values).all(axis=-1)                              # (F, S)
    index = np.where(valid, np.arange(frames)[:, None], -1)
    last_valid = np.maximum.accumulate(index, axis=0)
    previous = np.vstack([np.full((1, values.shape[1]), -1), last_valid[:-1]])
    has_previous = valid & (previous >= 0)
    segments = np.arange(values.shape[1])[None, :]
    prev_values = values[np.maximum(previous, 0), segments]               # (F, S, 3)

    # branch: switching is needed where the other triple is nearer the
    # previous frame (both triples of the previous frame are equally far
    # apart, so comparing principal values suffices), then accumulate (XOR)
    same = np.sum(_wrap(values - prev_values) ** 2, axis=-1)
    other = np.sum(_wrap(_other_branch(values, proper) - prev_values) ** 2, axis=-1)
    switch = has_previous & (other < same)
    branch = (np.cumsum(switch, axis=0) % 2).astype(bool)
    chosen = np.where(branch[..., None], _other_branch(values, proper), values)

    # turns: remove 360° jumps between consecutive valid frames
    prev_chosen = chosen[np.maximum(previous, 0), segments]
    step = chosen - prev_chosen
    correction = np.where(has_previous[..., None], -360.0 * np.round(step / 360.0), 0.0)
    correction = np.nan_to_num(correction)
    out = chosen + np.cumsum(correction, axis=0)
    out[~valid] = np.nan
    return out


def near_gimbal_lock(principal: np.ndarray, sequence: str,
                     tolerance: float = GIMBAL_TOLERANCE) -> np.ndarray:
    """Frames whose middle angle is within ``tolerance`` degrees of gimbal lock.

    Parameters
    ----------
    principal : ndarray, shape (..., 3)
        Principal values (matrices_to_angles), degrees.

    Returns
    -------
    ndarray of bool, shape (...)
        Tait-Bryan: ``|b| >= 90 - tolerance``; proper Euler: ``b <= tolerance``
        or ``b >= 180 - tolerance``.  False for NaN rows.
    """
    middle = principal[..., 1]
    with np.errstate(invalid="ignore"):
        if is_proper_euler(sequence):
            return (middle <= tolerance) | (middle >= 180.0 - tolerance)
        return np.abs(middle) >= 90.0 - tolerance


def joint_angles(trial: Trial, markerset: MarkerSet, sequence: str = DEFAULT_SEQUENCE,
                 *, unwrap: bool = True, gimbal_tolerance: float = GIMBAL_TOLERANCE
                 ) -> JointAngles:
    """Joint angles of every segment of ``markerset`` over ``trial``.

    Parameters
    ----------
    trial : Trial
        ``points`` (frames, markers, 3) metres, NaN where missing.
    markerset : MarkerSet
    sequence : str
        scipy Euler sequence, default ``"ZXY"``.
    unwrap : bool
        Continuous angles (unwrap_angles); False keeps scipy's principal values.
    gimbal_tolerance : float
        Degrees; frames this near gimbal lock give a GimbalLockWarning per
        segment (naming the segment and the first such frame).

    Returns
    -------
    JointAngles
        ``values`` (frames, segments, 3) degrees; NaN where a segment's or its
        parent's markers are missing.

    Raises
    ------
    MocapError
        Unknown sequence, or markers the set needs missing from the trial.
    """
    from mocap.frames import segment_frames

    check_sequence(sequence)
    rotations, _ = segment_frames(trial, markerset)
    parents = markerset.parent_index
    principal = matrices_to_angles(relative_rotations(rotations, parents), sequence)
    _warn_gimbal(principal, sequence, markerset.segment_names, trial, gimbal_tolerance)
    values = unwrap_angles(principal, sequence) if unwrap else principal
    return JointAngles(times=trial.times, values=values, segments=markerset.segment_names,
                       sequence=sequence, parents=list(parents))


def _warn_gimbal(principal: np.ndarray, sequence: str, segments: list[str], trial: Trial,
                 tolerance: float) -> None:
    near = near_gimbal_lock(principal, sequence, tolerance)            # (F, S)
    for s in np.flatnonzero(near.any(axis=0)):
        frames = np.flatnonzero(near[:, s])
        first = int(frames[0])
        where = f" in {trial.path}" if trial.path else ""
        warnings.warn(
            f"segment '{segments[s]}'{where}: {len(frames)} frame(s) within "
            f"{tolerance:g} degrees of gimbal lock for sequence {sequence}, first at frame "
            f"{first} ({first / trial.rate:.3f} s); the first and third angles are "
            f"ill-defined there, try a sequence with another middle axis",
            GimbalLockWarning, stacklevel=3)


# ------------------------------------------------------------------------------ CSV

def write_angles_csv(angles: JointAngles, path: str | os.PathLike) -> None:
    """Write joint angles as CSV (DESIGN 3.2), all-or-nothing.

    Header ``time,<segment>.<axis>,…``; time in seconds, angles in degrees
    with 6 decimals; a NaN angle is an empty cell.
    """
    frames, segments, _ = angles.values.shape
    table = np.empty((frames, 1 + 3 * segments))
    table[:, 0] = angles.times
    table[:, 1:] = angles.values.reshape(frames, 3 * segments)
    buffer = io.StringIO()
    np.savetxt(buffer, table, fmt="%.6f", delimiter=",")
    body = buffer.getvalue().replace("nan", "")
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="") as handle:
            handle.write(",".join(angles.columns) + "\n")
            handle.write(body)


_EMPTY_CELL = re.compile(r"(?<=,)(?=,|$)|^(?=,)", re.MULTILINE)


def read_angles_csv(path: str | os.PathLike, markerset: MarkerSet | None = None
                    ) -> JointAngles:
    """Read a joint-angle CSV written by write_angles_csv (or to DESIGN 3.2).

    Parameters
    ----------
    path : path-like
    markerset : MarkerSet, optional
        Supplies ``parents`` (the CSV does not store them); otherwise -1 each.

    Raises
    ------
    MocapError
        Missing file, bad header, ragged rows or non-numeric cells.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MocapError("file not found", path) from None
    except (OSError, UnicodeDecodeError) as error:
        raise MocapError(f"cannot read: {error}", path) from None
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
    sequence = "".join(a.rstrip("2") for a in letters)
    if sequence not in SEQUENCES or axis_names(sequence) != letters:
        raise MocapError(f"axis columns {letters} name no Euler sequence", path)
    body = body.strip("\n")
    if body:
        try:
            table = np.loadtxt(io.StringIO(_EMPTY_CELL.sub("nan", body)), delimiter=",",
                               ndmin=2, dtype=float)
        except ValueError as error:
            raise MocapError(f"bad row: {error}", path) from None
        if table.shape[1] != len(columns):
            raise MocapError(f"rows have {table.shape[1]} cells, the header "
                             f"{len(columns)}", path)
    else:
        table = np.zeros((0, len(columns)))
    parents = markerset.parent_index if markerset is not None else [-1] * len(segments)
    if markerset is not None and markerset.segment_names != segments:
        raise MocapError(f"segments {segments} differ from marker set "
                         f"'{markerset.name}' ({markerset.segment_names})", path)
    return JointAngles(times=table[:, 0].copy(),
                       values=table[:, 1:].reshape(len(table), len(segments), 3).copy(),
                       segments=segments, sequence=sequence, parents=list(parents))
