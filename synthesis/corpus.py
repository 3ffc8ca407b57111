"""Corpus → people × actions tensor: list trials, read their joint angles, stack the cycles.

A *corpus* is a set of trials, each labelled with a person and an action: a folder of files
named ``<person>_<action>[_<anything>].<c3d|csv|trc|bvh|amc>`` (sub-folders such as ``truth/``
are ignored) or a manifest CSV with columns ``path,person,action``. Each trial becomes joint
angles (``mocap.rotations.angles.joint_angles`` with a marker set; read directly from an angle CSV),
then one gait cycle of ``samples`` frames per angle (unwrapping, one cycle per trial or cycle
detection, branch: see :mod:`synthesis.cycles`). A corpus of skeleton trials only (BVH,
ASF/AMC) is read by :mod:`synthesis.skeletons` instead: the rig's own joints (or the body model
when skeletons differ), rotation vectors about the corpus mean rotations, heading removed,
leg-signal cycles (``representation="rotvec"``); ``representation="euler"`` keeps the older
Euler angles on the body model.

* **Several trials of one (person, action) cell** are averaged the same way as cycles.
* **Heading.** Euler corpora are heading-free too: each trial is turned about the lab
  vertical by its mean pelvis heading (:func:`synthesis.rotations.remove_mean_heading`), so a
  walk through the lab in −X gives the angles of the same walk in +X. An angle CSV read
  without a marker set has no hierarchy (no root to turn) and keeps its angles, and so does
  every trial of its corpus (``MotionCorpus.heading_removed`` says which).

The result, :class:`MotionCorpus`, holds ``angles`` (people, actions, samples, columns) in
degrees and ``durations`` (people, actions) in seconds, NaN where a cell is missing.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable, Iterable, Sequence

import numpy as np

from mocap.rotations.angles import JointAngles, axis_names, check_sequence, unwrap_columns
from mocap.body.angles import motion_joint_angles
from mocap.body.segments import read_joint_map
from mocap.errors import MocapError
from mocap.io import file_kind
from mocap.io.angles_csv import read_angles_csv
from mocap.io.discovery import find_files, is_angle_csv, parse_trial_name
from mocap.io.motion import MARKER_SUFFIXES, MOTION_SUFFIXES, read_motion
from mocap.markersets import load_markerset
from mocap.pipeline import Cleaning, marker_file_angles
from synthesis.cycles import DEFAULT_SAMPLES, centre_branch, mean_cycle, warn_misaligned_cycles
from synthesis.rotations import hierarchy_known, remove_mean_heading
from synthesis.skeletons import is_skeleton_trial, read_skeleton_corpus

#: File suffixes a corpus folder may hold: marker trials (and angle CSVs), BVH and ASF/AMC
#: (read through ``mocap.io.motion``).
TRIAL_SUFFIXES = MARKER_SUFFIXES + MOTION_SUFFIXES



# --------------------------------------------------------------------------- corpus listing

@dataclass(frozen=True)
class CorpusEntry:
    """One trial of a corpus: where it is and whose (person, action) it is."""

    path: Path
    person: str
    action: str


def list_corpus_folder(folder: str | Path) -> list[CorpusEntry]:
    """Trials directly inside ``folder`` (sub-folders ignored), sorted by name.

    Parameters
    ----------
    folder : path
        Holds ``<person>_<action>[_anything].<c3d|csv|trc|bvh|amc>`` files.

    Returns
    -------
    list of CorpusEntry
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise MocapError("corpus must be a folder of trials (or give a manifest= CSV)", folder)
    files = find_files([folder], TRIAL_SUFFIXES, recursive=False)
    entries = []
    for path in files:
        person, action = parse_trial_name(path)
        entries.append(CorpusEntry(path, person, action))
    return entries


