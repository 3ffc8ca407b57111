"""N-mode SVD: known ranks, orthogonality, all-orthogonal ordered core, agreement with tensorly."""
from __future__ import annotations

import numpy as np
import pytest
import tensorly as tl
from tensorly.decomposition import tucker

from synthesis.nmode import gram_svd, nmode_svd, reconstruct, relative_error


def multilinear_tensor(shape, ranks, seed=0):
    """Exact multilinear-rank tensor: random core times random orthonormal factors."""
    rng = np.random.default_rng(seed)
    core = rng.normal(size=ranks)
    factors = [np.linalg.qr(rng.normal(size=(n, r)))[0] for n, r in zip(shape, ranks)]
    return reconstruct(core, factors)


@pytest.mark.parametrize("shape", [(3, 40), (40, 3), (7, 7)])
def test_gram_svd_matches_numpy_svd_on_either_side(shape):
    matrix = np.random.default_rng(1).normal(size=shape)
    left, sigma, energy = gram_svd(matrix)
    u, s, _ = np.linalg.svd(matrix, full_matrices=False)
    assert np.allclose(sigma, s, rtol=1e-10)
    assert energy == pytest.approx(1.0)
    # Same subspace and, singular values being distinct, the same vectors up to sign.
    assert np.allclose(np.abs(left.T @ u), np.eye(len(s)), atol=1e-8)
    assert np.allclose(left.T @ left, np.eye(left.shape[1]), atol=1e-12)


def test_rank_by_count_and_by_energy():
    matrix = np.diag([4.0, 3.0, 2.0, 1.0])            # energies 16, 9, 4, 1 of 30
    _, sigma, energy = gram_svd(matrix, rank=2)
    assert sigma.tolist() == pytest.approx([4.0, 3.0])
    assert energy == pytest.approx(25 / 30)
    _, sigma, _ = gram_svd(matrix, rank=0.9)          # 25/30 < 0.9 <= 29/30
    assert len(sigma) == 3
    _, sigma, _ = gram_svd(matrix, rank=25 / 30)      # exactly reached by two components
    assert len(sigma) == 2
    with pytest.raises(ValueError):
        gram_svd(matrix, rank=1.5)


def test_numerical_ranks_of_an_exact_multilinear_tensor():
    tensor = multilinear_tensor((6, 4, 300), (3, 2, 5))
    result = nmode_svd(tensor)
    assert result.ranks == (3, 2, 5)
    assert relative_error(tensor, result.reconstruct()) < 1e-10


def test_full_rank_reconstruction_orthonormal_factors_and_ordered_all_orthogonal_core():
    tensor = np.random.default_rng(2).normal(size=(5, 4, 30))
    result = nmode_svd(tensor)
    assert result.ranks == (5, 4, 20)
    assert np.allclose(result.reconstruct(), tensor, atol=1e-10)
    for mode, factor in enumerate(result.factors):
        assert np.allclose(factor.T @ factor, np.eye(factor.shape[1]), atol=1e-10)
        # Core slices along a mode are mutually orthogonal with norms = singular values.
        slices = tl.unfold(result.core, mode)
        gram = slices @ slices.T
        assert np.allclose(gram, np.diag(result.singular_values[mode] ** 2), atol=1e-8)
        assert np.all(np.diff(result.singular_values[mode]) <= 1e-12)


def test_truncated_feature_mode_equals_tensorly_tucker():
    rng = np.random.default_rng(3)
    clean = multilinear_tensor((8, 4, 450), (8, 4, 6), seed=3)
    scale = 0.01 * np.linalg.norm(clean) / np.sqrt(clean.size)
    noisy = clean + scale * rng.normal(size=clean.shape)
    ours = nmode_svd(noisy, [8, 4, 6]).reconstruct()
    core, factors = tucker(noisy, rank=[8, 4, 6])
    theirs = tl.tucker_to_tensor((core, factors))
    assert relative_error(theirs, ours) < 1e-10
    # The truncation removes noise: closer to the clean tensor than the data are.
    assert relative_error(clean, ours) < relative_error(clean, noisy)


def test_energy_fraction_per_mode():
    tensor = multilinear_tensor((6, 4, 200), (6, 4, 8), seed=4)
    result = nmode_svd(tensor, [None, None, 0.95])
    assert result.energy[2] >= 0.95
    assert result.ranks[2] < 8


def test_rejects_missing_values():
    tensor = np.ones((2, 2, 3))
    tensor[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        nmode_svd(tensor)


@pytest.mark.parametrize("mode", [0, 1, 2])
def test_unfold_fold_and_mode_products_follow_tensorly(mode):
    """Our numpy unfold/fold/mode products give tensorly's (numpy backend) results."""
    from tensorly.tenalg import mode_dot as tl_mode_dot
    from tensorly.tenalg import multi_mode_dot as tl_multi_mode_dot

    from synthesis.nmode import fold, mode_dot, multi_mode_dot, unfold

    rng = np.random.default_rng(7)
    tensor = rng.normal(size=(3, 4, 5))
    with tl.backend_context("numpy"):
        assert np.array_equal(unfold(tensor, mode), tl.unfold(tensor, mode))
        assert np.array_equal(fold(unfold(tensor, mode), mode, tensor.shape), tensor)
        matrix = rng.normal(size=(2, tensor.shape[mode]))
        assert np.allclose(mode_dot(tensor, matrix, mode), tl_mode_dot(tensor, matrix, mode),
                           rtol=1e-13, atol=1e-13)
        assert np.allclose(mode_dot(tensor, matrix.T, mode, transpose=True),
                           tl_mode_dot(tensor, matrix, mode), rtol=1e-13, atol=1e-13)
        matrices = [rng.normal(size=(2, n)) for n in tensor.shape]
        order = [mode] + [m for m in range(3) if m != mode]
        assert np.allclose(multi_mode_dot(tensor, [matrices[m] for m in order], order),
                           tl_multi_mode_dot(tensor, matrices, [0, 1, 2]),
                           rtol=1e-12, atol=1e-12)
