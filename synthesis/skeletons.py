"""Skeleton corpora (BVH, ASF/AMC): the rig's own joints, wrap-free features, leg cycles, takes.

When every trial of a corpus shares one skeleton (same joint names and hierarchy), the
corpus is decomposed on that rig's own joints; when skeletons differ (or ``body=True``)
every trial is first mapped onto the 15-segment body model
(:func:`mocap.body.retarget.reduce_to_segments`). Each trial then becomes
(:mod:`synthesis.rotations`) rotation vectors about the corpus mean rotation of each joint
(the body root's heading removed) and root motion in the heading frame.

With ``cycles=True`` the trials are cut on one leg signal chosen for the whole corpus
(:func:`synthesis.cycles.leg_separation` along :func:`synthesis.cycles.walking_axis`): an
action is *cyclic* when most of its trials hold a complete cycle; a trial of a cyclic action
without one is used whole, with a :class:`~synthesis.cycles.CycleWarning` naming it, and the
trials of an action that is not cyclic are time-normalised whole (one warning naming the
action) — ``--cycles`` never aborts a corpus. Every cycle is registered so that its
mid-cycle event lands at the corpus' mean phase; the cycles of a trial and the takes of a
cell are averaged, and each cell keeps its mean cycle duration and mid-event phase (its
timing).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable

import numpy as np

from mocap.body.retarget import reduce_to_segments
from mocap.body.segments import read_joint_map
from mocap.errors import MocapError
from mocap.io import file_kind
from mocap.io.motion import read_motion
from mocap.skeleton import Motion, Skeleton
from synthesis.cycles import (CycleWarning, foot_joints, leg_cycles, leg_separation,
                              register_cycle, walking_axis, warn_misaligned_cycles)
from synthesis.rotations import (ROOT_FEATURES, chordal_mean, features_to_rotations,
                                 root_features, root_path, rotation_features, skeleton_frames,
                                 yaw_matrices)

def is_skeleton_trial(path: str | Path) -> bool:
    """True for a BVH file or an AMC motion (:func:`mocap.io.file_kind`)."""
    return file_kind(path) == "motion"


def same_skeleton(motions: list) -> bool:
    """True when every motion has the first one's joint names and hierarchy."""
    first = motions[0].skeleton
    return all(m.skeleton.names == first.names and m.skeleton.parents == first.parents
               for m in motions[1:])


@dataclass
class RigSignals:
    """What the whole corpus shares for cutting cycles: the feet, the walking axis, a leg.

    ``axes`` holds the axes of actions whose feet do not swing along the walking axis
    (sidesteps: across it), found by :func:`cut_action`; a new trial without a cycle along the
    walking axis is tried along them.
    """

    feet: tuple
    axis: np.ndarray
    leg_length: float
    axes: dict = field(default_factory=dict)

    def separation(self, frames) -> np.ndarray:
        """Horizontal foot separation of one trial in its heading frame, (frames, 2) metres."""
        return leg_separation(frames.positions, frames.heading, self.feet)

    def signal(self, frames) -> np.ndarray:
        """Leg signal of one trial (:class:`synthesis.rotations.SkeletonFrames`), metres."""
        return self.separation(frames) @ self.axis

    def to_json(self) -> dict:
        return {"feet": [int(f) for f in self.feet], "axis": [float(v) for v in self.axis],
                "leg_length": float(self.leg_length),
                "axes": {a: [float(v) for v in axis] for a, axis in self.axes.items()}}

    @classmethod
    def from_json(cls, value: dict) -> "RigSignals":
        return cls(tuple(value["feet"]), np.asarray(value["axis"], float),
                   float(value["leg_length"]),
                   {a: np.asarray(v, float) for a, v in (value.get("axes") or {}).items()})


