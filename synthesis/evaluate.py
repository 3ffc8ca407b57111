"""Leave-one-cell-out evaluation of motion synthesis and person recognition.

Each captured (person, action) cell is held out in turn: a model is fitted to the corpus
without that cell (so the person is incomplete and takes no part in the bases), the cell is
synthesised from the person's other actions, and compared with the capture:

* **synthesis error**: RMS geodesic angle between the synthesised and the captured joint
  rotations over the normalised cycle, degrees (independent of any Euler sequence);
* **baseline**: the mean of the other people's captures of that action;
* **additive**: that mean plus the person's mean offset over their other actions;
* **recognition**: the person whose model motion of that action is nearest to the held-out
  capture (the held-out person's entry is their prediction, everyone else's their capture;
  distances weighted per segment by the model's prediction variance when it has one);
* **take-to-take spread**: with several takes per cell, the RMS angle between a take and the
  mean of the others — what no model can beat. ``hold_out="take"`` scores each take against
  a model that never saw it.

Cells whose person has no other action are skipped (nothing to predict from).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable, Iterable

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.errors import MocapError
from synthesis.corpus import MotionCorpus
from synthesis.model import MotionModel
from synthesis.rotations import geodesic_deg


def rotation_errors(corpus: MotionCorpus, first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Geodesic angle (degrees) between the joint rotations of two cycles, (samples, segments).

    Rotation-vector corpora compare the rotations directly; Euler corpora turn each
    segment's three angles into a rotation first, so the figure does not depend on the
    Euler sequence.
    """
    if corpus.representation == "rotvec":
        return geodesic_deg(first, second)
    samples = first.shape[0]
    a = Rotation.from_euler(corpus.sequence, first.reshape(-1, 3), degrees=True)
    b = Rotation.from_euler(corpus.sequence, second.reshape(-1, 3), degrees=True)
    return np.degrees((a.inv() * b).magnitude()).reshape(samples, -1)


def paired_comparison(cells) -> dict:
    """Cell-by-cell comparison of the synthesis with the additive model.

    Parameters
    ----------
    cells : list of CellResult

    Returns
    -------
    dict
        ``wins`` / ``losses`` / ``ties``: cells whose synthesis error is below / above / within
        0.005° of the additive model's; ``median_difference_deg``: median of (synthesis −
        additive) RMS error over the cells, degrees (negative: the model earned its complexity).

    Examples
    --------
    >>> from types import SimpleNamespace as Cell
    >>> paired_comparison([Cell(synthesis_rms=1.0, additive_rms=2.0),
    ...                    Cell(synthesis_rms=3.0, additive_rms=2.5),
    ...                    Cell(synthesis_rms=2.0, additive_rms=2.0)])
    {'wins': 1, 'losses': 1, 'ties': 1, 'median_difference_deg': 0.0}
    """
    differences = np.array([c.synthesis_rms - c.additive_rms for c in cells], dtype=float)
    differences = differences[np.isfinite(differences)]
    return {"wins": int(np.sum(differences < -TIE_DEG)),
            "losses": int(np.sum(differences > TIE_DEG)),
            "ties": int(np.sum(np.abs(differences) <= TIE_DEG)),
            "median_difference_deg": float(np.median(differences)) if differences.size
            else float("nan")}


#: Cells whose synthesis and additive errors differ by at most this much are ties, degrees.
TIE_DEG = 0.005


def _rms(values) -> float:
    values = np.asarray(values, dtype=float)
    return float(np.sqrt(np.mean(values ** 2))) if values.size else float("nan")


@dataclass
class CellResult:
    """Leave-one-out result of one (person, action) cell.

    Attributes
    ----------
    person, action : str
    synthesis_rms, baseline_rms, additive_rms : float
        RMS geodesic angle between the synthesised (baseline: mean of the other people;
        additive: that mean plus the person's mean offset over their other actions) and the
        captured joint rotations, degrees.
    duration, predicted_duration : float
        Captured and predicted cycle duration, seconds.
    recognised : str
        Person recognised from the held-out capture (action given).
    take_spread_rms : float
        RMS angle between each take of the cell and the mean of its other takes (NaN with one
        take): the floor no model can beat.
    recognised_rank : int
        How many people were nearer the held-out capture than the right one (0 = recognised;
        below 3 = in the top 3).
    right_score : float
        The recognition score (:attr:`synthesis.recognition.Recognition.scores`) of the right
        person, in [0, 1]: calibrated scores average to the accuracy.
    captured, synthesised, baseline : ndarray, shape (samples, columns)
    """

    person: str
    action: str
    synthesis_rms: float
    baseline_rms: float
    duration: float
    predicted_duration: float
    recognised: str
    captured: np.ndarray = field(repr=False, default=None)
    synthesised: np.ndarray = field(repr=False, default=None)
    baseline: np.ndarray = field(repr=False, default=None)
    additive_rms: float = float("nan")
    take_spread_rms: float = float("nan")
    recognised_rank: int = 0
    right_score: float = float("nan")


