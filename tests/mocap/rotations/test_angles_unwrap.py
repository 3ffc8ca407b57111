"""unwrap_columns: the per-column, NaN-aware unwrap (BVH channels, angle curves)."""
from __future__ import annotations

import numpy as np

from mocap.rotations.angles import unwrap_columns


def test_unwrap_across_the_wrap_point_with_missing_samples():
    true = np.linspace(150.0, 230.0, 81)                     # crosses +180°
    wrapped = (true + 180.0) % 360.0 - 180.0
    wrapped[10:15] = np.nan
    unwrapped = unwrap_columns(wrapped[:, None])[:, 0]
    valid = ~np.isnan(unwrapped)
    assert np.allclose(unwrapped[valid], true[valid])
    assert np.isnan(unwrapped[10:15]).all()


def test_unwrap_columns_equals_numpy_per_column_on_any_shape():
    """Each column on its own, as np.unwrap over its defined samples; shape kept."""
    rng = np.random.default_rng(5)
    true = np.cumsum(rng.normal(0.0, 40.0, size=(300, 4, 3)), axis=0)
    wrapped = (true + 180.0) % 360.0 - 180.0
    gaps = wrapped.copy()
    gaps[40:60, 1, 2] = np.nan
    out = unwrap_columns(gaps)
    assert out.shape == gaps.shape
    assert np.array_equal(np.isnan(out), np.isnan(gaps))
    complete = np.ones((4, 3), dtype=bool)
    complete[1, 2] = False
    assert np.array_equal(out[:, complete], np.unwrap(wrapped[:, complete], period=360.0, axis=0))
    defined = ~np.isnan(gaps[:, 1, 2])
    assert np.array_equal(out[defined, 1, 2], np.unwrap(wrapped[defined, 1, 2], period=360.0))