def cut_action(times: list, separations: list, axis: np.ndarray, leg_length: float
               ) -> tuple[list, np.ndarray | None]:
    """Cycles of one action's trials along the walking axis or, failing that, its own axis.

    Walking backwards swings the feet along the walking axis like walking forwards, but a
    sidestep swings them across it: when most trials show no complete cycle along ``axis``,
    the action's own swing axis (:func:`synthesis.cycles.walking_axis` of its trials) is tried.

    Parameters
    ----------
    times : list of ndarray, shape (frames,), seconds
    separations : list of ndarray, shape (frames, 2), metres
        Foot separation of each trial in its heading frame.
    axis : ndarray, shape (2,)
        The corpus' walking axis.
    leg_length : float, metres

    Returns
    -------
    events : list of ndarray, shape (cycles, 3)
        ``[start, middle, end]`` seconds per trial (maybe empty).
    own_axis : ndarray, shape (2,), or None
        The action's own axis when it was used.
    """
    events = [leg_cycles(t, s @ axis, leg_length) for t, s in zip(times, separations)]
    if 2 * sum(len(e) > 0 for e in events) >= len(events):
        return events, None
    own = walking_axis(separations)
    if abs(float(own @ axis)) > 0.9:              # the same axis: nothing new to try
        return events, None
    again = [leg_cycles(t, s @ own, leg_length) for t, s in zip(times, separations)]
    if sum(len(e) > 0 for e in again) > sum(len(e) > 0 for e in events):
        return again, own
    return events, None


def rig_signals(frames: list, parents: list[int]) -> RigSignals:
    """Feet, walking axis and leg length of a corpus from its trials' frames."""
    first = frames[0].positions[0]
    feet = foot_joints(first, parents)
    legs = [float(np.median(f.root[:, 1] - f.positions[:, list(feet), 1].min(axis=1)))
            for f in frames]
    axis = walking_axis([leg_separation(f.positions, f.heading, feet) for f in frames])
    return RigSignals(feet, axis, float(np.median(legs)))


def trial_events(times: np.ndarray, signal: np.ndarray, signals: RigSignals) -> np.ndarray:
    """``[start, middle, end]`` seconds of the complete cycles of one trial (maybe none)."""
    return leg_cycles(times, signal, signals.leg_length)


def normalise_trial(times: np.ndarray, features: np.ndarray, root: np.ndarray,
                    events: np.ndarray | None, phase: float, samples: int
                    ) -> tuple[np.ndarray, np.ndarray, float, float, int]:
    """One trial → its mean registered cycle (or the whole trial when ``events`` is None).

    Returns
    -------
    curve : ndarray, shape (samples, features)
    root : ndarray, shape (samples, 4)
    duration : float, seconds
    middle : float
        Phase of the mid-cycle event before registration (``phase`` for a whole trial).
    count : int
        Cycles averaged (1 for a whole trial).
    """
    both = np.concatenate([features, root], axis=1)
    if events is None or len(events) == 0:
        curve = register_cycle(times, both, np.array([times[0], times[-1]]),
                               np.array([0.0, 1.0]), samples)
        width = features.shape[1]
        return curve[:, :width], curve[:, width:], float(times[-1] - times[0]), phase, 1
    targets = np.array([0.0, phase, 1.0])
    curves = np.stack([register_cycle(times, both, cycle, targets, samples) for cycle in events])
    curve = curves.mean(axis=0)
    width = features.shape[1]
    spans = events[:, 2] - events[:, 0]
    middles = (events[:, 1] - events[:, 0]) / spans
    return curve[:, :width], curve[:, width:], float(spans.mean()), float(middles.mean()), \
        int(len(events))