@dataclass
class Evaluation:
    """All cells of a leave-one-out evaluation.

    Attributes
    ----------
    cells : list of CellResult
    skipped : list of (person, action, reason)
    columns : list of str
        Feature column names.
    method : str
        Synthesis method the model chose (``signature`` or ``transfer``).
    hold_out : str
        ``"cell"`` (score against the cell's mean capture) or ``"take"`` (against each take
        the model did not see).
    whole_trials : list of (person, action, path)
        Trials in which cycle detection found no complete cycle (time-normalised whole).
    """

    cells: list
    skipped: list
    columns: list
    method: str = "signature"
    hold_out: str = "cell"
    whole_trials: list = field(default_factory=list)

    def _overall(self, cells) -> dict:
        synthesis = _rms([c.synthesis_rms for c in cells])
        baseline = _rms([c.baseline_rms for c in cells])
        additive = _rms([c.additive_rms for c in cells])
        spreads = [c.take_spread_rms for c in cells if np.isfinite(c.take_spread_rms)]
        return {"cell_count": len(cells), "synthesis_rms_deg": synthesis,
                "baseline_rms_deg": baseline, "additive_rms_deg": additive,
                "improvement": baseline / synthesis if synthesis > 0 else float("inf"),
                "improvement_over_additive": additive / synthesis if synthesis > 0
                else float("inf"),
                "recognition_accuracy": float(np.mean([c.recognised == c.person
                                                       for c in cells])),
                "recognition_top3": float(np.mean([c.recognised_rank < 3 for c in cells])),
                "recognition_right_score": float(np.mean([c.right_score for c in cells])),
                "recognition_log_score": float(np.mean(
                    [np.log(max(c.right_score, 1e-12)) for c in cells])),
                "versus_additive": paired_comparison(cells),
                "take_spread_rms_deg": _rms(spreads) if spreads else float("nan")}

    @property
    def synthesis_rms(self) -> float:
        """Overall RMS synthesis error over all evaluated cells, degrees."""
        return _rms([c.synthesis_rms for c in self.cells])

    @property
    def baseline_rms(self) -> float:
        """Overall RMS error of the baseline (mean of the other people), degrees."""
        return _rms([c.baseline_rms for c in self.cells])

    @property
    def additive_rms(self) -> float:
        """Overall RMS error of the additive model, degrees."""
        return _rms([c.additive_rms for c in self.cells])

    @property
    def recognition_accuracy(self) -> float:
        """Fraction of held-out cells whose person was recognised."""
        return float(np.mean([c.recognised == c.person for c in self.cells]))

    @property
    def duration_rms(self) -> float:
        """RMS error of the predicted cycle durations, seconds."""
        return _rms([c.predicted_duration - c.duration for c in self.cells])

    def by_action(self) -> dict:
        """Overall figures of each action's cells."""
        actions = sorted({c.action for c in self.cells})
        return {a: self._overall([c for c in self.cells if c.action == a]) for a in actions}

    def to_json(self) -> dict:
        """Plain dict: per-cell figures, per-action and overall ones."""
        result = {
            "method": self.method, "hold_out": self.hold_out,
            "cells": [{"person": c.person, "action": c.action,
                       "synthesis_rms_deg": c.synthesis_rms, "baseline_rms_deg": c.baseline_rms,
                       "additive_rms_deg": c.additive_rms,
                       "take_spread_rms_deg": c.take_spread_rms,
                       "duration_s": c.duration, "predicted_duration_s": c.predicted_duration,
                       "recognised": c.recognised,
                       "recognised_rank": c.recognised_rank,
                       "right_score": c.right_score} for c in self.cells],
            "skipped": [{"person": p, "action": a, "reason": r} for p, a, r in self.skipped],
            "trials_without_cycle": [{"person": p, "action": a, "path": t}
                                     for p, a, t in self.whole_trials],
            "actions": self.by_action(),
        }
        result.update(self._overall(self.cells))
        result["duration_rms_s"] = self.duration_rms
        return result

    def table(self) -> str:
        """Human-readable table: one line per cell, then the overall figures."""
        width = max([len(c.person) for c in self.cells] + [6])
        awidth = max([len(c.action) for c in self.cells] + [6])
        lines = [f"{'person':<{width}}  {'action':<{awidth}}  {'synth °':>8}  {'baseline °':>10}"
                 f"  {'additive °':>10}  {'dur s':>6}  {'pred s':>6}  recognised"]
        for c in self.cells:
            mark = "" if c.recognised == c.person else "  ✗"
            lines.append(f"{c.person:<{width}}  {c.action:<{awidth}}  {c.synthesis_rms:8.2f}  "
                         f"{c.baseline_rms:10.2f}  {c.additive_rms:10.2f}  {c.duration:6.3f}  "
                         f"{c.predicted_duration:6.3f}  {c.recognised}{mark}")
        for person, action, reason in self.skipped:
            lines.append(f"{person:<{width}}  {action:<{awidth}}  skipped: {reason}")
        overall = self._overall(self.cells)
        ratio = overall["improvement"]
        # improvement = baseline / synthesis: below 1 the synthesis is the worse of the two.
        if ratio >= 1000:
            times = "over 1000× lower"
        elif ratio >= 1:
            times = f"{ratio:.1f}× lower"
        elif ratio > 0:
            times = f"synthesis {1 / ratio:.2f}× higher"
        else:
            times = "no ratio"
        lines += [
            "",
            f"overall RMS joint-rotation error ({self.method}, held out by {self.hold_out}): "
            f"synthesis {self.synthesis_rms:.2f}°, baseline (mean of the other people) "
            f"{self.baseline_rms:.2f}° ({times}), additive (mean + the person's offset) "
            f"{self.additive_rms:.2f}°",
        ]
        if self.additive_rms > self.baseline_rms:
            lines.append("the additive model is worse than the baseline here: a person's offset "
                         "in their other actions says little about these")
        if self.whole_trials:
            actions = sorted({a for _, a, _ in self.whole_trials})
            counts = ", ".join(f"{a} {sum(t[1] == a for t in self.whole_trials)}"
                               for a in actions)
            lines.append(f"no complete cycle found (time-normalised whole) in "
                         f"{len(self.whole_trials)} trial(s): {counts} (each named in --json)")
        if np.isfinite(overall["take_spread_rms_deg"]):
            lines.append(f"take-to-take spread of the captures: "
                         f"{overall['take_spread_rms_deg']:.2f}° (the floor)")
        paired = overall["versus_additive"]
        lines += [
            f"against the additive model: {paired['wins']} cells better, {paired['losses']} "
            f"worse, {paired['ties']} equal; median difference "
            f"{paired['median_difference_deg']:+.2f}°",
            f"cycle duration RMS error: {self.duration_rms * 1000:.0f} ms",
            f"person recognition: {sum(c.recognised == c.person for c in self.cells)}/"
            f"{len(self.cells)} = {100 * self.recognition_accuracy:.0f} % "
            f"(top 3: {100 * overall['recognition_top3']:.0f} %); mean score of the right "
            f"person {overall['recognition_right_score']:.2f} (calibrated: the accuracy), "
            f"mean log score {overall['recognition_log_score']:.2f}",
        ]
        return "\n".join(lines)


