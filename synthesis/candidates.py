"""Every candidate configuration's prediction of a person's offset, for the interaction model.

:class:`synthesis.interaction.InteractionModel` scores these on the same leave-one-donor-out
folds: the action mode (the person basis, :func:`action_weight_grid`) and the people mode (the
signature, :func:`people_candidates`), every rank and every ridge of :data:`ALPHAS` at once,
and the ridge map across actions (:func:`regression_candidates`, the weights of
:class:`synthesis.transfer.TransferModel`). Rank 0 of either mode, and the map at an infinite
ridge, are the additive model.
"""
from __future__ import annotations

import numpy as np

#: Ridge strengths tried by leave-one-donor-out (``λ = α · unit``; see each mode).
ALPHAS = (0.0, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0)
#: Largest people rank tried (every leave-one-out fold must reach it).
MAX_PEOPLE_RANK = 12


def regression_weights(gram: np.ndarray, cross: np.ndarray, alpha: float) -> np.ndarray:
    """Weights of the observed offsets in the ridge map ``Σ_a w_a x_a``, shrunk toward the
    additive weights ``1/m``.

    Solves ``(G + λ I) w = c + λ 1/m`` with ``λ = α · trace(G)/m`` (dimensionless ``α``;
    ``inf`` gives ``1/m``, the additive model).

    Parameters
    ----------
    gram : ndarray, shape (m, m)
        ``Σ_q X_qᵀ X_q`` over the training people, ``X_q`` (features, m) their observed offsets.
    cross : ndarray, shape (m,)
        ``Σ_q X_qᵀ y_q``, ``y_q`` their target offset.
    alpha : float

    Returns
    -------
    ndarray, shape (m,)

    Examples
    --------
    >>> import numpy as np
    >>> regression_weights(np.array([[4.0]]), np.array([2.0]), 0.0).round(9).tolist()
    [0.5]
    >>> regression_weights(np.array([[4.0]]), np.array([2.0]), float("inf")).tolist()
    [1.0]
    """
    count = gram.shape[0]
    uniform = np.full(count, 1.0 / count)
    if not np.isfinite(alpha):
        return uniform
    strength = alpha * np.trace(gram) / count + 1e-12 * max(np.trace(gram), 1.0)
    return np.linalg.solve(gram + strength * np.eye(count), cross + strength * uniform)


def regression_candidates(training: np.ndarray, x: np.ndarray) -> tuple[list, np.ndarray]:
    """Ridge-map predictions of people's target offset, for every ridge of :data:`ALPHAS`.

    The map is the action transfer's (:class:`synthesis.transfer.TransferModel`): one weight
    per observed action, shared by every feature, fitted by least squares on the training
    donors' offsets and shrunk toward the additive weights ``1/m``
    (:func:`regression_weights`). Unlike the action mode it needs no second observed action:
    with one, it is the donors' regression of the target offset on the observed one — how
    much of a person's offset in a walk carries into their wave.

    Parameters
    ----------
    training : ndarray, shape (Q, m + 1, F)
        Offsets of the training donors (observed actions, then the target).
    x : ndarray, shape (n, m, F)
        Offsets of n predicted people.

    Returns
    -------
    labels : list of ("regression", m, alpha)
    predictions : ndarray, shape (n, len(ALPHAS), F)
    """
    weights = map_weights(training, ALPHAS)
    return [("regression", x.shape[1], alpha) for alpha in ALPHAS], \
        np.einsum("km,nmf->nkf", weights, x)


def map_weights(training: np.ndarray, alphas) -> np.ndarray:
    """The ridge map's weights fitted to the training donors, one row per ridge.

    Parameters
    ----------
    training : ndarray, shape (Q, m + 1, F)
        Offsets of the training donors (observed actions, then the target).
    alphas : sequence of float

    Returns
    -------
    ndarray, shape (len(alphas), m)
    """
    m = training.shape[1] - 1
    gram = np.einsum("qaf,qbf->ab", training[:, :m], training[:, :m])
    cross = np.einsum("qaf,qf->a", training[:, :m], training[:, m])
    return np.stack([regression_weights(gram, cross, alpha) for alpha in alphas])


def action_weights(vectors: np.ndarray, alpha: float) -> np.ndarray:
    """Weights ``w`` of the observed offsets in the action-mode prediction ``Σ_a w_a x_a``.

    Parameters
    ----------
    vectors : ndarray, shape (..., m + 1, r)
        Action-mode singular vectors; rows 0..m−1 the observed actions, row m the target.
    alpha : float
        Ridge on the person basis ``C`` (dimensionless: ``V`` is orthonormal).

    Returns
    -------
    ndarray, shape (..., m)
        With r = 0, ``1/m`` each (the additive model).

    Examples
    --------
    >>> import numpy as np
    >>> action_weights(np.zeros((3, 0)), 0.0).tolist()
    [0.5, 0.5]
    """
    m = vectors.shape[-2] - 1
    rank = vectors.shape[-1]
    ones = np.ones(vectors.shape[:-2] + (m, 1))
    design = np.concatenate([ones, vectors[..., :m, :]], axis=-1)            # (..., m, 1+r)
    row = np.concatenate([np.ones(vectors.shape[:-2] + (1,)), vectors[..., m, :]], axis=-1)
    penalty = np.diag(np.r_[0.0, np.full(rank, alpha)])
    system = np.einsum("...ki,...kj->...ij", design, design) + penalty      # (..., 1+r, 1+r)
    inverse = np.linalg.pinv(system, rcond=1e-10, hermitian=True)
    return np.einsum("...ki,...ij,...j->...k", design, inverse, row)


