"""Motion signatures: action bases, signature regression, synthesis, recognition, blending.

Notation (Vasilescu 2002, §3). The data tensor of
deviations from the action means, people × actions × features, is decomposed as

    D − M = Z ×_1 P ×_2 A ×_3 J.

* The **action basis** of action ``a`` maps a signature to a motion:
  ``B_a = Z ×_2 a_aᵀ ×_3 J`` (``r_P × features``). Here it is kept in the coordinates of the
  feature basis ``J``: ``G_a = Z ×_2 a_aᵀ`` (``r_P × r_J``), so ``B_a = G_a Jᵀ``.
* A person's **signature** ``s`` (``r_P``) from any set ``S`` of their observed actions is the
  (ridge) least-squares solution of ``d_{p,a} − m_a ≈ B_aᵀ s`` for all ``a ∈ S`` stacked:

      (Σ_a G_a G_aᵀ + λ I) s = Σ_a G_a Jᵀ (d_{p,a} − m_a).

  With ``λ = 0`` and one observed action this is Vasilescu's ``p_newᵀ = d_{new,a}ᵀ B_a⁺``.
* **Synthesis** of action ``b`` for signature ``s``: ``d = m_b + J G_bᵀ s``.
* **Recognition**: the person whose synthesised motion for the trial's action is nearest to
  the trial (RMS over the angle features), with posterior-like scores.
* **Interpolation** between two people: ``s = (1 − w) s_1 + w s_2``.

All functions work on plain arrays; :class:`synthesis.model.MotionModel` holds them together.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from synthesis.nmode import NModeSVD, mode_dot


def action_bases(core: np.ndarray, action_factor: np.ndarray) -> np.ndarray:
    """``G_a = Z ×_2 a_aᵀ`` for every action, in the coordinates of the feature basis.

    Parameters
    ----------
    core : ndarray, shape (r_P, r_A, r_J)
        Core tensor ``Z``.
    action_factor : ndarray, shape (actions, r_A)
        Action mode matrix ``A``; row ``a`` holds the action parameters ``a_aᵀ``.

    Returns
    -------
    ndarray, shape (actions, r_P, r_J)
        ``B_a = G_a Jᵀ`` maps a signature to action ``a``'s motion (deviation from its mean).
    """
    return np.moveaxis(mode_dot(core, action_factor, 1), 1, 0)


def person_bases(core: np.ndarray, people_factor: np.ndarray) -> np.ndarray:
    """``C_p = Z ×_1 p_pᵀ`` for every person (action coefficients → that person's motion).

    Parameters
    ----------
    core : ndarray, shape (r_P, r_A, r_J)
    people_factor : ndarray, shape (people, r_P)

    Returns
    -------
    ndarray, shape (people, r_A, r_J)
    """
    return mode_dot(core, people_factor, 0)


def signature_system(bases: np.ndarray, feature_factor: np.ndarray, residuals: np.ndarray,
                     actions: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """Normal equations ``(Σ G_a G_aᵀ, Σ G_a Jᵀ r_a)`` of a signature fit.

    Parameters
    ----------
    bases : ndarray, shape (actions, r_P, r_J)
        From :func:`action_bases`.
    feature_factor : ndarray, shape (features, r_J)
        Orthonormal feature basis ``J``.
    residuals : ndarray, shape (observations, features)
        ``d_{p,a} − m_a`` of each observed action.
    actions : sequence of int, length observations
        Action index of each residual.

    Returns
    -------
    gram : ndarray, shape (r_P, r_P)
    right_hand_side : ndarray, shape (r_P,)
    """
    actions = np.asarray(actions, dtype=int)
    chosen = bases[actions]                                   # (k, r_P, r_J)
    coordinates = np.asarray(residuals) @ feature_factor      # (k, r_J)
    gram = np.einsum("kij,klj->il", chosen, chosen)
    right_hand_side = np.einsum("kij,kj->i", chosen, coordinates)
    return gram, right_hand_side


def solve_signature(gram: np.ndarray, right_hand_side: np.ndarray, ridge: float) -> np.ndarray:
    """Ridge solution of ``(gram + ridge I) s = rhs`` (minimum-norm least squares when singular).

    Parameters
    ----------
    gram : ndarray, shape (r, r)
    right_hand_side : ndarray, shape (r,)
    ridge : float
        λ ≥ 0, same units as ``gram``.

    Returns
    -------
    ndarray, shape (r,)
    """
    system = gram + ridge * np.eye(gram.shape[0])
    solution, *_ = np.linalg.lstsq(system, right_hand_side, rcond=1e-10)
    return solution


def fit_signature(bases: np.ndarray, feature_factor: np.ndarray, residuals: np.ndarray,
                  actions: Sequence[int], ridge: float = 0.0) -> np.ndarray:
    """A person's signature from any subset of their actions (stacked ridge least squares).

    Parameters
    ----------
    bases : ndarray, shape (actions, r_P, r_J)
    feature_factor : ndarray, shape (features, r_J)
    residuals : ndarray, shape (observations, features)
        Observed motions minus their action means.
    actions : sequence of int
        Action index of each observation.
    ridge : float
        λ ≥ 0 (0 = plain least squares, Vasilescu's pseudo-inverse).

    Returns
    -------
    ndarray, shape (r_P,)

    Examples
    --------
    >>> import numpy as np
    >>> bases = np.array([[[1.0, 0.0], [0.0, 2.0]]])           # one action, r_P = r_J = 2
    >>> J = np.eye(2)
    >>> fit_signature(bases, J, np.array([[3.0, 4.0]]), [0]).tolist()
    [3.0, 2.0]
    """
    gram, right_hand_side = signature_system(bases, feature_factor, residuals, actions)
    return solve_signature(gram, right_hand_side, ridge)


def synthesize_features(bases: np.ndarray, feature_factor: np.ndarray, action_mean: np.ndarray,
                        signature: np.ndarray, action: int) -> np.ndarray:
    """Motion of a signature doing an action: ``m_b + J G_bᵀ s``.

    Parameters
    ----------
    bases : ndarray, shape (actions, r_P, r_J)
    feature_factor : ndarray, shape (features, r_J)
    action_mean : ndarray, shape (actions, features)
    signature : ndarray, shape (r_P,) or (people, r_P)
    action : int

    Returns
    -------
    ndarray, shape (features,) or (people, features)
    """
    return action_mean[action] + (np.asarray(signature) @ bases[action]) @ feature_factor.T


def interpolate_signatures(first: np.ndarray, second: np.ndarray, weight: float) -> np.ndarray:
    """``(1 − w) s_1 + w s_2``: w = 0 gives the first person, 1 the second; outside [0, 1]
    extrapolates (caricatures).

    Parameters
    ----------
    first, second : ndarray, shape (r_P,)
        Signatures.
    weight : float

    Returns
    -------
    ndarray, shape (r_P,)
    """
    return (1.0 - weight) * np.asarray(first) + weight * np.asarray(second)


def posterior_scores(distances: np.ndarray, scale: float) -> np.ndarray:
    """Scores summing to 1 from distances: softmax of ``−½ (distance / scale)²``.

    Parameters
    ----------
    distances : ndarray, shape (candidates,)
        Distances, degrees.
    scale : float
        Typical distance of the right candidate, degrees (same measure as ``distances``).

    Returns
    -------
    ndarray, shape (candidates,)
    """
    scale = float(scale) if np.isfinite(scale) and scale > 0 else 1.0
    logits = -0.5 * (np.asarray(distances, dtype=float) / scale) ** 2
    logits -= logits.max()
    weights = np.exp(logits)
    return weights / weights.sum()


def bases_from_decomposition(decomposition: NModeSVD) -> np.ndarray:
    """:func:`action_bases` of an N-mode SVD of a people × actions × features tensor.

    Parameters
    ----------
    decomposition : NModeSVD
        Core (r_P, r_A, r_J) and factors.

    Returns
    -------
    ndarray, shape (actions, r_P, r_J)
    """
    return action_bases(decomposition.core, decomposition.factors[1])