def read_manifest(manifest: str | Path) -> list[CorpusEntry]:
    """Trials listed in a manifest CSV with columns ``path,person,action``.

    Relative paths are taken relative to the manifest's folder.
    """
    manifest = Path(manifest)
    if not manifest.is_file():
        raise MocapError("manifest not found", manifest)
    try:
        with open(manifest, newline="", encoding="utf-8-sig") as handle:
            rows = list(csv.DictReader(handle))
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise MocapError(f"cannot read manifest: {error}", manifest) from None
    if not rows or not {"path", "person", "action"} <= set(rows[0].keys()):
        raise MocapError("manifest needs a header with columns path,person,action and one row "
                         "per trial", manifest)
    entries = []
    for number, row in enumerate(rows, start=2):
        path, person, action = (str(row.get(k) or "").strip() for k in ("path", "person", "action"))
        if not (path and person and action):
            raise MocapError(f"line {number}: path, person and action must all be given",
                             manifest)
        resolved = Path(path) if Path(path).is_absolute() else manifest.parent / path
        entries.append(CorpusEntry(resolved, person, action))
    return entries


# --------------------------------------------------------------------------- reading angles

def angle_columns(segments: Sequence[str], sequence: str) -> list[str]:
    """Column names ``<segment>.<axis>`` of ``docs/formats/angles-csv.md`` (a repeated axis letter gets a ``2``).

    Examples
    --------
    >>> angle_columns(["pelvis"], "ZYZ")
    ['pelvis.Z', 'pelvis.Y', 'pelvis.Z2']
    """
    return [f"{segment}.{letter}" for segment in segments for letter in axis_names(sequence)]


def _named_like_markers(path: Path, markerset) -> bool:
    """True when a CSV that parses as angles (``<name>.x,<name>.y,<name>.z``) is rather a
    marker CSV: a marker set is given and the names are not its segments but its markers."""
    if markerset is None or isinstance(markerset, (str, Path)):
        return False
    with open(path, newline="", encoding="utf-8-sig") as handle:
        header = next(csv.reader(handle), [])
    names = {column.strip().rpartition(".")[0] for column in header[1:]}
    markers = {label for segment in markerset.segments for label in segment.markers}
    return not names <= set(markerset.segment_names) and names <= markers | \
        {v.name for v in getattr(markerset, "virtual", [])}


def read_trial_angles(path: str | Path, markerset=None, sequence: str = "ZXY",
                      lowpass_hz: float | None = None, max_gap_seconds: float | None = None,
                      joint_map: str | Path | dict | None = None):
    """Joint angles of one trial file.

    Parameters
    ----------
    path : path
        A marker trial (``.c3d``, ``.csv``, ``.trc``), a joint-angle CSV (``docs/formats/angles-csv.md``), a BVH
        file or an AMC motion (with ``<person>.asf`` beside it), the last two mapped onto the
        15-segment body model (``mocap.body.retarget.reduce_to_segments``).
    markerset : MarkerSet, str or None
        Marker set (object, preset name or TOML path) for marker trials; not needed for angle
        CSVs (whose segments, when they are the set's, get its hierarchy).
    sequence : str
        Euler sequence (scipy convention) for marker trials.
    lowpass_hz : float, optional
        Zero-lag Butterworth low-pass of the markers before the angles
        (:func:`mocap.clean.lowpass`), Hz.
    max_gap_seconds : float, optional
        Fill marker gaps up to this long first (:func:`mocap.clean.fill_gaps`), seconds.
    joint_map : path or dict, optional
        BVH/AMC: body segment → joint name where the rig's names do not say it.

    Returns
    -------
    mocap.rotations.angles.JointAngles
        ``values`` (frames, segments, 3) degrees, ``times`` (frames,) seconds; an angle CSV
        with the marker set's segments gets its ``parents``.
    """
    path = Path(path)
    if not path.exists():
        raise MocapError("trial file not found", path)
    if isinstance(markerset, (str, Path)):
        markerset = load_markerset(markerset)
    if is_angle_csv(path) and not _named_like_markers(path, markerset):
        angles = read_angles_csv(path)
        if markerset is not None and list(angles.segments) == list(markerset.segment_names):
            angles.parents = list(markerset.parent_index)     # the CSV does not store them
        return angles
    if file_kind(path) == "motion":
        return _skeleton_angles(path, sequence, joint_map)
    if markerset is None:
        raise MocapError("marker trials need markerset= to turn markers into joint angles",
                         path)
    cleaning = Cleaning(max_gap_seconds=float(max_gap_seconds) if max_gap_seconds else None,
                        lowpass_hz=float(lowpass_hz) if lowpass_hz else None, short_runs="keep")
    return marker_file_angles(path, markerset, sequence, cleaning).angles


