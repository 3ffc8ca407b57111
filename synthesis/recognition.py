"""Recognition: the most likely person (and action) of a captured cycle, by a weighted
distance to every person's motion as a synthesis method models it
(:meth:`synthesis.model.MotionModel.recognize` calls these with its angle method).

A person's motion of an action is modelled from their *other* actions (their capture only
when they have no other), for every person alike — so the person whose cell was never
captured is not the only one compared through a model (:meth:`CellMethod.template`). Each
feature's difference is scaled by the inverse of its leave-one-person-out prediction spread
(:func:`recognition_weights`) and the distance is the **mean absolute** scaled difference
(a Laplace rather than a Gaussian likelihood, :func:`distances`): a prediction from other
actions misses a few joints by far more than the rest, and a squared distance lets those few
decide. Chosen on the design split (docs/synthesis.md): bandai2 styles active / elderly /
exhausted / feminine, top-1 92 % against 79 % for the plain distance to the captures (the
weights), then 100 % against 92 % (three takes) and 75 % against 58–67 % on walk + run + wave
(mean absolute against RMS); a person's main effects rather than the interaction's
prediction as the template of a captured cell where they have one other action (the
prediction shrinks toward the action mean there): pairs of actions 61 → 89 % on average.
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
#: Mean absolute value of a normal error per unit of its RMS, √(2/π).
MEAN_ABSOLUTE_PER_RMS = float(np.sqrt(2.0 / np.pi))


@dataclass
class Recognition:
    """Result of :func:`recognize`.

    Attributes
    ----------
    person, action : str
        Most likely person and action.
    scores : dict of str to float
        Person → score in [0, 1] (summing to 1) for the recognised action: softmax of
        ``−½ (d / σ)²`` with ``d`` the distance (:func:`distances`, degrees) between the
        trial and the model's motion of that person, ``σ`` the mean absolute difference
        that the model's leave-one-out synthesis RMS gives for normal errors (× √(2/π)).
    distances : dict of str to float
        Person → weighted mean absolute difference, degrees, for the recognised action.
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
    """Weighted mean absolute difference between a cycle and every person's motion of every
    action (module notes): ``mean_f |x_f − t_f| √(w_f / mean w)``, with ``w`` the
    :func:`recognition_weights` (unweighted when they are None).

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
            difference = np.abs(motion - flat)
            if weights is not None:
                difference = difference * np.sqrt(weights / weights.mean())
            table[person, action] = difference.mean()
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
        Typical synthesis error (RMS), degrees, for the scores (:func:`posterior_scores`,
        which get the mean absolute difference it gives for normal errors, × √(2/π)).

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
    # The distances are mean absolute differences: compare them with the mean absolute
    # difference of normal errors of RMS ``scale``.
    scale = scale * MEAN_ABSOLUTE_PER_RMS
    scores = posterior_scores(column[valid], scale)
    action_scores = posterior_scores(nearest[list(candidates)], scale)
    return Recognition(
        person=names[int(np.argmin(column[valid]))], action=actions[best_action],
        scores={name: float(s) for name, s in zip(names, scores)},
        distances={name: float(d) for name, d in zip(names, column[valid])},
        action_scores={actions[a]: float(s) for a, s in zip(candidates, action_scores)})