def read_skeleton_corpus(entries: list, samples: int, cycles: bool, body: bool = False,
                         progress: Callable[[Iterable, str], Iterable] | None = None,
                         joint_map=None) -> dict:
    """Read, featurise, cut and stack a corpus of BVH / ASF-AMC trials.

    Parameters
    ----------
    entries : list of synthesis.corpus.CorpusEntry
    samples : int
        Frames per normalised cycle.
    cycles : bool
        Cut cycles on the leg signal (see module notes); otherwise each trial is one cycle.
    body : bool
        Map every trial onto the 15-segment body model even when they share one skeleton.
    progress : callable, optional
    joint_map : path or dict, optional
        Body segment → joint name for the mapping onto the body, where the rig's joint names
        do not say it (:func:`mocap.body.segments.read_joint_map`).

    Returns
    -------
    dict
        The fields of a :class:`synthesis.corpus.MotionCorpus` with
        ``representation="rotvec"`` (:func:`synthesis.corpus.read_corpus` builds it).
    """
    wrap = progress or (lambda items, description: items)
    if joint_map is not None and not isinstance(joint_map, dict):
        joint_map = read_joint_map(joint_map)
    motions = [read_motion(entry.path, joint_map=joint_map)
               for entry in wrap(entries, "reading trials")]
    for entry, motion in zip(entries, motions):
        if motion.frames < 2:
            raise MocapError("a trial needs at least two frames to be time-normalised",
                             entry.path)
    on_body = body or not same_skeleton(motions)
    if on_body:
        mapped = []
        for entry, motion in zip(entries, motions):
            try:
                mapped.append(reduce_to_segments(motion))
            except MocapError as error:
                raise MocapError(error.problem, error.path or entry.path) from None
            except (KeyError, ValueError) as error:
                raise MocapError(f"cannot map the skeleton onto the body model: {error}",
                                 entry.path) from None
        motions = mapped
    skeleton = motions[0].skeleton
    frames = [skeleton_frames(motion) for motion in motions]
    joints = frames[0].joints
    means = np.stack([chordal_mean(np.concatenate([f.rotations[:, k] for f in frames]))
                      for k in range(len(joints))])
    times = [motion.times for motion in motions]
    features = [rotation_features(f.rotations, means) for f in frames]
    roots = [root_features(t, f.heading, f.root) for t, f in zip(times, frames)]
    signals = None
    if cycles:
        try:
            signals = rig_signals(frames, skeleton.parents)
        except MocapError as error:
            warnings.warn(f"no leg signal to cut cycles on ({error.problem}): every trial is "
                          "time-normalised whole", CycleWarning, stacklevel=2)
    events: list = [None] * len(entries)
    if signals is not None:
        separations = [signals.separation(f) for f in frames]
        for action in sorted({e.action for e in entries}):
            mine = [k for k, e in enumerate(entries) if e.action == action]
            found, own = cut_action([times[k] for k in mine], [separations[k] for k in mine],
                                    signals.axis, signals.leg_length)
            for k, cut in zip(mine, found):
                events[k] = cut
            if own is not None:
                signals.axes[action] = own
                warnings.warn(f"action {action!r}: the feet swing across the walking direction "
                              "(a sidestep?); its cycles are cut along its own axis",
                              CycleWarning, stacklevel=2)
            with_cycles = [k for k in mine if len(events[k])]
            if 2 * len(with_cycles) < len(mine):
                warnings.warn(f"action {action!r} is not cyclic (no complete gait cycle in "
                              f"{len(mine) - len(with_cycles)} of its {len(mine)} trials): its "
                              "trials are time-normalised whole", CycleWarning, stacklevel=2)
                for k in mine:
                    events[k] = None
            else:
                for k in set(mine) - set(with_cycles):
                    warnings.warn(f"{entries[k].path}: no complete cycle (fewer than two "
                                  "repetitions of the movement); the trial is used whole",
                                  CycleWarning, stacklevel=2)
                    events[k] = None
    middles = [(ev[:, 1] - ev[:, 0]) / (ev[:, 2] - ev[:, 0]) for ev in events
               if ev is not None and len(ev)]
    phase = float(np.mean(np.concatenate(middles))) if middles else 0.5
    per_cell: dict = {}
    cut: dict = {}
    for k, entry in enumerate(entries):
        result = normalise_trial(times[k], features[k], roots[k], events[k], phase, samples)
        per_cell.setdefault((entry.person, entry.action), []).append((result, str(entry.path)))
        if events[k] is not None and len(events[k]):
            cut.setdefault(entry.action, []).append((result[0], str(entry.path)))
    for action, trials in cut.items():
        warn_misaligned_cycles(np.stack([curve for curve, _ in trials]),
                               [source for _, source in trials], action)
    people = sorted({person for person, _ in per_cell})
    actions = sorted({action for _, action in per_cell})
    names = [skeleton.names[j] for j in joints]
    width = features[0].shape[1]
    shape = (len(people), len(actions))
    angles = np.full(shape + (samples, width), np.nan)
    root = np.full(shape + (samples, len(ROOT_FEATURES)), np.nan)
    durations, phases = np.full(shape, np.nan), np.full(shape, np.nan)
    counts = np.zeros(shape, dtype=int)
    takes, sources = {}, {}
    for (person, action), parts in per_cell.items():
        p, a = people.index(person), actions.index(action)
        curves = np.stack([r[0] for r, _ in parts])
        takes[(person, action)] = curves
        angles[p, a] = curves.mean(axis=0)
        root[p, a] = np.mean([r[1] for r, _ in parts], axis=0)
        durations[p, a] = float(np.mean([r[2] for r, _ in parts]))
        phases[p, a] = float(np.mean([r[3] for r, _ in parts]))
        counts[p, a] = int(sum(r[4] for r, _ in parts))
        sources[(person, action)] = [source for _, source in parts]
    rig = {"names": list(skeleton.names), "parents": list(skeleton.parents),
           "offsets": skeleton.offsets.tolist(), "joints": list(joints), "on_body": on_body,
           "phase": phase, "signals": None if signals is None else signals.to_json(),
           "cut_actions": sorted(cut)}
    return dict(
        people=people, actions=actions, segments=names,
        parents=[joints.index(skeleton.parents[j]) if skeleton.parents[j] in joints else -1
                 for j in joints],
        sequence="rotvec", columns=[f"{n}.{c}" for n in names for c in ("rx", "ry", "rz")],
        angles=angles, durations=durations, cycle_counts=counts, cycles=cycles,
        cycle_column="leg signal" if cycles else None, sources=sources,
        representation="rotvec", rotation_means=means, root=root, phases=phases, takes=takes,
        rig=rig, trial_cycles={} if signals is None else
        {str(e.path): 0 if events[k] is None else len(events[k]) for k, e in enumerate(entries)})


