"""Imputation of the missing cells of a people × actions × features tensor, and the
held-out comparison of a model with the additive one.

* :func:`impute_cells`: alternating N-mode SVD and signature regression from each person's
  observed cells, with a people rank below the number of people chosen by cross-validation
  (at full rank an imputed guess reproduces itself). The cross-validation also scores the
  additive model on the same hidden cells (:func:`held_out_by_action`), so a caller can tell
  whether the imputation earned its place per action.
* :func:`additive_errors`: the additive model (action mean + the person's mean offset, means
  without the person) on any held-out cells.
* :func:`can_impute`, :func:`can_fit`: whether a tensor's cells allow it.
"""
from __future__ import annotations

import numpy as np

from mocap.errors import MocapError
from synthesis.interaction import InteractionModel
from synthesis.nmode import Rank, nmode_svd
from synthesis.signature import (action_bases, fit_signature, solve_signature,
                                 synthesize_features)


def rank_grid(largest: int) -> list[int]:
    """Signature ranks tried by leave-one-out: every count up to 12, then steps of ~25 %.

    Examples
    --------
    >>> rank_grid(5)
    [1, 2, 3, 4, 5]
    >>> rank_grid(30)
    [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 15, 19, 24, 30]
    """
    ranks = list(range(1, min(largest, 12) + 1))
    while ranks[-1] < largest:
        ranks.append(min(largest, int(np.ceil(ranks[-1] * 1.25))))
    return ranks


def _two_way_fill(data: np.ndarray, observed: np.ndarray) -> np.ndarray:
    """Missing cells ← action mean + the person's mean offset from the action means."""
    counts = observed.sum(axis=0)[:, None]                               # (A, 1)
    zeroed = np.where(observed[..., None], data, 0.0)
    action_mean = zeroed.sum(axis=0) / np.maximum(counts, 1)             # (A, F)
    offsets = np.where(observed[..., None], data - action_mean, 0.0)
    person_offset = offsets.sum(axis=1) / np.maximum(observed.sum(axis=1), 1)[:, None]
    guess = action_mean[None] + person_offset[:, None]
    return np.where(observed[..., None], data, guess)


#: Relative ridge of the signature fits inside the imputation (keeps them well posed).
IMPUTATION_RIDGE = 1e-3


def _impute_with_rank(data: np.ndarray, observed: np.ndarray, rank: int, action_rank: Rank,
                      feature_rank: Rank, iterations: int = 300, tolerance: float = 1e-5
                      ) -> np.ndarray:
    """Alternating imputation: N-mode SVD bases of the filled tensor (people rank ``rank``),
    then every missing cell re-predicted from its person's *observed* cells only."""
    filled = _two_way_fill(data, observed)
    incomplete = np.flatnonzero(~observed.all(axis=1))
    if action_rank is None and feature_rank is None:
        return _impute_full_modes(data, observed, filled, incomplete, rank, iterations,
                                  tolerance)
    for _ in range(iterations):
        mean = filled.mean(axis=0)
        decomposition = nmode_svd(filled - mean, [rank, action_rank, feature_rank])
        bases = action_bases(decomposition.core, decomposition.factors[1])
        feature_factor = decomposition.factors[2]
        sigma = decomposition.singular_values[0]
        ridge = IMPUTATION_RIDGE * float(np.mean(sigma ** 2)) / data.shape[1]
        change = 0.0
        for person in incomplete:
            have = np.flatnonzero(observed[person])
            lack = np.flatnonzero(~observed[person])
            signature = fit_signature(bases, feature_factor, data[person, have] - mean[have],
                                      have, ridge)
            predicted = np.stack([synthesize_features(bases, feature_factor, mean, signature, a)
                                  for a in lack])
            change = max(change, float(np.max(np.abs(predicted - filled[person, lack]))))
            filled[person, lack] = predicted
        if change <= tolerance * max(float(np.max(np.abs(filled))), 1e-300):
            break
    return filled


