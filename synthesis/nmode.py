"""The N-mode SVD (higher-order SVD) of a data tensor, computed the cheap way.

For a tensor ``D`` of shape ``(I_1, …, I_N)`` the N-mode SVD (De Lathauwer, De Moor and
Vandewalle 2000; Vasilescu 2002) is

    D = Z ×_1 U_1 ×_2 U_2 … ×_N U_N,

where ``U_n`` holds the left singular vectors of the mode-n unfolding ``D_(n)`` and the core
is ``Z = D ×_1 U_1ᵀ … ×_N U_Nᵀ``. Truncating ``U_n`` to its leading ``r_n`` columns gives the
truncated HOSVD. With full rank in every mode but one (people and actions full, joint-angle
features truncated) the truncated HOSVD is already the least-squares optimum, so no HOOI
sweeps are needed (see De Lathauwer et al. 2000, §4; Vasilescu 2002).

Each ``U_n`` comes from the eigen-decomposition of the *smaller* Gram matrix of the
unfolding: ``D_(n) D_(n)ᵀ`` when the mode is short, or ``D_(n)ᵀ D_(n) = V Σ² Vᵀ`` followed by
``U_n = D_(n) V Σ⁻¹`` when the mode is long. Only the leading eigenpairs are computed when the
rank is given as a count (ARPACK's Lanczos iteration for a few pairs of a large Gram). When
the last (feature) mode is at least as long as the number of cells, one product gives every
mode's Gram: the cell Gram ``Y Yᵀ`` of the cells × features view, whose partial traces are the
people and action Grams, and ``Uᵀ D_(N) = Σ Vᵀ`` then gives that mode's projection for free.
Squaring the matrix squares its condition number, so singular values below ~1e-8·σ_max lose
relative accuracy; such directions are dropped as numerically zero
(:data:`RELATIVE_TOLERANCE`).

Unfoldings, foldings and mode products (:func:`unfold`, :func:`fold`, :func:`mode_dot`,
:func:`multi_mode_dot`) are tensorly's (``tl.unfold``, ``tl.fold``, ``tenalg.mode_dot``), run
on tensorly's numpy backend for the calling thread only (``tl.backend_context(...,
local_threadsafe=True)``), so a backend the user chose elsewhere is neither needed nor
changed.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence, Union

import numpy as np
import scipy.linalg
import tensorly as tl
from scipy.sparse.linalg import ArpackNoConvergence, eigsh
from tensorly import tenalg

#: Singular values below this fraction of the largest are treated as zero (numerical rank).
RELATIVE_TOLERANCE = 1e-7

#: A mode's rank: ``None`` keeps the numerical rank, an ``int`` keeps that many components,
#: a ``float`` in (0, 1] keeps the fewest components whose squared singular values reach that
#: fraction of the mode's energy (``‖D‖²``).
Rank = Union[int, float, None]


def _numpy_backend():
    """tensorly's numpy backend for this thread, restored on exit (never the global choice)."""
    return tl.backend_context("numpy", local_threadsafe=True)


def unfold(tensor: np.ndarray, mode: int) -> np.ndarray:
    """Mode-``mode`` unfolding ``D_(n)`` (``tl.unfold``).

    Parameters
    ----------
    tensor : ndarray, shape (I_1, …, I_N)
    mode : int
        0-based.

    Returns
    -------
    ndarray, shape (I_mode, ∏ other I_k)
        Mode-``mode`` fibres as columns, the remaining modes in C order.

    Examples
    --------
    >>> unfold(np.arange(8.0).reshape(2, 2, 2), 1)
    array([[0., 1., 4., 5.],
           [2., 3., 6., 7.]])
    """
    with _numpy_backend():
        return tl.unfold(tensor, mode)


def fold(unfolded: np.ndarray, mode: int, shape: Sequence[int]) -> np.ndarray:
    """Inverse of :func:`unfold` (``tl.fold``): the tensor of ``shape`` whose mode-``mode``
    unfolding is given.

    Parameters
    ----------
    unfolded : ndarray, shape (shape[mode], ∏ other shape[k])
    mode : int
    shape : sequence of int

    Returns
    -------
    ndarray, shape ``shape``
    """
    with _numpy_backend():
        return tl.fold(unfolded, mode, tuple(shape))


