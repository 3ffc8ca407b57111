"""Leave-one-cell-out evaluation of motion synthesis and person recognition.

Each captured (person, action) cell is held out in turn: a model is fitted to the corpus
without that cell (so the person is incomplete and takes no part in the bases), the cell is
synthesised from the person's other actions, and compared with the capture:

* **synthesis error**: RMS joint-angle difference over the normalised cycle, degrees;
* **baseline**: the mean of the other people's captures of that action;
* **recognition**: the person whose model motion of that action is nearest to the held-out
  capture (the held-out person's entry is their prediction, everyone else's their capture).

Cells whose person has no other action are skipped (nothing to predict from).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Iterable

import numpy as np

from mocap.errors import MocapError
from synthesis.corpus import MotionCorpus
from synthesis.model import MotionModel


@dataclass
class CellResult:
    """Leave-one-out result of one (person, action) cell.

    Attributes
    ----------
    person, action : str
    synthesis_rms, baseline_rms : float
        Degrees.
    duration, predicted_duration : float
        Captured and predicted cycle duration, seconds.
    recognised : str
        Person recognised from the held-out capture (action given).
    captured, synthesised, baseline : ndarray, shape (samples, columns), degrees
    """

    person: str
    action: str
    synthesis_rms: float
    baseline_rms: float
    duration: float
    predicted_duration: float
    recognised: str
    captured: np.ndarray = field(repr=False)
    synthesised: np.ndarray = field(repr=False)
    baseline: np.ndarray = field(repr=False)


@dataclass
class Evaluation:
    """All cells of a leave-one-out evaluation.

    Attributes
    ----------
    cells : list of CellResult
    skipped : list of (person, action, reason)
    columns : list of str
        Angle column names.
    """

    cells: list
    skipped: list
    columns: list

    @property
    def synthesis_rms(self) -> float:
        """Overall RMS synthesis error over all evaluated cells, degrees."""
        return float(np.sqrt(np.mean([c.synthesis_rms ** 2 for c in self.cells])))

    @property
    def baseline_rms(self) -> float:
        """Overall RMS error of the baseline (mean of the other people), degrees."""
        return float(np.sqrt(np.mean([c.baseline_rms ** 2 for c in self.cells])))

    @property
    def recognition_accuracy(self) -> float:
        """Fraction of held-out cells whose person was recognised."""
        return float(np.mean([c.recognised == c.person for c in self.cells]))

    @property
    def duration_rms(self) -> float:
        """RMS error of the predicted cycle durations, seconds."""
        return float(np.sqrt(np.mean([(c.predicted_duration - c.duration) ** 2
                                      for c in self.cells])))

    def to_json(self) -> dict:
        """Plain dict: per-cell figures and the overall ones."""
        return {
            "cells": [{"person": c.person, "action": c.action,
                       "synthesis_rms_deg": c.synthesis_rms, "baseline_rms_deg": c.baseline_rms,
                       "duration_s": c.duration, "predicted_duration_s": c.predicted_duration,
                       "recognised": c.recognised} for c in self.cells],
            "skipped": [{"person": p, "action": a, "reason": r} for p, a, r in self.skipped],
            "synthesis_rms_deg": self.synthesis_rms, "baseline_rms_deg": self.baseline_rms,
            "improvement": self.baseline_rms / self.synthesis_rms if self.synthesis_rms > 0
            else float("inf"),
            "recognition_accuracy": self.recognition_accuracy,
            "duration_rms_s": self.duration_rms,
        }

    def table(self) -> str:
        """Human-readable table: one line per cell, then the overall figures."""
        width = max([len(c.person) for c in self.cells] + [6])
        awidth = max([len(c.action) for c in self.cells] + [6])
        lines = [f"{'person':<{width}}  {'action':<{awidth}}  {'synth °':>8}  {'baseline °':>10}"
                 f"  {'dur s':>6}  {'pred s':>6}  recognised"]
        for c in self.cells:
            mark = "" if c.recognised == c.person else "  ✗"
            lines.append(f"{c.person:<{width}}  {c.action:<{awidth}}  {c.synthesis_rms:8.2f}  "
                         f"{c.baseline_rms:10.2f}  {c.duration:6.3f}  {c.predicted_duration:6.3f}"
                         f"  {c.recognised}{mark}")
        for person, action, reason in self.skipped:
            lines.append(f"{person:<{width}}  {action:<{awidth}}  skipped: {reason}")
        ratio = self.baseline_rms / self.synthesis_rms if self.synthesis_rms > 0 else float("inf")
        times = f"{ratio:.1f}×" if ratio < 1000 else "over 1000×"
        lines += [
            "",
            f"overall RMS joint-angle error: synthesis {self.synthesis_rms:.2f}°, baseline "
            f"(mean of the other people) {self.baseline_rms:.2f}° ({times} lower)",
            f"cycle duration RMS error: {self.duration_rms * 1000:.0f} ms",
            f"person recognition: {sum(c.recognised == c.person for c in self.cells)}/"
            f"{len(self.cells)} = {100 * self.recognition_accuracy:.0f} %",
        ]
        return "\n".join(lines)


def leave_one_out(corpus: MotionCorpus, progress: Callable[[Iterable, str], Iterable] | None = None,
                  **model_options) -> Evaluation:
    """Hold out every captured cell in turn, synthesise it, compare with the capture.

    Parameters
    ----------
    corpus : MotionCorpus
    progress : callable, optional
        ``progress(iterable, description)`` wrapper.
    **model_options
        Passed to :class:`MotionModel` (ranks, ridge, timing weight).

    Returns
    -------
    Evaluation
    """
    observed = corpus.observed
    wrap = progress or (lambda items, description: items)
    cells, skipped = [], []
    pairs = [(p, a) for p, a in np.argwhere(observed)]
    # Bases of sets of complete people never include the held-out person, whose cells are the
    # only ones that change between folds: they are shared across all held-out cells.
    cache: dict = {}
    for p, a in wrap(pairs, "leave-one-out"):
        person, action = corpus.people[p], corpus.actions[a]
        if observed[p].sum() < 2:
            skipped.append((person, action, "the person has no other action"))
            continue
        others = np.flatnonzero(observed[:, a] & (np.arange(len(corpus.people)) != p))
        if others.size == 0:
            skipped.append((person, action, "nobody else performed this action"))
            continue
        reduced = corpus.without_cell(person, action)
        try:
            model = MotionModel(**model_options).fit(reduced, cache)
        except MocapError as error:
            skipped.append((person, action, error.problem))
            continue
        curve, duration = model.synthesize(person, action)
        captured = corpus.angles[p, a]
        baseline = corpus.angles[others, a].mean(axis=0)
        recognition = model.recognize(captured, action)
        cells.append(CellResult(
            person=person, action=action,
            synthesis_rms=float(np.sqrt(np.mean((curve - captured) ** 2))),
            baseline_rms=float(np.sqrt(np.mean((baseline - captured) ** 2))),
            duration=float(corpus.durations[p, a]), predicted_duration=duration,
            recognised=recognition.person, captured=captured, synthesised=curve,
            baseline=baseline))
    if not cells:
        raise MocapError("no cell could be evaluated: leave-one-out needs people with at least "
                         "two actions and at least 3 people who performed every action")
    return Evaluation(cells, skipped, list(corpus.columns))