def _impute_full_modes(data: np.ndarray, observed: np.ndarray, filled: np.ndarray,
                       incomplete: np.ndarray, rank: int, iterations: int, tolerance: float
                       ) -> np.ndarray:
    """:func:`_impute_with_rank` when the action and feature modes keep their full rank.

    Then the action basis is ``B_a = Pᵀ (D_a − m_a)`` (people × features, ``P`` the leading
    ``rank`` people singular vectors; notes §1.3d), so every quantity of a signature fit lives
    in the small people space: ``B_a B_aᵀ = Pᵀ C_a P`` with ``C_a`` the people × people Gram
    of action ``a``'s deviations. Same result as the general loop, without its per-iteration
    decompositions of the long modes.
    """
    for _ in range(iterations):
        mean = filled.mean(axis=0)                                           # (A, F)
        deviations = filled - mean                                           # (K, A, F)
        cross = np.einsum("paf,qaf->apq", deviations, deviations)            # (A, K, K)
        values, vectors = np.linalg.eigh(cross.sum(axis=0))
        people_factor = vectors[:, ::-1][:, :rank]                           # (K, r)
        ridge = IMPUTATION_RIDGE * float(np.mean(np.clip(values[::-1][:rank], 0, None))) \
            / data.shape[1]
        change = 0.0
        for person in incomplete:
            have = np.flatnonzero(observed[person])
            lack = np.flatnonzero(~observed[person])
            residuals = data[person, have] - mean[have]                      # (h, F)
            gram = people_factor.T @ cross[have].sum(axis=0) @ people_factor
            side = people_factor.T @ np.einsum("paf,af->p", deviations[:, have], residuals)
            signature = solve_signature(gram, side, ridge)
            weights = people_factor @ signature                              # (K,)
            predicted = mean[lack] + np.einsum("paf,p->af", deviations[:, lack], weights)
            change = max(change, float(np.max(np.abs(predicted - filled[person, lack]))))
            filled[person, lack] = predicted
        if change <= tolerance * max(float(np.max(np.abs(filled))), 1e-300):
            break
    return filled


TOO_FEW_CELLS = ("need at least 2 people who performed every action to build the action bases "
                 "(or, to impute missing cells, at least 3 people and every action performed by "
                 "at least 2 of them)")


def additive_errors(data: np.ndarray, observed: np.ndarray, cells) -> np.ndarray:
    """Squared errors (summed over features) of the additive model, action mean + the
    person's mean offset, predicting each of ``cells`` from the person's other observed
    cells, the means taken without the person.

    Parameters
    ----------
    data : ndarray, shape (people, actions, features)
    observed : ndarray of bool, shape (people, actions)
        The cells the model may use (the predicted cell's own value never enters).
    cells : sequence of (person, action)

    Returns
    -------
    ndarray, shape (len(cells),); NaN where the person has no other cell or the action no
    other person
    """
    data = np.asarray(data, dtype=float)
    # The additive model's one home: the interaction model at rank 0, on the usable cells.
    model = InteractionModel(max_rank=0).fit(np.where(observed[..., None], data, np.nan))
    counts = observed.sum(axis=0)
    result = np.full(len(cells), np.nan)
    for i, (p, a) in enumerate(cells):
        others = counts - observed[p]                                   # (actions,)
        if others[a] == 0 or not any(b != a and others[b] > 0
                                     for b in np.flatnonzero(observed[p])):
            continue
        result[i] = float(np.sum((model.additive(p, a) - data[p, a]) ** 2))
    return result


def held_out_by_action(actions: np.ndarray, own: np.ndarray, additive: np.ndarray,
                       count: int, robust: bool = False) -> np.ndarray:
    """Per action, a model's held-out RMS error, the additive model's on the same cells, and
    the fraction of those cells the model predicts better.

    Parameters
    ----------
    actions : ndarray of int, shape (cells,)
        Action of each held-out cell.
    own, additive : ndarray, shape (cells,)
        Squared errors of the model and of the additive model (same units).
    count : int
        Number of actions.
    robust : bool
        Root of the median squared error instead of the mean (a cross-validation whose
        alternating fit goes astray in one fold must not decide).

    Returns
    -------
    ndarray, shape (4, count)
        Rows: RMS (or root median square) of ``own``, the same of ``additive``, fraction
        won, number of cells; NaN for an action with no held-out cell (nothing says the
        model is better there).
    """
    average = np.median if robust else np.mean
    result = np.full((4, count), np.nan)
    for action in range(count):
        chosen = (np.asarray(actions) == action) & np.isfinite(additive)
        if chosen.any():
            result[:, action] = (np.sqrt(average(own[chosen])),
                                 np.sqrt(average(additive[chosen])),
                                 np.mean(own[chosen] < additive[chosen]), chosen.sum())
    return result


def can_impute(observed: np.ndarray) -> bool:
    """True when :func:`impute_cells` can fill the missing cells of ``observed``.

    Parameters
    ----------
    observed : ndarray of bool, shape (people, actions)
    """
    observed = np.asarray(observed, dtype=bool)
    return bool(observed.shape[0] >= 3 and np.all(observed.sum(axis=0) >= 2)
                and np.all(observed.sum(axis=1) >= 1))