def mode_dot(tensor: np.ndarray, matrix: np.ndarray, mode: int,
             transpose: bool = False) -> np.ndarray:
    """Mode-n product ``D ×_n M`` (``tenalg.mode_dot``).

    Parameters
    ----------
    tensor : ndarray, shape (I_1, …, I_N)
    matrix : ndarray, shape (J, I_mode), or (I_mode, J) with ``transpose``
    mode : int
    transpose : bool
        Multiply by ``matrixᵀ``.

    Returns
    -------
    ndarray, shape (I_1, …, J, …, I_N)
        ``J`` in place of ``I_mode``.
    """
    with _numpy_backend():
        return tenalg.mode_dot(tensor, matrix, mode, transpose=transpose)


def multi_mode_dot(tensor: np.ndarray, matrices: Sequence[np.ndarray], modes: Sequence[int],
                   transpose: bool = False) -> np.ndarray:
    """``D ×_{m_1} M_1 ×_{m_2} M_2 …``, the products taken in the order given (the order
    that shrinks the tensor first is the caller's choice; ``tenalg.multi_mode_dot`` would
    sort them by mode).

    Parameters
    ----------
    tensor : ndarray, shape (I_1, …, I_N)
    matrices : sequence of ndarray, entry k of shape (J_k, I_{modes[k]})
        ``(I_{modes[k]}, J_k)`` with ``transpose``.
    modes : sequence of int
    transpose : bool
        Multiply by every matrix's transpose.

    Returns
    -------
    ndarray
        ``tensor``'s shape with ``J_k`` in place of ``I_{modes[k]}``.
    """
    for matrix, mode in zip(matrices, modes):
        tensor = mode_dot(tensor, matrix, mode, transpose)
    return tensor


@dataclass
class NModeSVD:
    """Result of :func:`nmode_svd`.

    Attributes
    ----------
    core : ndarray, shape (r_1, …, r_N)
        The core tensor ``Z``.
    factors : list of ndarray, factor n of shape (I_n, r_n)
        Orthonormal mode matrices ``U_n`` (columns ordered by decreasing singular value).
    singular_values : list of ndarray, entry n of shape (r_n,)
        Mode-n singular values kept (``‖Z_{i_n = k}‖`` for the untruncated core).
    energy : list of float
        Fraction of ``‖D‖²`` kept by each mode's truncation.
    """

    core: np.ndarray
    factors: list[np.ndarray]
    singular_values: list[np.ndarray]
    energy: list[float]

    @property
    def ranks(self) -> tuple[int, ...]:
        """Rank kept in each mode."""
        return tuple(int(factor.shape[1]) for factor in self.factors)

    def reconstruct(self) -> np.ndarray:
        """The approximation ``Z ×_1 U_1 … ×_N U_N``, same shape as the decomposed tensor."""
        return reconstruct(self.core, self.factors)


def _rank_from_eigenvalues(eigenvalues: np.ndarray, total_energy: float, rank: Rank,
                           mode: int) -> int:
    """Number of components to keep, from descending Gram eigenvalues (= σ²)."""
    largest = float(eigenvalues[0]) if eigenvalues.size else 0.0
    numerical = int(np.count_nonzero(eigenvalues > (RELATIVE_TOLERANCE ** 2) * largest)) \
        if largest > 0 else 0
    if rank is None:
        return max(numerical, 1)
    if isinstance(rank, (bool, np.bool_)):
        raise ValueError(f"rank of mode {mode} must be an int, a float in (0, 1] or None")
    if isinstance(rank, (int, np.integer)):
        if rank < 1:
            raise ValueError(f"rank of mode {mode} must be at least 1, got {rank}")
        return int(min(rank, eigenvalues.size))
    fraction = float(rank)
    if not 0.0 < fraction <= 1.0:
        raise ValueError(f"energy fraction of mode {mode} must be in (0, 1], got {rank}")
    if total_energy <= 0:
        return 1
    kept = np.cumsum(eigenvalues) / total_energy
    count = int(np.searchsorted(kept, fraction - 1e-12) + 1)
    return int(min(max(count, 1), max(numerical, 1)))


#: Gram matrices at least this large use a Krylov (ARPACK) solver for a few leading eigenpairs.
KRYLOV_MIN_SIZE = 400
#: Gram matrices at most this large are decomposed in full (numpy ``eigh``).
SMALL_GRAM = 128


