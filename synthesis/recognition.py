"""Recognition: the most likely person (and action) of a captured cycle, by a weighted
distance to every person's motion as a synthesis method models it
(:meth:`synthesis.model.MotionModel.recognize` calls these with its angle method).

A person's motion of an action is the model's prediction from their *other* actions (their
capture only when they have no other), for every person alike — so the person whose cell
was never captured is not the only one compared through a prediction — and each feature is
weighted by the inverse of its leave-one-person-out prediction variance (a diagonal
Mahalanobis distance, :func:`recognition_weights`). Chosen on the design split
(docs/synthesis.md): bandai2 styles active/elderly/exhausted/feminine, top-1 92 % against
79 % for the plain distance to the captures.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from mocap.errors import MocapError
from synthesis.methods import CellMethod
from synthesis.signature import posterior_scores

#: Shrinkage of the per-feature recognition variances towards their mean (chosen on the design
#: split, bandai2 styles active/elderly/exhausted/feminine: docs/synthesis.md).
RECOGNITION_SHRINKAGE = 0.1


@dataclass
class Recognition:
    """Result of :func:`recognize`.

    Attributes
    ----------
    person, action : str
        Most likely person and action.
    scores : dict of str to float
        Person → score in [0, 1] (summing to 1) for the recognised action: softmax of
        ``−½ (d / σ)²`` with ``d`` the RMS distance (degrees) between the trial and the model's
        motion of that person, ``σ`` the model's leave-one-out synthesis RMS.
    distances : dict of str to float
        Person → RMS distance, degrees, for the recognised action.
    action_scores : dict of str to float
        Action → score (same softmax over each action's nearest person).
    """

    person: str
    action: str
    scores: dict
    distances: dict
    action_scores: dict

    def to_json(self) -> dict:
        """``{"person", "action", "scores", "distances_deg", "action_scores"}``."""
        return {"person": self.person, "action": self.action, "scores": self.scores,
                "distances_deg": self.distances, "action_scores": self.action_scores}


def recognition_weights(method: CellMethod, action: int) -> np.ndarray | None:
    """Per-feature weights of recognition distances for one action: the inverse of each
    feature's leave-one-person-out prediction variance ``σ_f²``, shrunk by
    :data:`RECOGNITION_SHRINKAGE` of the mean variance, ``1 / (σ_f² + c · mean σ²)``; None
    when too few people give a variance.

    Returns
    -------
    ndarray, shape (features,), or None
    """
    variance = method.feature_variance(action)
    if variance is None or not variance.mean() > 0:
        return None
    return 1.0 / (variance + RECOGNITION_SHRINKAGE * variance.mean())


def distances(method: CellMethod, curve: np.ndarray,
              actions: Sequence[int] | None = None) -> np.ndarray:
    """Weighted RMS distance between a cycle and every person's motion of every action
    (module notes).

    Parameters
    ----------
    method : CellMethod
        A fitted synthesis method of the angle cells.
    curve : ndarray, shape (samples, columns), degrees
        A cycle normalised like the corpus.
    actions : sequence of int, optional
        Action indices to compare with (default: all); the other columns are NaN.

    Returns
    -------
    ndarray, shape (people, actions), degrees
        NaN for people without a motion of that action.
    """
    flat = np.asarray(curve, dtype=float).ravel()
    people, count = method.data_.shape[:2]
    table = np.full((people, count), np.nan)
    for action in range(count) if actions is None else actions:
        weights = recognition_weights(method, action)
        for person in range(people):
            try:
                motion = method.template(person, action)
            except MocapError:
                continue
            squared = (motion - flat) ** 2
            if weights is not None:
                squared = squared * weights / weights.mean()
            table[person, action] = np.sqrt(squared.mean())
    return table


def recognize(method: CellMethod, people: Sequence[str], actions: Sequence[str],
              curve: np.ndarray, candidates: Sequence[int], scale: float) -> Recognition:
    """Most likely person and action of a captured cycle.

    Parameters
    ----------
    method : CellMethod
        A fitted synthesis method of the angle cells.
    people, actions : sequence of str
        Names of the method's people and actions.
    curve : ndarray, shape (samples, columns), degrees
    candidates : sequence of int
        Actions the trial may be (one when it is known).
    scale : float
        Typical synthesis error, degrees, for the scores (:func:`posterior_scores`).

    Returns
    -------
    Recognition
    """
    table = distances(method, curve, candidates)
    nearest = np.full(len(actions), np.inf)
    for a in candidates:
        if np.isfinite(table[:, a]).any():
            nearest[a] = np.nanmin(table[:, a])
    best_action = min(candidates, key=lambda a: nearest[a])
    column = table[:, best_action]
    valid = np.isfinite(column)
    names = [people[i] for i in np.flatnonzero(valid)]
    scores = posterior_scores(column[valid], scale)
    action_scores = posterior_scores(nearest[list(candidates)], scale)
    return Recognition(
        person=names[int(np.argmin(column[valid]))], action=actions[best_action],
        scores={name: float(s) for name, s in zip(names, scores)},
        distances={name: float(d) for name, d in zip(names, column[valid])},
        action_scores={actions[a]: float(s) for a, s in zip(candidates, action_scores)})