def _skeleton_angles(path: Path, sequence: str, joint_map=None):
    """Joint angles of a BVH or ASF/AMC file on the 15-segment body model, in a Z-up lab's axes
    (the axes of marker-derived angles): :func:`mocap.body.angles.motion_joint_angles` of
    :func:`mocap.io.motion.read_motion`."""
    check_sequence(sequence)
    return motion_joint_angles(read_motion(path, joint_map=joint_map), sequence)


# --------------------------------------------------------------------------- the corpus

@dataclass
class MotionCorpus:
    """People × actions joint-angle cycles, time-normalised; NaN where a cell is missing.

    Attributes
    ----------
    people, actions : list of str
        Sorted names (tensor order).
    segments : list of str
        Segments in marker-set order.
    parents : list of int
        Parent index of each segment (−1 for the root).
    sequence : str
        Euler sequence of the angles (scipy convention).
    columns : list of str
        Angle column names ``<segment>.<axis>`` (``docs/formats/angles-csv.md``), ``len = 3 · segments``.
    angles : ndarray, shape (people, actions, samples, columns), degrees
    durations : ndarray, shape (people, actions), seconds
    cycle_counts : ndarray, shape (people, actions), int
        Cycles averaged into each cell (0 = missing).
    markerset : str or None
        Marker set name or path the angles came from.
    cycles : bool
        Whether cycles were detected (else one cycle per trial).
    cycle_column : str or None
        Reference angle of cycle detection.
    sources : dict of (person, action) to list of str
        Files of each cell.
    cleaning : dict
        Marker cleaning applied before the angles: ``lowpass_hz``, ``max_gap_seconds``.
    representation : {"euler", "rotvec"}
        ``"euler"``: ``angles`` are Euler angles (degrees, ``sequence``); ``"rotvec"``
        (skeleton corpora, :mod:`synthesis.skeletons`): rotation vectors about
        ``rotation_means`` (degrees; columns ``<joint>.rx|ry|rz``; the body root's is its
        tilt, heading removed).
    rotation_means : ndarray, shape (segments, 3, 3), optional
        Corpus mean rotation of each joint (``"rotvec"``).
    root : ndarray, shape (people, actions, samples, 4), optional
        Root motion in the heading frame (:data:`synthesis.rotations.ROOT_FEATURES`).
    phases : ndarray, shape (people, actions), optional
        Phase of the registered mid-cycle event (the cycle's time warp), in (0, 1).
    takes : dict of (person, action) to ndarray (takes, samples, columns)
        Every take of a cell (for take hold-out and the take-to-take spread).
    rig : dict, optional
        Skeleton to write synthesised motions on: ``names``, ``parents``, ``offsets``
        (metres), ``joints`` (feature joints), ``on_body`` (mapped onto the body model).
    trial_cycles : dict of str to int
        Skeleton corpora read with cycles: trial path → complete cycles found (0: none, the
        trial was time-normalised whole).
    heading_removed : bool
        Whether the heading about the vertical is out of the features: every skeleton corpus
        (per frame, the body root's tilt); an Euler corpus whose trials all have a known
        hierarchy (per trial, :func:`synthesis.rotations.remove_mean_heading`).
    """

    people: list[str]
    actions: list[str]
    segments: list[str]
    parents: list[int]
    sequence: str
    columns: list[str]
    angles: np.ndarray
    durations: np.ndarray
    cycle_counts: np.ndarray
    markerset: str | None = None
    cycles: bool = False
    cycle_column: str | None = None
    sources: dict = field(default_factory=dict)
    cleaning: dict = field(default_factory=dict)
    representation: str = "euler"
    rotation_means: np.ndarray | None = None
    root: np.ndarray | None = None
    phases: np.ndarray | None = None
    takes: dict = field(default_factory=dict)
    rig: dict | None = None
    trial_cycles: dict = field(default_factory=dict)
    heading_removed: bool = False

    #: Per-cell arrays (first two axes people × actions) and their "missing" value.
    _CELL_ARRAYS = (("angles", np.nan), ("durations", np.nan), ("cycle_counts", 0),
                    ("root", np.nan), ("phases", np.nan))

    @property
    def samples(self) -> int:
        """Frames per normalised cycle."""
        return int(self.angles.shape[2])

    @property
    def observed(self) -> np.ndarray:
        """(people, actions) bool: True where the cell was captured."""
        return np.isfinite(self.durations)

    def missing_cells(self) -> list[tuple[str, str]]:
        """(person, action) pairs nobody captured."""
        return [(self.people[p], self.actions[a]) for p, a in np.argwhere(~self.observed)]

    def without_cell(self, person: str, action: str) -> "MotionCorpus":
        """A copy with one cell removed (for leave-one-out)."""
        p, a = self.people.index(person), self.actions.index(action)
        changed = {}
        for name, missing in self._CELL_ARRAYS:
            value = getattr(self, name)
            if value is not None:
                value = value.copy()
                value[p, a] = missing
                changed[name] = value
        sources = {key: value for key, value in self.sources.items() if key != (person, action)}
        takes = {key: value for key, value in self.takes.items() if key != (person, action)}
        return replace(self, sources=sources, takes=takes, **changed)

    def subset(self, people: Sequence[str] | None = None, actions: Sequence[str] | None = None
               ) -> "MotionCorpus":
        """A copy restricted to some people and/or actions (in the given order)."""
        people = list(self.people if people is None else people)
        actions = list(self.actions if actions is None else actions)
        unknown = [n for n in people if n not in self.people] + \
                  [n for n in actions if n not in self.actions]
        if unknown:
            raise MocapError(f"not in the corpus: {', '.join(unknown)}")
        pi = [self.people.index(n) for n in people]
        ai = [self.actions.index(n) for n in actions]
        inside = {key for key in self.sources if key[0] in people and key[1] in actions}
        changed = {name: getattr(self, name)[np.ix_(pi, ai)] for name, _ in self._CELL_ARRAYS
                   if getattr(self, name) is not None}
        return replace(self, people=people, actions=actions,
                       sources={key: self.sources[key] for key in inside},
                       takes={key: v for key, v in self.takes.items() if key in inside},
                       **changed)