def action_weight_grid(vectors: np.ndarray) -> np.ndarray:
    """:func:`action_weights` for every rank 1..m and every ridge of :data:`ALPHAS` at once.

    Parameters
    ----------
    vectors : ndarray, shape (m + 1, m)
        The m leading action-mode singular vectors (rows: observed actions, then the target).

    Returns
    -------
    ndarray, shape (m, len(ALPHAS), m)
        Entry ``[r − 1, i]``: the weights of rank r and ridge ``ALPHAS[i]``.
    """
    m = vectors.shape[1]
    used = np.arange(m)[None, :] < np.arange(1, m + 1)[:, None]              # (R, m)
    columns = np.concatenate([np.ones((m, 1), bool), used], axis=1)           # (R, 1+m)
    design = np.concatenate([np.ones((m, 1)), vectors[:m]], axis=1)[None] * columns[:, None]
    row = np.r_[1.0, vectors[m]][None] * columns                              # (R, 1+m)
    # Unused components get a unit penalty and no column: their coefficient is 0.
    penalty = np.where(columns[:, None], np.asarray(ALPHAS)[None, :, None], 1.0)
    penalty[..., 0] = 0.0                                                     # α is free
    system = np.einsum("rki,rkj->rij", design, design)[:, None] + \
        penalty[..., None] * np.eye(m + 1)                                    # (R, A, 1+m, 1+m)
    inverse = np.linalg.pinv(system, rcond=1e-10, hermitian=True)
    return np.einsum("rki,raij,rj->rak", design, inverse, row)


def people_candidates(centred: np.ndarray, x: np.ndarray, largest: int,
                       free_offset: bool = True) -> tuple[list, np.ndarray]:
    """People-mode (signature) predictions of a person's target offset for every rank and ridge.

    With ``U`` the leading people-mode singular vectors of the interaction ``E`` and
    ``Ẽ_a = E_a − Ē_O`` (bases centred over the observed actions, since the offset α is
    free), the signature solves ``(Uᵀ H U + λ I) s = Uᵀ h`` with ``H = Σ_{a∈O} Ẽ_a Ẽ_aᵀ`` and
    ``h = Σ_{a∈O} Ẽ_a x_a``; the prediction is ``x̄_O + Ẽ_bᵀ U s`` — all in the donors' space.

    Parameters
    ----------
    centred : ndarray, shape (Q, m + 1, F)
        Interaction of the training donors (offsets minus each donor's mean offset).
    x : ndarray, shape (n, m, F)
        Offsets of n predicted people.
    largest : int
        Largest rank tried (capped at :data:`MAX_PEOPLE_RANK`).
    free_offset : bool
        Fit the person's offset α with the signature (else α = 0 and ``centred`` holds the
        donors' offsets themselves).

    Returns
    -------
    labels : list of ("people", rank, alpha)
    predictions : ndarray, shape (n, len(labels), F)
    """
    n, m, features = x.shape
    tilde = centred - centred[:, :m].mean(axis=1, keepdims=True) if free_offset else centred
    start = x.mean(axis=1) if free_offset else np.zeros((n, features))      # (n, F)
    values, vectors = np.linalg.eigh(np.einsum("qaf,raf->qr", centred, centred))
    values, vectors = values[::-1], vectors[:, ::-1]
    system = np.einsum("qaf,raf->qr", tilde[:, :m], tilde[:, :m])
    side = np.einsum("qaf,naf->nq", tilde[:, :m], x)                          # (n, Q)
    labels, blocks = [], [np.zeros((n, 0, features))]
    alphas = np.asarray(ALPHAS)
    for rank in range(1, min(largest, MAX_PEOPLE_RANK, len(values)) + 1):
        u = vectors[:, :rank]
        # Every ridge from one eigen-decomposition of the reduced system (pseudo-inverse at 0).
        eigenvalues, eigenvectors = np.linalg.eigh(u.T @ system @ u)
        projected = (side @ u) @ eigenvectors                                  # (n, r)
        scale = eigenvalues[None] + alphas[:, None] * float(np.mean(values[:rank])) / m
        tiny = 1e-10 * max(float(eigenvalues.max(initial=0.0)), 1e-300)
        inverse = np.where(np.abs(scale) > tiny, 1.0 / np.where(scale == 0, 1.0, scale), 0.0)
        signatures = (inverse[None] * projected[:, None]) @ eigenvectors.T     # (n, alphas, r)
        blocks.append(start[:, None] + (signatures @ u.T) @ tilde[:, m])      # (n, alphas, F)
        labels += [("people", rank, alpha) for alpha in ALPHAS]
    return labels, np.concatenate(blocks, axis=1)
