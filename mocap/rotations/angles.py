"""Joint angles: relative segment rotations as continuous Euler/Cardan angles.

A joint rotation is ``R_parent⁻¹ R_child`` (a root segment's is its rotation in
the lab).  Angles follow scipy's ``Rotation.as_euler`` convention: an upper-case
sequence (``"ZXY"``) is intrinsic, a lower-case one (``"zxy"``) extrinsic; all 12
Tait-Bryan (three different axes) and 12 proper Euler (first axis repeated)
sequences are accepted.  Angles are in degrees and continuous (see
:func:`unwrap_angles`); frames with missing markers stay NaN, and become empty
cells in the CSV (``docs/formats/angles-csv.md``).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from mocap.errors import MocapError
from mocap.rotations.euler import euler_from_components
from mocap.rotations.frames import iter_frame_blocks
from mocap.markersets import MarkerSet
from mocap.trial import Trial

#: The 24 sequences accepted: 12 intrinsic (upper case) and 12 extrinsic.
SEQUENCES = tuple(
    s for s in (a + b + c for a in "XYZ" for b in "XYZ" for c in "XYZ")
    if s[0] != s[1] and s[1] != s[2]
) + tuple(
    s.lower() for s in (a + b + c for a in "XYZ" for b in "XYZ" for c in "XYZ")
    if s[0] != s[1] and s[1] != s[2]
)
#: Default sequence (``docs/formats/angles-csv.md``).
DEFAULT_SEQUENCE = "ZXY"
#: Column suffixes of clinical (Plug-in Gait) angles, Cardan YXZ.
CLINICAL_AXES = ("flexion", "adduction", "rotation")
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
    axes : list of 3 str, optional
        Column suffixes instead of the sequence's letters, e.g. Plug-in Gait's
        ``["flexion", "adduction", "rotation"]`` (clinical angles).
    """

    times: np.ndarray
    values: np.ndarray
    segments: list[str]
    sequence: str
    parents: list[int]
    axes: list[str] | None = None

    @property
    def frames(self) -> int:
        """Number of frames."""
        return int(self.values.shape[0])

    @property
    def columns(self) -> list[str]:
        """CSV header: ``time`` then ``<segment>.<axis>`` (``docs/formats/angles-csv.md``)."""
        names = self.axes or axis_names(self.sequence)
        return ["time"] + [f"{s}.{a}" for s in self.segments for a in names]

    def segment(self, name: str) -> np.ndarray:
        """Angles of one segment, shape (frames, 3), degrees."""
        try:
            return self.values[:, self.segments.index(name), :]
        except ValueError:
            raise KeyError(name) from None

    def to_dataframe(self):
        """The angles as a pandas DataFrame: index ``time`` (s), one column per
        ``<segment>.<axis>`` in degrees (the CSV's header, ``docs/formats/angles-csv.md``),
        NaN where unknown. Needs pandas (the ``tables`` extra)."""
        from mocap.errors import import_pandas

        pandas = import_pandas()
        index = pandas.Index(np.asarray(self.times, dtype=float), name="time")
        return pandas.DataFrame(self.values.reshape(self.frames, -1), index=index,
                                columns=self.columns[1:])


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


