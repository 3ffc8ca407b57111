"""Synthetic trials and corpora: markers with ground truth, written to a folder."""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from mocap import io
from mocap.rotations.angles import JointAngles, matrices_to_angles
from mocap.atomic import atomic_path
from mocap.errors import MocapError
from mocap.io.angles_csv import write_angles_csv
from mocap.progress import progress
from mocap.synthetic.balance import _motion
from mocap.synthetic.people import (
    _STYLES,
    ACTIONS,
    MARKER_LABELS,
    PARENT_INDEX,
    SEGMENT_NAMES,
    GroundTruth,
    Person,
    _contact_points,
    _marker_positions,
    _offsets,
    cycle_seconds,
    lab_frames,
    make_people,
)
from mocap.synthetic.templates import _to_rotations
from mocap.trial import Trial

# --------------------------------------------------------------------------- trials

def person_angles(person: Person, action: str, phase: np.ndarray, seed: int = 0) -> np.ndarray:
    """Clinical joint angles of ``person`` doing ``action``, (frames, segments, 3) degrees.

    ``phase`` is the gait-cycle phase (cycles, 0 = right foot landing); it may run
    over several cycles.  Leg angles come from the feet's paths by inverse kinematics
    (see the module docstring), the others from the action's templates.
    """
    return _motion(person, action, phase, seed)[0]


def synthesize_trial(person: int | Person, action: str, seed: int = 0, people: int = 6,
                     rate: float = 100.0, cycles: float = 1.0, noise_mm: float = 0.0,
                     gap_fraction: float = 0.0) -> tuple[Trial, GroundTruth]:
    """One synthetic trial and its ground truth.

    Parameters
    ----------
    person : int or Person
        Index into ``make_people(people, seed)`` or a Person.
    action : str
        One of ``ACTIONS``.
    seed : int
        Seeds people, styles, noise and gaps: same seed, same trial.
    people : int
        Size of the population ``person`` indexes.
    rate : float
        Sampling rate, Hz.
    cycles : float
        Number of gait cycles in the trial; one cycle spans exactly one period
        (the last sample falls one sample before the next heel strike).
    noise_mm : float
        Standard deviation of Gaussian marker noise, millimetres.
    gap_fraction : float
        About this fraction of marker samples is removed as gaps of 3–30 frames.

    Returns
    -------
    trial : Trial
        Markers in metres, labels ``MARKER_LABELS``.
    truth : GroundTruth
    """
    if isinstance(person, int):
        population = make_people(max(people, person + 1), seed)
        person = population[person]
    if rate <= 0 or cycles <= 0:
        raise MocapError(f"rate and cycles must be positive (got {rate}, {cycles})")
    period = cycle_seconds(person, action, seed)
    frames = max(int(round(cycles * period * rate)), 2)
    times = np.arange(frames) / rate
    clinical, root, _ = _motion(person, action, times / period, seed)
    joint_rotations = _to_rotations(clinical)
    offsets = _offsets(person)
    rotations, origins = lab_frames(joint_rotations, offsets, root)
    points = _marker_positions(rotations, origins)
    rng = np.random.default_rng([seed, 4, ACTIONS.index(action), sum(map(ord, person.name))])
    if noise_mm > 0:
        points = points + rng.normal(0.0, noise_mm / 1000.0, size=points.shape)
    if gap_fraction > 0:
        points = _add_gaps(points, gap_fraction, rng)
    trial = Trial(list(MARKER_LABELS), points, rate, units="m", format="synthetic",
                  metadata={"person": person.name, "action": action, "generator": "mocap.synthetic",
                            "cycle_seconds": period})
    truth = GroundTruth(joint_rotations, rotations, origins, offsets,
                        _contact_points(rotations, origins, person), rate, person.name, action,
                        period)
    return trial, truth