def check_corpus_size(people: Sequence[str], actions: Sequence[str],
                      source: str | Path | None = None) -> None:
    """MocapError unless there are at least two people and two actions."""
    if len(people) < 2 or len(actions) < 2:
        def named(names: Sequence[str], singular: str, plural: str) -> str:
            listed = f" ({', '.join(names)})" if names else ""
            return f"{len(names)} {singular if len(names) == 1 else plural}{listed}"
        raise MocapError("need at least 2 people and 2 actions to separate people from actions, "
                         f"found {named(people, 'person', 'people')} and "
                         f"{named(actions, 'action', 'actions')}", source)


def stack_corpus(cells: dict[tuple[str, str], list[tuple[np.ndarray, float, int]]],
                 segments: Sequence[str], parents: Sequence[int], sequence: str,
                 **metadata) -> MotionCorpus:
    """Build a :class:`MotionCorpus` from normalised cycles grouped by (person, action).

    Parameters
    ----------
    cells : dict
        ``(person, action) → [(curve (samples, columns) degrees, duration s, cycles), …]``;
        several entries of one cell are averaged (weighted by their cycle counts).
    segments, parents, sequence
        Skeleton description shared by every curve.
    **metadata
        ``markerset``, ``cycles``, ``cycle_column``, ``sources`` for the corpus.
    """
    people = sorted({person for person, _ in cells})
    actions = sorted({action for _, action in cells})
    check_corpus_size(people, actions)
    first = next(iter(cells.values()))[0][0]
    samples, columns = first.shape
    angles = np.full((len(people), len(actions), samples, columns), np.nan)
    durations = np.full((len(people), len(actions)), np.nan)
    counts = np.zeros((len(people), len(actions)), dtype=int)
    for (person, action), parts in cells.items():
        p, a = people.index(person), actions.index(action)
        weights = np.array([count for _, _, count in parts], dtype=float)
        curves = centre_branch(np.stack([curve for curve, _, _ in parts]))
        angles[p, a] = np.tensordot(weights / weights.sum(), curves, axes=1)
        durations[p, a] = float(np.dot(weights, [d for _, d, _ in parts]) / weights.sum())
        counts[p, a] = int(weights.sum())
    return MotionCorpus(people=people, actions=actions, segments=list(segments),
                        parents=[int(i) for i in parents], sequence=sequence,
                        columns=angle_columns(segments, sequence), angles=angles,
                        durations=durations, cycle_counts=counts, **metadata)