def _relative_components(components: np.ndarray, parent_index: list[int]) -> np.ndarray:
    """relative_rotations in the component-major layout of iter_frame_blocks.

    components : (3, 3, frames, segments) → same shape, ``R_parent^T R_child``.
    """
    parents = np.asarray(parent_index, dtype=int)
    roots = parents < 0
    parent = components[..., np.where(roots, 0, parents)]
    relative = np.empty_like(components)
    for i in range(3):
        for k in range(3):
            entry = relative[i, k]
            np.multiply(parent[0, i], components[0, k], out=entry)
            entry += parent[1, i] * components[1, k]
            entry += parent[2, i] * components[2, k]
    relative[..., roots] = components[..., roots]
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

    Examples
    --------
    >>> half = np.sqrt(0.5)                       # 45° about z, then nothing
    >>> matrices_to_angles(np.array([[half, -half, 0], [half, half, 0], [0, 0, 1]]), "ZXY")
    array([45.,  0.,  0.])
    """
    check_sequence(sequence)
    flat = np.asarray(matrices, dtype=float).reshape(-1, 3, 3)
    out = np.empty((flat.shape[0], 3))
    # blocks of rotations, so the temporaries stay in the cache (3x faster on 1.5 M)
    for start in range(0, flat.shape[0], EULER_BLOCK):
        block = slice(start, start + EULER_BLOCK)
        out[block] = euler_from_components(np.moveaxis(flat[block], (1, 2), (0, 1)), sequence)
    return out.reshape(np.shape(matrices)[:-2] + (3,))


#: Rotations per block of :func:`matrices_to_angles`.
EULER_BLOCK = 16384


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
    from scipy.spatial.transform import Rotation   # deferred: 0.4 s to import
    check_sequence(sequence)
    values = np.asarray(values_deg, dtype=float)
    shape = values.shape[:-1]
    flat = values.reshape(-1, 3)
    valid = np.isfinite(flat).all(axis=1)
    out = np.full((flat.shape[0], 3, 3), np.nan)
    if valid.any():
        out[valid] = Rotation.from_euler(sequence, flat[valid], degrees=True).as_matrix()
    return out.reshape(shape + (3, 3))


def _other_branch(values: np.ndarray, proper: bool) -> np.ndarray:
    """The second Euler triple of the same rotation.

    Tait-Bryan: (a + 180, 180 - b, c + 180); proper Euler: (a + 180, -b, c + 180).
    """
    other = values.copy()
    other[..., 0] += 180.0
    other[..., 2] += 180.0
    other[..., 1] = (180.0 - values[..., 1]) if not proper else -values[..., 1]
    return other


def _turns(step: np.ndarray) -> np.ndarray:
    """Whole turns to remove from a step of less than 540° (-1, 0 or 1)."""
    return (step > 180.0).astype(np.int32) - (step < -180.0)


def _circle_distance(step: np.ndarray) -> np.ndarray:
    """Distance on the circle of a step of at most 360° in size, degrees."""
    step = np.abs(step)
    return np.minimum(step, 360.0 - step)


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
    unwrapper = Unwrapper(sequence, values.shape[1])
    out = np.empty_like(values)
    # blocks of frames keep the temporaries in the cache; state carries over
    for start in range(0, values.shape[0], UNWRAP_BLOCK):
        block = slice(start, start + UNWRAP_BLOCK)
        out[block] = unwrapper(values[block])
    return out


def unwrap_columns(values: np.ndarray, period: float = 360.0) -> np.ndarray:
    """Remove whole-period jumps along axis 0 of every column on its own, skipping NaN.

    Unlike :func:`unwrap_angles` this knows nothing of Euler triples (no branch switch): it is
    ``np.unwrap`` per column (a BVH channel, an angle curve), over the samples where the
    column is defined; the first sample after a gap continues from the last one before it.

    Parameters
    ----------
    values : ndarray, shape (frames, ...)
        Angles in the unit of ``period`` (degrees by default), NaN where undefined.
    period : float
        Size of one turn.

    Returns
    -------
    ndarray, same shape as ``values``; NaN stays NaN.

    Examples
    --------
    >>> unwrap_columns(np.array([[170.0], [np.nan], [-170.0]]))[:, 0].tolist()
    [170.0, nan, 190.0]
    """
    # C order: the reshape below must be a view, or the columns' writes are lost
    values = np.array(values, dtype=float, order="C")
    valid = ~np.isnan(values)
    if valid.all():
        _remove_turns(values, period)
        return values
    flat, valid = values.reshape(values.shape[0], -1), valid.reshape(values.shape[0], -1)
    for column in np.flatnonzero(~valid.all(axis=0)):   # loop over columns with gaps only
        rows = valid[:, column]
        flat[rows, column] = np.unwrap(flat[rows, column], period=period)
    complete = valid.all(axis=0)
    flat[:, complete] = np.unwrap(flat[:, complete], period=period, axis=0)
    return values


def unwrap_turns(values: np.ndarray) -> np.ndarray:
    """The principal branch's continuity: whole turns of the first and third angles.

    The middle angle keeps scipy's principal range (no frame ever changes
    branch, so no 180° set can leak past a gap or a fill); the first and
    third are unwrapped by :func:`unwrap_columns` (a gap is skipped: the first
    valid frame after it continues from the last one before).

    Parameters
    ----------
    values : ndarray, shape (frames, ..., 3), degrees (principal values)

    Returns
    -------
    ndarray, same shape; NaN where ``values`` is NaN.

    Examples
    --------
    >>> unwrap_turns(np.array([[170.0, 0, 0], [-175, 0, 0], [np.nan] * 3, [-170, 0, 0]]))[:, 0]
    array([170., 185.,  nan, 190.])
    """
    out = np.array(values, dtype=float, copy=True)
    _unwrap_turns_in_place(out)
    return out


def _remove_turns(values: np.ndarray, period: float) -> None:
    """:func:`unwrap_columns` of columns without NaN, in place (``values`` may be a strided
    view): np.unwrap's result (whole turns removed where a step exceeds half a turn) in a
    third of its time, the turns being counted as integers."""
    # block by block of frames (small temporaries); the turns are whole numbers, so the
    # running count carried from block to block is exact
    if values.shape[0] < 2:
        return
    carry = np.zeros(values.shape[1:])
    previous = values[0].copy()
    for start in range(1, values.shape[0], UNWRAP_BLOCK):
        chunk = values[start:start + UNWRAP_BLOCK]
        step = np.diff(chunk, axis=0, prepend=previous[None])
        previous = chunk[-1].copy()                 # before it is unwrapped
        turns = np.divide(step, period)
        np.rint(turns, out=turns)
        turns[np.abs(step) <= period / 2] = 0.0
        np.cumsum(turns, axis=0, out=turns)
        turns += carry
        carry = turns[-1].copy()
        turns *= period
        chunk -= turns


def _unwrap_turns_in_place(values: np.ndarray) -> None:
    """:func:`unwrap_turns` on ``values`` itself (frames, ..., 3): without a copy of the
    first and third angles when they have no gap."""
    first, third = values[..., 0], values[..., 2]
    if np.isnan(first).any() or np.isnan(third).any():
        values[..., [0, 2]] = unwrap_columns(values[..., [0, 2]])
    else:
        _remove_turns(first, 360.0)
        _remove_turns(third, 360.0)




#: Frames per block of Unwrapper work in unwrap_angles.
UNWRAP_BLOCK = 2048


class Unwrapper:
    """unwrap_angles over consecutive blocks of frames, carrying its state.

    Calling it with the principal values of the next block of frames
    (frames, segments, 3) returns their continuous values; the result over all
    blocks equals unwrap_angles over the whole trial.

    Parameters
    ----------
    sequence : str
        scipy Euler sequence of the angles.
    segments : int
        Number of segments in every block.
    """

    def __init__(self, sequence: str, segments: int):
        self.proper = is_proper_euler(sequence)
        self.last = np.full((segments, 3), np.nan)       # principal, last valid frame
        self.branch = np.zeros(segments, dtype=bool)     # its branch
        self.turns = np.zeros((segments, 3), dtype=np.int32)  # its accumulated turns

    def __call__(self, values: np.ndarray) -> np.ndarray:
        frames, segments = values.shape[:2]
        if frames == 0:
            return values.copy()
        proper = self.proper
        # row 0 is the carried last valid frame (NaN when there is none yet)
        rows = np.concatenate([self.last[None], values], axis=0)          # (F+1, S, 3)
        valid = ~np.isnan(rows[..., 0])
        if valid.all():
            def previous_of(array: np.ndarray) -> np.ndarray:
                return array[:-1]
            has_previous = np.ones((frames, segments), dtype=bool)
            last_row = np.full(segments, frames)
        else:
            index = np.where(valid, np.arange(frames + 1)[:, None], -1)
            last_valid = np.maximum.accumulate(index, axis=0)
            last_row = last_valid[-1]
            previous = last_valid[:-1]                                    # for rows 1..F
            has_previous = valid[1:] & (previous >= 0)
            take, columns = np.maximum(previous, 0), np.arange(segments)[None, :]

            def previous_of(array: np.ndarray) -> np.ndarray:
                return array[take, columns]
        current = rows[1:]

        # branch: switch where the other triple is nearer the previous frame
        # (both triples of the previous frame are equally far apart, so
        # comparing principal values suffices); the branch is a running XOR
        step = current - previous_of(rows)                                # (F, S, 3)
        outer = _circle_distance(step[..., [0, 2]])                       # |wrap(a)|, |wrap(c)|
        same = np.einsum("fsk,fsk->fs", outer, outer) + step[..., 1] ** 2
        flipped = (180.0 - current[..., 1]) if not proper else -current[..., 1]
        middle_other = _circle_distance(flipped - previous_of(rows[..., 1]))
        outer_other = 180.0 - outer            # a shift of 180° on the circle
        other = np.einsum("fsk,fsk->fs", outer_other, outer_other) + middle_other ** 2
        switch = has_previous & (other < same)
        branch = np.empty((frames + 1, segments), dtype=bool)
        branch[0] = self.branch
        branch[1:] = ((np.cumsum(switch, axis=0, dtype=np.int32) & 1).astype(bool)
                      ^ self.branch)
        chosen = rows.copy()
        if branch.any():
            chosen[branch] = _other_branch(rows[branch], proper)

        # turns: remove 360° jumps between consecutive valid frames
        step = chosen[1:] - previous_of(chosen)
        turns = np.empty((frames + 1, segments, 3), dtype=np.int32)
        turns[0] = self.turns
        turns[1:] = np.where(has_previous[..., None], _turns(step), 0)
        np.cumsum(turns, axis=0, out=turns)
        out = chosen[1:] - 360.0 * turns[1:]
        out[~valid[1:]] = np.nan

        # carry the last valid frame of each segment into the next block
        had = last_row >= 0
        pick = np.maximum(last_row, 0), np.arange(segments)
        self.last = np.where(had[:, None], rows[pick], np.nan)
        self.branch = np.where(had, branch[pick], False)
        self.turns = np.where(had[:, None], turns[pick], 0)
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


#: Angle branches joint_angles offers.
BRANCHES = ("principal", "continuous")


def joint_angles(trial: Trial, markerset: MarkerSet, sequence: str = DEFAULT_SEQUENCE,
                 *, unwrap: bool = True, branch: str = "principal",
                 gimbal_tolerance: float = GIMBAL_TOLERANCE) -> JointAngles:
    """Joint angles of every segment of ``markerset`` over ``trial``.

    Parameters
    ----------
    trial : Trial
        ``points`` (frames, markers, 3) metres, NaN where missing.
    markerset : MarkerSet
    sequence : str
        scipy Euler sequence, default ``"ZXY"``.
    unwrap : bool
        Remove 360° jumps (see ``branch``); False keeps scipy's principal values
        frame by frame.
    branch : {"principal", "continuous"}
        ``"principal"`` (default): the middle angle stays in the principal
        range ([-90, 90] Tait-Bryan, [0, 180] proper Euler) and only the first
        and third angles are unwrapped by whole turns, within each run of
        valid frames (unwrap_turns).  ``"continuous"``: the branch too follows
        the motion through gimbal lock, across gaps (unwrap_angles).
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

    Examples
    --------
    >>> from mocap.io import read                                  # doctest: +SKIP
    >>> from mocap.markersets import load_markerset                 # doctest: +SKIP
    >>> trial = read("HC002D06.c3d")                               # doctest: +SKIP
    >>> angles = joint_angles(trial, load_markerset("plugingait-lower"), "YXZ")  # doctest: +SKIP
    >>> knee_flexion = angles.segment("l_shank")[:, 0]             # doctest: +SKIP
    """

    check_sequence(sequence)
    if branch not in BRANCHES:
        raise ValueError(f"branch must be one of {BRANCHES}, not {branch!r}")
    full = markerset.apply_virtual(trial)
    columns = markerset.marker_columns(full.labels)
    parents = markerset.parent_index
    values = np.empty((trial.frames, len(parents), 3))
    near = np.zeros((trial.frames, len(parents)), dtype=bool)
    continuous = unwrap and branch == "continuous"
    unwrapper = Unwrapper(sequence, len(parents))
    # block by block of frames, so the intermediate matrices stay in the cache
    for block, components in iter_frame_blocks(full.points, columns,
                                               markerset.axes_matrices):
        principal = euler_from_components(_relative_components(components, parents),
                                          sequence)
        near[block] = near_gimbal_lock(principal, sequence, gimbal_tolerance)
        values[block] = unwrapper(principal) if continuous else principal
    if unwrap and not continuous:
        _unwrap_turns_in_place(values)          # values is ours: no copy
    _warn_gimbal(near, sequence, markerset.segment_names, trial, gimbal_tolerance)
    return JointAngles(times=trial.times, values=values, segments=markerset.segment_names,
                       sequence=sequence, parents=list(parents))


def _warn_gimbal(near: np.ndarray, sequence: str, segments: list[str], trial: Trial,
                 tolerance: float) -> None:
    for s in np.flatnonzero(near.any(axis=0)):
        frames = np.flatnonzero(near[:, s])
        first = int(frames[0])
        where = f" in {trial.path}" if trial.path else ""
        warnings.warn(
            f"segment '{segments[s]}'{where}: {len(frames)} frame(s) within "
            f"{tolerance:g} degrees of gimbal lock for sequence {sequence}, first at frame "
            f"{first}{f' ({first / trial.rate:.3f} s)' if trial.rate > 0 else ''}; the "
            f"first and third angles are "
            f"ill-defined there, try a sequence with another middle axis",
            GimbalLockWarning, stacklevel=3)