def _add_gaps(points: np.ndarray, fraction: float, rng: np.random.Generator) -> np.ndarray:
    """Blank random runs of 3–30 frames in random markers until ``fraction`` is missing."""
    points = points.copy()
    frames, markers = points.shape[:2]
    target = fraction * frames * markers
    missing = 0
    while missing < target:
        length = int(rng.integers(3, min(30, max(frames - 1, 4))))
        start = int(rng.integers(0, max(frames - length, 1)))
        marker = int(rng.integers(0, markers))
        before = np.isnan(points[start:start + length, marker, 0]).sum()
        points[start:start + length, marker] = np.nan
        missing += length - before
    return points


# --------------------------------------------------------------------------- corpus

def truth_angles(truth: GroundTruth, sequence: str = "ZXY"):
    """Ground-truth joint angles of a trial in ``sequence``, as a :class:`mocap.rotations.angles.JointAngles`."""
    values = matrices_to_angles(truth.rotations, sequence)
    times = np.arange(truth.rotations.shape[0]) / truth.rate
    return JointAngles(times=times, values=values, segments=list(SEGMENT_NAMES),
                       sequence=sequence, parents=list(PARENT_INDEX))


def generate_corpus(out_dir: str | Path, people: int = 6, actions: Sequence[str] = ACTIONS,
                    seed: int = 0, noise_mm: float = 0.0, gap_fraction: float = 0.0,
                    cycles: float = 1.0, rate: float = 100.0, sequence: str = "ZXY",
                    file_format: str = "c3d", show_progress: bool | None = None) -> list[Path]:
    """Write a people × actions corpus of marker trials with ground truth.

    Writes ``<person>_<action>.<file_format>`` marker files into ``out_dir`` and the
    exact joint angles as ``truth/<person>_<action>_angles.csv`` (``docs/formats/angles-csv.md`` angle CSV,
    ``sequence``), plus ``truth/people.csv`` with each person's signature
    parameters (height m, cadence, timing, asymmetry, style factors).

    Parameters
    ----------
    out_dir : path
        Created if needed.
    people : int
        Number of people (at least 1).
    actions : sequence of str
        Subset of ``ACTIONS``.
    seed, noise_mm, gap_fraction, cycles, rate
        As in :func:`synthesize_trial`.
    sequence : str
        Euler sequence of the ground-truth CSVs.
    file_format : {"c3d", "trc", "csv"}
    show_progress : bool, optional
        Progress bar on stderr (default: when stderr is a terminal).

    Returns
    -------
    list of Path
        The marker files written, person-major.
    """
    unknown = [a for a in actions if a not in ACTIONS]
    if unknown:
        raise MocapError(f"unknown action(s) {', '.join(unknown)}; known: {', '.join(ACTIONS)}")
    if not actions:
        raise MocapError("need at least one action")
    repeated = sorted({a for a in actions if list(actions).count(a) > 1})
    if repeated:
        raise MocapError(f"action(s) {', '.join(repeated)} given more than once; each action "
                         "is one trial per person")
    if file_format not in ("c3d", "trc", "csv"):
        raise MocapError(f"unknown marker file format {file_format!r}; use c3d, trc or csv")
    out_dir = Path(out_dir)
    truth_dir = out_dir / "truth"
    truth_dir.mkdir(parents=True, exist_ok=True)
    population = make_people(people, seed)
    written = []
    cells = [(person, action) for person in population for action in actions]
    for person, action in progress(cells, "generating trials", enabled=show_progress):
        trial, truth = synthesize_trial(person, action, seed=seed, rate=rate, cycles=cycles,
                                        noise_mm=noise_mm, gap_fraction=gap_fraction)
        path = out_dir / f"{person.name}_{action}.{file_format}"
        io.write(trial, path)
        write_angles_csv(truth_angles(truth, sequence), truth_dir / f"{person.name}_{action}_angles.csv")
        written.append(path)
    with atomic_path(truth_dir / "people.csv") as tmp:
        header = "person,height_m,cadence,timing,asymmetry," + ",".join(
            f"style{k + 1}" for k in range(_STYLES))
        rows = [f"{p.name},{p.height:.4f},{p.cadence:.4f},{p.timing:.4f},{p.asymmetry:.4f},"
                + ",".join(f"{s:.4f}" for s in p.style) for p in population]
        tmp.write_text("\n".join([header] + rows) + "\n")
    return written