def leading_eigenpairs(gram: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``count`` largest eigenvalues (descending) and eigenvectors of a symmetric matrix.

    A few eigenpairs of a large matrix come from ARPACK's Lanczos iteration
    (``scipy.sparse.linalg.eigsh``, to machine precision, deterministic start vector), which
    needs only matrix-vector products; otherwise from LAPACK's subset driver
    (``scipy.linalg.eigh(subset_by_index=…)``), which still reduces the whole matrix to
    tridiagonal form (≈ 11 s against ≈ 2 s for the 60 leading pairs of a 4000² Gram).

    Parameters
    ----------
    gram : ndarray, shape (n, n), symmetric positive semi-definite
    count : int, 1 ≤ count ≤ n

    Returns
    -------
    values : ndarray, shape (count,)
    vectors : ndarray, shape (n, count)
    """
    size = gram.shape[0]
    if size >= KRYLOV_MIN_SIZE and count <= size // 4:
        start = np.random.default_rng(0).normal(size=size)
        try:
            values, vectors = eigsh(gram, k=count, which="LA", v0=start, tol=0.0)
        except ArpackNoConvergence:
            values = None
        if values is not None:
            order = np.argsort(values)[::-1]
            return values[order], vectors[:, order]
    if size <= SMALL_GRAM:
        # Small matrices: a full decomposition costs less than the subset driver's set-up.
        values, vectors = np.linalg.eigh(gram)
        return values[::-1][:count], vectors[:, ::-1][:, :count]
    values, vectors = scipy.linalg.eigh(gram, subset_by_index=[size - count, size - 1],
                                        check_finite=False)
    return values[::-1], vectors[:, ::-1]


def gram_svd(matrix: np.ndarray, rank: Rank = None, mode: int = 0
             ) -> tuple[np.ndarray, np.ndarray, float]:
    """Leading left singular vectors of a matrix from the eigen-decomposition of its smaller Gram.

    Parameters
    ----------
    matrix : ndarray, shape (m, n)
        For the N-mode SVD, a mode-n unfolding ``D_(n)``.
    rank : int, float or None
        Components to keep: a count, a kept-energy fraction in (0, 1], or ``None`` for the
        numerical rank (singular values above ``RELATIVE_TOLERANCE · σ_max``).
    mode : int
        Only used in error messages.

    Returns
    -------
    U : ndarray, shape (m, r)
        Orthonormal left singular vectors, by decreasing singular value, with the sign chosen
        so that the largest-magnitude entry of each column is positive (deterministic).
    singular_values : ndarray, shape (r,)
    energy : float
        Fraction of ``‖matrix‖²`` kept.

    Examples
    --------
    >>> import numpy as np
    >>> U, s, kept = gram_svd(np.diag([3.0, 2.0, 1.0]), rank=2)
    >>> np.round(s, 6).tolist(), round(kept, 4)
    ([3.0, 2.0], 0.9286)
    """
    left, singular_values, energy, _ = _gram_svd(matrix, rank, mode)
    return left, singular_values, energy


def _gram_svd(matrix: np.ndarray | None, rank: Rank, mode: int,
              gram: np.ndarray | None = None, shape: tuple[int, int] | None = None
              ) -> tuple[np.ndarray, np.ndarray, float, np.ndarray | None]:
    """:func:`gram_svd`, plus ``Uᵀ matrix`` (r, n) when it came for free (else None).

    ``gram`` may be given precomputed (the smaller one); ``matrix`` may then be None when it
    is ``matrix matrixᵀ``, with ``shape`` the matrix's shape.
    """
    rows, columns = matrix.shape if matrix is not None else shape
    tall_side_small = rows <= columns
    if gram is None:
        gram = matrix @ matrix.T if tall_side_small else matrix.T @ matrix
    size = gram.shape[0]
    total_energy = float(np.trace(gram))
    if isinstance(rank, (int, np.integer)) and not isinstance(rank, (bool, np.bool_)) \
            and 0 < rank < size:
        values, vectors = leading_eigenpairs(gram, int(rank))
        all_values = values
    else:
        # Rank from the spectrum (numerical rank or kept energy): one full decomposition.
        values, vectors = np.linalg.eigh(gram)
        values, vectors = values[::-1], vectors[:, ::-1]
        all_values = values
    all_values = np.clip(all_values, 0.0, None)
    keep = _rank_from_eigenvalues(all_values, total_energy, rank, mode)
    values = np.clip(values[:keep], 0.0, None)
    vectors = vectors[:, :keep]
    # Directions below the numerical rank are noise from the squared condition number.
    largest = values[0] if values.size else 0.0
    valid = values > (RELATIVE_TOLERANCE ** 2) * largest if largest > 0 else np.zeros(keep, bool)
    if not valid.all():
        values, vectors = values[valid], vectors[:, valid]
    singular_values = np.sqrt(values)
    projected = None
    if tall_side_small:
        left = vectors
    else:
        left = (matrix @ vectors) / singular_values
        # U = D V Σ⁻¹ is orthonormal up to rounding amplified by σ_max²/σ²: re-orthonormalise
        # only when that shows.
        if left.shape[1] and np.abs(left.T @ left - np.eye(left.shape[1])).max() > 1e-10:
            left, triangle = np.linalg.qr(left)
            left *= np.sign(np.diag(triangle))
        else:
            # Uᵀ D = Σ⁻¹ Vᵀ DᵀD = Σ⁻¹ Vᵀ V Σ² = Σ Vᵀ: the projection onto U comes for free.
            projected = singular_values[:, None] * vectors.T if left.shape[1] else None
    if left.shape[1] == 0:
        left = np.zeros((rows, 1))
        left[0, 0] = 1.0
        singular_values = np.zeros(1)
        projected = None
    # Deterministic signs: largest-magnitude entry of each column positive.
    pivots = np.argmax(np.abs(left), axis=0)
    signs = np.sign(left[pivots, np.arange(left.shape[1])])
    signs[signs == 0] = 1.0
    left = left * signs
    if projected is not None:
        projected = projected * signs[:, None]
    kept_energy = float(np.sum(singular_values ** 2) / total_energy) if total_energy > 0 else 1.0
    return left, singular_values, kept_energy, projected


def mode_factor(tensor: np.ndarray, mode: int, rank: Rank = None
                ) -> tuple[np.ndarray, np.ndarray, float]:
    """Mode matrix ``U_n`` of the N-mode SVD: leading left singular vectors of ``D_(n)``.

    Parameters
    ----------
    tensor : ndarray, shape (I_1, …, I_N)
    mode : int
    rank : int, float or None
        See :func:`gram_svd`.

    Returns
    -------
    U_n : ndarray, shape (I_mode, r)
    singular_values : ndarray, shape (r,)
    energy : float
    """
    return gram_svd(unfold(tensor, mode), rank, mode)


def nmode_svd(tensor: np.ndarray, ranks: Sequence[Rank] | Rank = None) -> NModeSVD:
    """N-mode SVD (truncated HOSVD) ``D = Z ×_1 U_1 … ×_N U_N``.

    Parameters
    ----------
    tensor : ndarray, shape (I_1, …, I_N), float
        Data tensor without missing values.
    ranks : sequence of (int, float or None), or one of those for every mode
        Per mode: a count of components, a kept-energy fraction in (0, 1], or ``None`` for the
        numerical rank.

    Returns
    -------
    NModeSVD
        Core, orthonormal factors, kept singular values and kept energy per mode.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> D = rng.normal(size=(4, 3, 50))
    >>> result = nmode_svd(D)
    >>> result.ranks
    (4, 3, 12)
    >>> bool(np.allclose(result.reconstruct(), D))
    True
    """
    tensor = np.asarray(tensor, dtype=float)
    if not np.all(np.isfinite(tensor)):
        raise ValueError("the N-mode SVD needs a tensor without NaN or infinite values")
    if ranks is None or not isinstance(ranks, (list, tuple)):
        ranks = [ranks] * tensor.ndim
    if len(ranks) != tensor.ndim:
        raise ValueError(f"{len(ranks)} ranks for a tensor of {tensor.ndim} modes")
    factors, singular_values, energy = [], [], []
    shortcut = None                  # (mode, D ×_mode U_modeᵀ) when an SVD gave it for free
    grams = _grams_from_cells(tensor)
    for mode, rank in enumerate(ranks):
        if grams is None:
            factor, sigma, kept, projected = _gram_svd(unfold(tensor, mode), rank, mode)
        elif mode < tensor.ndim - 1:
            others = int(np.prod(tensor.shape)) // tensor.shape[mode]
            factor, sigma, kept, projected = _gram_svd(None, rank, mode, grams[mode],
                                                       (tensor.shape[mode], others))
        else:
            factor, sigma, kept, projected = _gram_svd(unfold(tensor, mode), rank, mode,
                                                       grams[mode])
        factors.append(factor)
        singular_values.append(sigma)
        energy.append(kept)
        if projected is not None and (shortcut is None or
                                      factor.shape[1] / tensor.shape[mode] <
                                      factors[shortcut[0]].shape[1] / tensor.shape[shortcut[0]]):
            shape = tensor.shape[:mode] + (factor.shape[1],) + tensor.shape[mode + 1:]
            shortcut = (mode, fold(projected, mode, shape))
    if shortcut is None:
        core = project(tensor, factors)
    else:
        mode, partial = shortcut
        core = project(partial, [factors[m] if m != mode else None for m in range(tensor.ndim)])
    return NModeSVD(core, factors, singular_values, energy)


def _grams_from_cells(tensor: np.ndarray) -> list[np.ndarray] | None:
    """Every mode's smaller Gram matrix from one product, when the last mode is the long one.

    With ``Y`` the tensor seen as cells × last-mode fibres (``∏ I_k`` × ``I_N``, no copy), the
    cell Gram ``C = Y Yᵀ`` is the smaller Gram of the last unfolding, and the Gram of every
    other mode is a partial trace of it: ``D_(n) D_(n)ᵀ = Σ C[…, i_n, …; …, j_n, …]`` over
    the other (equal) cell indices. One BLAS product instead of one per mode, and no
    unfolding copies. Returns None when the last mode is shorter than the number of cells.
    """
    cells = int(np.prod(tensor.shape[:-1]))
    if tensor.ndim < 2 or tensor.shape[-1] < cells or tensor.ndim > 26:
        return None
    flat = tensor.reshape(cells, tensor.shape[-1])
    cell_gram = flat @ flat.T
    blocks = cell_gram.reshape(tensor.shape[:-1] * 2)
    letters = "abcdefghijklmnopqrstuvwxyz"[:tensor.ndim - 1]
    grams = []
    for mode in range(tensor.ndim - 1):
        right = letters[:mode] + letters[mode].upper() + letters[mode + 1:]
        grams.append(np.einsum(f"{letters}{right}->{letters[mode]}{letters[mode].upper()}",
                               blocks))
    grams.append(cell_gram)
    return grams


def _shrinking_order(shape: Sequence[int], factors: Sequence[np.ndarray]) -> list[int]:
    """Modes ordered so the product that shrinks the tensor most comes first."""
    return sorted(range(len(factors)),
                  key=lambda m: 1.0 if factors[m] is None else factors[m].shape[1] / shape[m])


def project(tensor: np.ndarray, factors: Sequence[np.ndarray]) -> np.ndarray:
    """Core ``Z = D ×_1 U_1ᵀ … ×_N U_Nᵀ``.

    Parameters
    ----------
    tensor : ndarray, shape (I_1, …, I_N)
    factors : list of ndarray, factor n of shape (I_n, r_n)
        ``None`` for a mode to leave as it is.

    Returns
    -------
    ndarray, shape (r_1, …, r_N)
    """
    order = [m for m in _shrinking_order(tensor.shape, factors) if factors[m] is not None]
    return multi_mode_dot(tensor, [factors[m] for m in order], modes=order, transpose=True)


def reconstruct(core: np.ndarray, factors: Sequence[np.ndarray]) -> np.ndarray:
    """``Z ×_1 U_1 … ×_N U_N``: the tensor a core and its mode matrices describe.

    Parameters
    ----------
    core : ndarray, shape (r_1, …, r_N)
    factors : list of ndarray, factor n of shape (I_n, r_n)

    Returns
    -------
    ndarray, shape (I_1, …, I_N)
    """
    # Expand the cheapest modes first (smallest growth ratio).
    order = sorted(range(len(factors)), key=lambda m: factors[m].shape[0] / factors[m].shape[1])
    return multi_mode_dot(core, [factors[m] for m in order], modes=order)


def relative_error(tensor: np.ndarray, approximation: np.ndarray) -> float:
    """``‖D − D̂‖ / ‖D‖`` (Frobenius); 0 when ``D`` is zero.

    Parameters
    ----------
    tensor, approximation : ndarray, same shape
    """
    norm = float(np.linalg.norm(tensor))
    return float(np.linalg.norm(tensor - approximation)) / norm if norm > 0 else 0.0