def read_corpus(entries: Iterable[CorpusEntry], markerset=None, sequence: str = "ZXY",
                samples: int = DEFAULT_SAMPLES, cycles: bool = False,
                cycle_column: str | None = None, lowpass_hz: float | None = None,
                max_gap_seconds: float | None = None,
                progress: Callable[[Iterable, str], Iterable] | None = None,
                representation: str = "auto", body: bool = False,
                joint_map: str | Path | dict | None = None,
                remove_heading: bool = True) -> MotionCorpus:
    """Read, time-normalise and stack the trials of a corpus.

    Parameters
    ----------
    entries : iterable of CorpusEntry
        From :func:`list_corpus_folder` or :func:`read_manifest`.
    markerset : str, path, MarkerSet or None
        Marker set for marker trials (angle CSVs need none).
    sequence : str
        Euler sequence for marker trials.
    samples : int
        Frames per normalised cycle.
    cycles : bool
        Detect and average cycles (see module notes); otherwise one cycle per trial.
    cycle_column : str, optional
        Reference angle column for cycle detection (``"r_thigh.Y"``); default: the column
        with the largest mean standard deviation over the corpus.
    lowpass_hz, max_gap_seconds : optional
        Marker cleaning before the angles (see :func:`read_trial_angles`).
    progress : callable, optional
        ``progress(iterable, description)`` wrapper (e.g. :func:`mocap.progress.progress`).
    representation : {"auto", "rotvec", "euler"}
        ``"auto"``: a corpus of skeleton trials only (BVH, ASF/AMC) gets wrap-free rotation
        features (:mod:`synthesis.skeletons`), anything else Euler angles; ``"euler"``:
        Euler angles of every trial on the body model (the older representation).
    body : bool
        Skeleton corpora: map onto the 15-segment body model even when every trial shares
        one skeleton.
    joint_map : path or dict, optional
        Body segment → joint name for the BVH/ASF-AMC trials' rig, where its joint names do
        not say it (:func:`mocap.body.segments.read_joint_map`).
    remove_heading : bool
        Euler corpora: turn each trial by its mean heading (see :func:`corpus_from_angles`);
        False keeps the direction of travel in the lab as a feature. Skeleton corpora
        always remove it.

    Returns
    -------
    MotionCorpus
    """
    entries = list(entries)
    if not entries:
        raise MocapError("the corpus has no trials")
    check_corpus_size(sorted({e.person for e in entries}), sorted({e.action for e in entries}))
    if representation not in ("auto", "rotvec", "euler"):
        raise MocapError(f"unknown representation {representation!r}: auto, rotvec or euler")
    skeletal = all(is_skeleton_trial(e.path) for e in entries)
    if representation == "rotvec" and not skeletal:
        raise MocapError("rotation-vector features need skeleton trials (BVH, ASF/AMC) only")
    if representation != "euler" and skeletal:
        return MotionCorpus(**read_skeleton_corpus(entries, samples, cycles, body, progress,
                                                   joint_map=joint_map), heading_removed=True)
    if joint_map is not None and not isinstance(joint_map, dict):
        joint_map = read_joint_map(joint_map)
    markerset_name = None if markerset is None else str(getattr(markerset, "name", markerset))
    if isinstance(markerset, (str, Path)):
        markerset = load_markerset(markerset)
    wrap = progress or (lambda items, description: items)
    read = []
    for entry in wrap(entries, "reading trials"):
        angles = read_trial_angles(entry.path, markerset, sequence, lowpass_hz, max_gap_seconds,
                                   joint_map=joint_map)
        read.append((entry, angles))
    return corpus_from_angles(read, samples, cycles, cycle_column, remove_heading,
                              markerset=markerset_name,
                              cleaning={"lowpass_hz": lowpass_hz,
                                        "max_gap_seconds": max_gap_seconds})


