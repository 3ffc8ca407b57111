"""``TransferModel``: a person's missing action from their other actions, through the action mode.

Data: people × actions × features, NaN where a cell is missing. Write ``m_a`` for the mean of
action ``a`` over the other people and ``r_{p,a} = d_{p,a} − m_a`` for person ``p``'s offset on
it. Two classical predictors of a missing cell ``(p, b)`` are

* the *baseline* ``m_b`` (mean of the other people), and
* the *additive* model ``m_b + mean_a r_{p,a}`` (the person's mean offset over their actions).

The additive model treats every action as equally informative about every other. The
transfer model learns how much each of the person's actions says about the missing one — the
action mode of the people × actions × features tensor, i.e. the person × action interaction
— by ridge regression across the other people:

    d̂_{p,b} = m_b + Σ_{a∈O} W_{b,a} r_{p,a}

with the weights ``W_b`` (one per observed action, shared by all features) fitted on every
other person ``q`` who has ``b`` and all of ``O`` (their offsets from the means *without*
``q``, exactly as the held-out person's are formed), shrunk towards the additive weights
``1/|O|`` with strength ``λ = α · trace(G)/|O|``. ``α`` is chosen by leave-one-person-out
among :data:`ALPHAS` (``inf`` = the additive model itself), so the model contains the additive
model and only departs from it where other people show that it predicts better.
The leave-one-person-out residuals also give each feature's prediction variance per target
action (used to weight recognition distances).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mocap.errors import MocapError
from synthesis.candidates import regression_weights

#: Relative ridge strengths tried by leave-one-person-out (inf = additive model).
ALPHAS = (0.0, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0, float("inf"))


@dataclass
class Transfer:
    """Weights for one (target action, observed actions) pair (``variance``: each feature's
    leave-one-person-out mean squared error, over the donors' held-out ``residuals``
    (donors, features): capture − held-out prediction)."""

    weights: np.ndarray
    alpha: float
    loo_rms: float
    variance: np.ndarray
    residuals: np.ndarray | None = field(default=None, repr=False)


@dataclass
class TransferModel:
    """Action-transfer predictor of missing cells (see module notes).

    Attributes
    ----------
    data_ : ndarray, shape (people, actions, features)
    observed_ : ndarray, shape (people, actions), bool
    """

    data_: np.ndarray | None = field(default=None, repr=False)
    observed_: np.ndarray | None = field(default=None, repr=False)
    _cache: dict = field(default_factory=dict, repr=False)

    def fit(self, data: np.ndarray) -> "TransferModel":
        """Remember the data; weights are learned per (target, observed set) on demand."""
        data = np.asarray(data, dtype=float)
        if data.ndim != 3:
            raise MocapError("transfer data must be people × actions × features")
        self.data_ = data
        self.observed_ = np.isfinite(data).all(axis=2)
        self._cache = {}
        return self

    def _means_without(self, person: int) -> np.ndarray:
        """Action means over the people other than ``person`` who have each action (NaN for an
        action nobody else has)."""
        keep = self.observed_.copy()
        keep[person] = False
        counts = keep.sum(axis=0)
        total = np.where(keep[..., None], self.data_, 0.0).sum(axis=0)
        return total / np.where(counts > 0, counts, np.nan)[:, None]

    def loo_rms(self) -> float:
        """RMS leave-one-person-out error of every action predicted from all the others."""
        actions = self.data_.shape[1]
        errors = [self.transfer(b, tuple(a for a in range(actions) if a != b)).loo_rms
                  for b in range(actions)]
        errors = [e for e in errors if np.isfinite(e)]
        return float(np.sqrt(np.mean(np.square(errors)))) if errors else float("nan")

    def transfer(self, target: int, observed: tuple[int, ...], exclude: int | None = None
                 ) -> Transfer:
        """Weights predicting action ``target`` from actions ``observed`` (``exclude`` is the
        person being predicted, left out of the training pairs)."""
        key = (target, observed, exclude)
        if key in self._cache:
            return self._cache[key]
        donors = self.donor_people(target, observed, exclude)
        features = self.data_.shape[2]
        if len(donors) < 3:
            uniform = np.full(len(observed), 1.0 / len(observed))
            result = Transfer(uniform, float("inf"), float("nan"), np.full(features, np.nan))
            self._cache[key] = result
            return result
        inputs, outputs = [], []
        for q in donors:
            means = self._leave_two_means(q, exclude)
            inputs.append(np.stack([self.data_[q, a] - means[a] for a in observed], axis=1))
            outputs.append(self.data_[q, target] - means[target])
        inputs, outputs = np.stack(inputs), np.stack(outputs)      # (Q, F, O), (Q, F)
        grams = np.einsum("qfa,qfb->qab", inputs, inputs)
        crosses = np.einsum("qfa,qf->qa", inputs, outputs)
        best = None
        for alpha in ALPHAS:
            residuals = []
            for k in range(len(donors)):
                others = np.arange(len(donors)) != k
                weights = regression_weights(grams[others].sum(0), crosses[others].sum(0), alpha)
                residuals.append(outputs[k] - inputs[k] @ weights)
            residuals = np.stack(residuals)
            error = float(np.mean(residuals ** 2))
            if best is None or error < best[0] - 1e-12:
                best = (error, alpha, residuals)
        error, alpha, residuals = best
        weights = regression_weights(grams.sum(0), crosses.sum(0), alpha)
        result = Transfer(weights, alpha, float(np.sqrt(error)), np.mean(residuals ** 2, axis=0),
                          residuals)
        self._cache[key] = result
        return result

    def donor_people(self, target: int, observed: tuple[int, ...], exclude: int | None = None
                     ) -> list[int]:
        """Indices of the people other than ``exclude`` who have ``target`` and every
        ``observed`` action: the donors, in the order of :attr:`Transfer.residuals`."""
        return [q for q in range(self.data_.shape[0]) if q != exclude
                and self.observed_[q, target] and self.observed_[q, list(observed)].all()]

    def _leave_two_means(self, person: int, exclude: int) -> np.ndarray:
        keep = self.observed_.copy()
        keep[person] = False
        if exclude is not None:
            keep[exclude] = False
        counts = keep.sum(axis=0)
        total = np.where(keep[..., None], self.data_, 0.0).sum(axis=0)
        return total / np.maximum(counts, 1)[:, None]

    def predict(self, person: int, target: int) -> tuple[np.ndarray, Transfer | None]:
        """Prediction of cell ``(person, target)`` from the person's other observed actions.

        Returns
        -------
        prediction : ndarray, shape (features,)
        transfer : Transfer or None
            The weights used (None when the person has no other action: the baseline).
        """
        means = self._means_without(person)
        observed = tuple(int(a) for a in np.flatnonzero(self.observed_[person])
                         if a != target and np.isfinite(means[a]).all())
        if not np.isfinite(means[target]).all():
            raise MocapError("nobody else performed this action")
        if not observed:
            return means[target], None
        transfer = self.transfer(target, observed, person)
        offsets = np.stack([self.data_[person, a] - means[a] for a in observed], axis=1)
        return means[target] + offsets @ transfer.weights, transfer

    def additive(self, person: int, target: int) -> np.ndarray:
        """The additive prediction ``m_b + mean_a r_{p,a}`` (shape (features,))."""
        means, _, offsets = self.offsets(person, target)
        if not len(offsets):
            return means[target]
        return means[target] + np.mean(offsets, axis=0)

    def offsets(self, person: int, target: int) -> tuple[np.ndarray, list[int], np.ndarray]:
        """The means without the person, their other actions, and their offsets ``r_{p,a}``
        from the means in those: the additive prediction's parts (recognition's
        single-action views, :meth:`CellMethod.additive_views`)."""
        means = self._means_without(person)
        observed = [int(a) for a in np.flatnonzero(self.observed_[person]) if a != target]
        return means, observed, self.data_[person, observed] - means[observed]