def trial_cycle(motion, rig: dict, means: np.ndarray, samples: int, cycles: bool,
                source: str | Path | None = None
                ) -> tuple[np.ndarray, np.ndarray, float, float, int]:
    """One new trial, featurised and cut the way a corpus was (for recognition and signatures).

    Parameters
    ----------
    motion : mocap.skeleton.Motion
    rig : dict
        :attr:`synthesis.corpus.MotionCorpus.rig` of the corpus the model came from.
    means : ndarray, shape (joints, 3, 3)
        The corpus' mean joint rotations.
    samples : int
    cycles : bool
        Cut cycles on the corpus' leg signal; a trial without a complete cycle is used whole
        (with a :class:`~synthesis.cycles.CycleWarning`).
    source : path, optional
        For messages.

    Returns
    -------
    As :func:`normalise_trial`, except that ``count`` is 0 for a trial used whole.
    """
    if rig.get("on_body"):
        motion = reduce_to_segments(motion)
    if motion.skeleton.names != rig["names"] or motion.skeleton.parents != rig["parents"]:
        raise MocapError("the trial's skeleton differs from the model's rig (joints "
                         f"{', '.join(motion.skeleton.names)}; the model knows "
                         f"{', '.join(rig['names'])})", source)
    frames = skeleton_frames(motion)
    times = motion.times
    features = rotation_features(frames.rotations, means)
    root = root_features(times, frames.heading, frames.root)
    events = None
    if cycles and rig.get("signals"):
        signals = RigSignals.from_json(rig["signals"])
        separation = signals.separation(frames)
        events = trial_events(times, separation @ signals.axis, signals)
        for axis in signals.axes.values():      # actions cut along their own axis
            if len(events) == 0:
                events = trial_events(times, separation @ axis, signals)
        if len(events) == 0:
            warnings.warn(f"{source or 'trial'}: no complete cycle (fewer than two repetitions "
                          "of the movement); the trial is used whole", CycleWarning,
                          stacklevel=2)
            events = None
    result = normalise_trial(times, features, root, events, float(rig.get("phase", 0.5)), samples)
    return result if events is not None else result[:4] + (0,)