def _take_spread(corpus: MotionCorpus, key: tuple[str, str]) -> float:
    takes = corpus.takes.get(key)
    if takes is None or takes.shape[0] < 2:
        return float("nan")
    errors = [rotation_errors(corpus, takes[k], np.delete(takes, k, axis=0).mean(axis=0))
              for k in range(takes.shape[0])]
    return _rms(errors)


def _without_take(corpus: MotionCorpus, take: int) -> MotionCorpus:
    """Cells averaged over their takes other than ``take`` (cells with one take unchanged)."""
    angles = corpus.angles.copy()
    for (person, action), takes in corpus.takes.items():
        if takes.shape[0] > take and takes.shape[0] >= 2:
            p, a = corpus.people.index(person), corpus.actions.index(action)
            angles[p, a] = np.delete(takes, take, axis=0).mean(axis=0)
    return replace(corpus, angles=angles)


def leave_one_out(corpus: MotionCorpus, progress: Callable[[Iterable, str], Iterable] | None = None,
                  hold_out: str = "cell", **model_options) -> Evaluation:
    """Hold out every captured cell in turn, synthesise it, compare with the capture.

    Parameters
    ----------
    corpus : MotionCorpus
    progress : callable, optional
        ``progress(iterable, description)`` wrapper.
    hold_out : {"cell", "take"}
        ``"cell"``: score against the cell's capture (mean of its takes). ``"take"``: for
        each take ``k``, the model is fitted on the other takes of every cell (the held-out
        cell removed entirely) and scored against take ``k``, which it never saw.
    **model_options
        Passed to :class:`MotionModel` (ranks, ridge, method).

    Returns
    -------
    Evaluation
    """
    if hold_out not in ("cell", "take"):
        raise MocapError(f"unknown hold-out {hold_out!r}: cell or take")
    takes = max([t.shape[0] for t in corpus.takes.values()] + [1])
    if hold_out == "take" and takes < 2:
        raise MocapError("--hold-out take needs several takes of a cell (trials of the same "
                         "person and action)")
    versions = [(None, corpus)] if hold_out == "cell" else \
        [(k, _without_take(corpus, k)) for k in range(takes)]
    observed = corpus.observed
    wrap = progress or (lambda items, description: items)
    pairs = [(p, a) for p, a in np.argwhere(observed)]
    scores: dict = {}
    skipped, method = [], "signature"
    for take, version in versions:
        cache: dict = {}
        for p, a in wrap(pairs, "leave-one-out" if take is None else f"take {take + 1}"):
            person, action = corpus.people[p], corpus.actions[a]
            key = (person, action)
            if take is None:
                captured = corpus.angles[p, a]
            else:
                cell_takes = corpus.takes.get(key)
                if cell_takes is None or cell_takes.shape[0] <= take:
                    continue
                captured = cell_takes[take]
            if observed[p].sum() < 2:
                skipped.append((person, action, "the person has no other action"))
                continue
            others = np.flatnonzero(observed[:, a] & (np.arange(len(corpus.people)) != p))
            if others.size == 0:
                skipped.append((person, action, "nobody else performed this action"))
                continue
            reduced = version.without_cell(person, action)
            try:
                model = MotionModel(**model_options).fit(reduced, cache)
            except MocapError as error:
                skipped.append((person, action, error.problem))
                continue
            method = model.method_
            curve, duration = model.synthesize(person, action)
            baseline = version.angles[others, a].mean(axis=0)
            additive = model.cells_.additive(p, a).reshape(curve.shape)
            recognition = model.recognize(captured, action)
            scores.setdefault(key, []).append(dict(
                synthesis=rotation_errors(corpus, curve, captured),
                baseline=rotation_errors(corpus, baseline, captured),
                additive=rotation_errors(corpus, additive, captured),
                duration=duration, recognised=recognition.person,
                score=recognition.scores.get(person, 0.0),
                rank=sum(d < recognition.distances[person]
                         for d in recognition.distances.values()), captured=captured,
                curve=curve, base=baseline))
    cells = []
    for (person, action), runs in scores.items():
        p, a = corpus.people.index(person), corpus.actions.index(action)
        recognised = [r["recognised"] for r in runs]
        cells.append(CellResult(
            person=person, action=action,
            synthesis_rms=_rms([r["synthesis"] for r in runs]),
            baseline_rms=_rms([r["baseline"] for r in runs]),
            additive_rms=_rms([r["additive"] for r in runs]),
            duration=float(corpus.durations[p, a]),
            predicted_duration=float(np.mean([r["duration"] for r in runs])),
            recognised=max(recognised, key=recognised.count),      # majority over takes
            recognised_rank=int(np.median([r["rank"] for r in runs])),
            right_score=float(np.mean([r["score"] for r in runs])),
            take_spread_rms=_take_spread(corpus, (person, action)),
            captured=runs[0]["captured"], synthesised=runs[0]["curve"],
            baseline=runs[0]["base"]))
    skipped = sorted(set(skipped))
    if not cells:
        raise MocapError("no cell could be evaluated: leave-one-out needs people with at least "
                         "two actions and at least 3 people who performed every action")
    cell_of = {path: key for key, paths in corpus.sources.items() for path in paths}
    whole = sorted(cell_of[path] + (path,) for path, count in corpus.trial_cycles.items()
                   if count == 0 and path in cell_of)
    return Evaluation(cells, skipped, list(corpus.columns), method, hold_out, whole)