def corpus_from_angles(trials: Sequence[tuple[CorpusEntry, JointAngles]],
                       samples: int = DEFAULT_SAMPLES, cycles: bool = False,
                       cycle_column: str | None = None, remove_heading: bool = True,
                       **metadata) -> MotionCorpus:
    """Time-normalise and stack joint angles already computed, one per trial.

    :func:`read_corpus` reads the files and calls this; a program that has the angles in
    memory (the demo) calls it directly, with no file written and read back.

    Parameters
    ----------
    trials : sequence of (CorpusEntry, JointAngles)
        Each trial's (path, person, action) and its angles (``values`` (frames, segments,
        3) degrees, ``times`` (frames,) seconds); every trial has the same segments and
        Euler sequence.
    samples, cycles, cycle_column
        As :func:`read_corpus`.
    remove_heading : bool
        Turn each trial about the lab vertical (Z) by its mean heading
        (:func:`synthesis.rotations.remove_mean_heading`), when every trial's hierarchy is
        known (:func:`synthesis.rotations.hierarchy_known`); otherwise the angles are kept
        as they are.
    **metadata
        ``markerset``, ``cleaning`` … recorded in the corpus.

    Returns
    -------
    MotionCorpus
    """
    read = list(trials)
    if not read:
        raise MocapError("the corpus has no trials")
    reference_segments, reference_sequence = read[0][1].segments, read[0][1].sequence
    for entry, angles in read:
        if list(angles.segments) != list(reference_segments):
            raise MocapError(f"segments {', '.join(angles.segments)} differ from those of "
                             f"{read[0][0].path.name} ({', '.join(reference_segments)})",
                             entry.path)
        if angles.sequence != reference_sequence:
            raise MocapError(f"Euler sequence {angles.sequence} differs from {reference_sequence} "
                             f"of {read[0][0].path.name}", entry.path)
    heading_removed = remove_heading and all(hierarchy_known(a) for _, a in read)
    if heading_removed:
        read = [(entry, remove_mean_heading(angles)) for entry, angles in read]
    columns = angle_columns(reference_segments, reference_sequence)
    reference = None
    if cycles:
        if cycle_column is not None:
            if cycle_column not in columns:
                raise MocapError(f"cycle reference angle {cycle_column!r} is not a column; "
                                 f"columns are {', '.join(columns)}")
            reference = columns.index(cycle_column)
        else:
            spreads = [np.nanstd(unwrap_columns(_flat(a)), axis=0) for _, a in read]
            reference = int(np.argmax(np.nanmean(np.stack(spreads), axis=0)))
    cells: dict[tuple[str, str], list] = {}
    sources: dict[tuple[str, str], list[str]] = {}
    cut: dict[str, list] = {}
    for entry, angles in read:
        curve, duration, count = mean_cycle(np.asarray(angles.times), _flat(angles),
                                            samples, cycles, reference, entry.path)
        cells.setdefault((entry.person, entry.action), []).append((curve, duration, count))
        sources.setdefault((entry.person, entry.action), []).append(str(entry.path))
        cut.setdefault(entry.action, []).append((curve, str(entry.path)))
    if cycles:
        for action, trials in cut.items():
            warn_misaligned_cycles(centre_branch(np.stack([curve for curve, _ in trials])),
                                   [source for _, source in trials], action)
    return stack_corpus(cells, reference_segments, read[0][1].parents, reference_sequence,
                        cycles=cycles,
                        cycle_column=None if reference is None else columns[reference],
                        sources=sources, heading_removed=heading_removed, **metadata)


def _flat(angles) -> np.ndarray:
    """(frames, segments, 3) angle values → (frames, columns)."""
    values = np.asarray(angles.values, dtype=float)
    return values.reshape(values.shape[0], -1)


def load_corpus(corpus: str | Path | None = None, manifest: str | Path | None = None,
                people: Sequence[str] | None = None, actions: Sequence[str] | None = None,
                **options) -> MotionCorpus:
    """A corpus folder or manifest → :class:`MotionCorpus` (``options`` as :func:`read_corpus`).

    ``people`` / ``actions`` keep only those trials, before any file is read.
    """
    if manifest is not None:
        entries = read_manifest(manifest)
    elif corpus is not None:
        entries = list_corpus_folder(corpus)
    else:
        raise MocapError("give a corpus= folder or a manifest= CSV")
    source = manifest if manifest is not None else corpus
    for names, attribute, label in ((people, "person", "people"), (actions, "action", "actions")):
        if names:
            known = {getattr(e, attribute) for e in entries}
            unknown = [n for n in names if n not in known]
            if unknown:
                raise MocapError(f"not in the corpus: {', '.join(unknown)} (its {label}: "
                                 f"{', '.join(sorted(known))})", source)
            entries = [e for e in entries if getattr(e, attribute) in set(names)]
    return read_corpus(entries, **options)