def unregister_cycle(curve: np.ndarray, registered: float, phase: float) -> np.ndarray:
    """Undo the registration of a cycle: the sample at registered phase ``registered`` moves
    to ``phase`` (piecewise-linear time warp), resampled at equal time steps.

    Parameters
    ----------
    curve : ndarray, shape (samples, columns), in registered phase
    registered, phase : float, in (0, 1)

    Returns
    -------
    ndarray, shape (samples, columns)
    """
    samples = curve.shape[0]
    if not (0.0 < phase < 1.0 and 0.0 < registered < 1.0):
        return np.asarray(curve, float)
    grid = np.linspace(0.0, 1.0, samples)
    # Real time t ↦ registered phase u: linear on [0, phase] → [0, registered] and after.
    source = np.interp(grid, [0.0, phase, 1.0], [0.0, registered, 1.0])
    return np.stack([np.interp(source, grid, column) for column in np.asarray(curve, float).T],
                    axis=1)


def cycle_motion(rig: dict, means: np.ndarray, curve: np.ndarray, root: np.ndarray,
                 duration: float, cycles: int = 1, phase: float | None = None):
    """A synthesised cycle back on the rig: rotations, heading and root path, repeated.

    Parameters
    ----------
    rig : dict
        :attr:`synthesis.corpus.MotionCorpus.rig`.
    means : ndarray, shape (joints, 3, 3)
    curve : ndarray, shape (samples, joints · 3), rotation-vector features (degrees)
    root : ndarray, shape (samples, 4), root motion in the heading frame
        (:data:`synthesis.rotations.ROOT_FEATURES`)
    duration : float
        Seconds per cycle.
    cycles : int
        Repetitions (the last sample of one is the first of the next).
    phase : float, optional
        The person's own phase of the mid-cycle event: the registered cycle is re-timed so the
        event falls there (:func:`unregister_cycle`) — timing style as well as poses.

    Returns
    -------
    mocap.skeleton.Motion
        Joints above the body root hold still; the body root follows the integrated path
        (starting at the origin, heading 0) at the synthesised height.
    """
    if cycles < 1:
        raise MocapError(f"cycles must be at least 1, got {cycles}")
    if not duration > 0:
        raise MocapError(f"the cycle duration must be positive, got {duration}")
    if phase is not None:
        registered = float(rig.get("phase", 0.5))
        curve = unregister_cycle(curve, registered, phase)
        root = unregister_cycle(root, registered, phase)
    repeat = lambda values: np.concatenate([np.tile(values[:-1], (cycles, 1)),  # noqa: E731
                                            values[-1:]])
    features, motion_root = repeat(np.asarray(curve, float)), repeat(np.asarray(root, float))
    frames = features.shape[0]
    times = np.linspace(0.0, cycles * duration, frames)
    heading, path = root_path(times, motion_root)
    local = features_to_rotations(features, means)
    joints = list(rig["joints"])
    names, parents = list(rig["names"]), list(rig["parents"])
    offsets = np.asarray(rig["offsets"], float)
    rotations = np.broadcast_to(np.eye(3), (frames, len(names), 3, 3)).copy()
    rotations[:, joints] = local
    rotations[:, joints[0]] = yaw_matrices(heading) @ local[:, 0]
    chain, index = [], joints[0]
    while index >= 0:
        chain.append(index)
        index = parents[index]
    translation = path - offsets[chain].sum(axis=0)
    rate = (frames - 1) / (cycles * duration)
    return Motion(Skeleton(names, parents, offsets), translation, rotations, rate,
                  {"source": "synthesised", "format": "synthesis"})