def can_fit(observed: np.ndarray) -> bool:
    """True when :meth:`MotionModel.fit` can fit a tensor with these cells: two complete
    people, or missing cells :func:`impute_cells` can fill.

    Parameters
    ----------
    observed : ndarray of bool, shape (people, actions)
    """
    observed = np.asarray(observed, dtype=bool)
    return bool(observed.all(axis=1).sum() >= 2 or can_impute(observed))


def impute_cells(data: np.ndarray, action_rank: Rank = None, feature_rank: Rank = None,
                 people_rank: Rank = None, folds: int = 4
                 ) -> tuple[np.ndarray, int, np.ndarray]:
    """Fill the missing cells of a tensor in which fewer than two people are complete.

    With full people rank a filled-in guess reproduces itself (every value of a missing cell
    fits), so the people rank is truncated: chosen by ``folds``-fold cross-validation over
    the observed cells (each fold hides some observed cells, imputes them with every candidate
    rank, and scores the prediction), unless ``people_rank`` is a count.

    Parameters
    ----------
    data : ndarray, shape (people, actions, features), NaN rows for missing cells

    Returns
    -------
    filled : ndarray, same shape, no NaN
    rank : int
        People rank used.
    held_out : ndarray, shape (4, actions)
        Per action, the cross-validation's root median squared error (feature units) of
        the imputation at that rank and of the additive model on the same hidden cells, and
        the fraction of them the imputation predicts better, and their number
        (:func:`held_out_by_action`);
        NaN for an action none of whose cells was hidden, and everywhere when the rank was
        given.

    Raises
    ------
    MocapError
        When an action has fewer than two people or a person no action at all.
    """
    observed = np.isfinite(data).all(axis=2)
    people, actions = observed.shape
    if not can_impute(observed):
        raise MocapError(TOO_FEW_CELLS)
    largest = people - 2               # below the centred people rank (people − 1): no echo
    if isinstance(people_rank, (int, np.integer)) and not isinstance(people_rank, bool):
        rank = int(min(people_rank, largest))
        return (_impute_with_rank(data, observed, rank, action_rank, feature_rank), rank,
                np.full((4, actions), np.nan))
    candidates = rank_grid(largest)
    cells = [(p, a) for p, a in np.argwhere(observed)
             if observed[p].sum() >= 3 and observed[:, a].sum() >= 4]
    order = np.random.default_rng(0).permutation(len(cells))
    errors = np.full((folds, len(candidates)), np.nan)
    features = data.shape[2]
    cell_errors: list = []              # per fold: actions, (cells, candidates), (cells,)
    for fold in range(folds):
        hidden = [cells[i] for i in order[fold::folds]]
        if not hidden:
            continue
        mask = observed.copy()
        for p, a in hidden:          # every person keeps two cells, every action three
            if mask[p].sum() >= 3 and mask[:, a].sum() >= 4:
                mask[p, a] = False
        held = [(p, a) for p, a in hidden if not mask[p, a]]
        masked = np.where(mask[..., None], data, np.nan)
        if not held:
            continue
        baseline = additive_errors(data, mask, held) / features
        squares = np.empty((len(held), len(candidates)))
        for i, rank in enumerate(candidates):
            filled = _impute_with_rank(masked, mask, rank, action_rank, feature_rank,
                                       iterations=100)
            squares[:, i] = [np.mean((filled[p, a] - data[p, a]) ** 2) for p, a in held]
            errors[fold, i] = np.sqrt(squares[:, i].mean())
        cell_errors.append(([a for _, a in held], squares, baseline))
    # Median over folds: one fold in which the alternating fit goes astray must not decide.
    scores = np.nanmedian(errors, axis=0) if np.isfinite(errors).any() \
        else np.zeros(len(candidates))
    best = int(np.argmin(scores))
    held_out = np.full((4, actions), np.nan)
    if cell_errors:
        held_out = held_out_by_action(
            np.concatenate([hidden for hidden, _, _ in cell_errors]),
            np.concatenate([squares[:, best] for _, squares, _ in cell_errors]),
            np.concatenate([baseline for _, _, baseline in cell_errors]), actions, robust=True)
    rank = candidates[best]
    return _impute_with_rank(data, observed, rank, action_rank, feature_rank), rank, held_out
