"""Recognition weights (limma's moderated variances against known draws) and the
calibration of recognition scores."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.special import polygamma

from synthesis.recognition import (ScoreModel, _trigamma_inverse, fit_score_model,
                                   moderated_variances, variance_prior)


@pytest.mark.parametrize("value", [1e-8, 1e-3, 0.3, 1.0, 10.0, 1e4, 1e9])
def test_trigamma_inverse_inverts_the_trigamma(value):
    assert float(polygamma(1, _trigamma_inverse(value))) == pytest.approx(value, rel=1e-6)


@pytest.mark.parametrize("prior_dof, dof", [(4.0, 3), (10.0, 6), (2.5, 12)])
def test_the_prior_of_drawn_variances_is_recovered(prior_dof, dof):
    """True variances σ² ~ s₀² d₀ / χ²_{d₀}, each seen as σ² χ²_d / d: the fitted prior is the
    one they were drawn from (50,000 features, within a few per cent)."""
    rng = np.random.default_rng(7)
    features, scale = 50_000, 2.5
    truth = scale * prior_dof / rng.chisquare(prior_dof, features)
    observed = truth * rng.chisquare(dof, features) / dof
    fitted_dof, fitted_scale = variance_prior(observed, dof)
    assert fitted_dof == pytest.approx(prior_dof, rel=0.08)
    assert fitted_scale == pytest.approx(scale, rel=0.04)
    # The moderated variances are nearer the truth than the raw ones, in log terms, and the
    # more so the more weight the prior has (d₀ against d).
    moderated = moderated_variances(observed, dof)
    gain = np.mean(np.log(moderated / truth) ** 2) / np.mean(np.log(observed / truth) ** 2)
    assert gain < 1.0 - 0.5 * prior_dof / (prior_dof + dof)


def test_one_true_variance_gives_one_weight_and_fewer_donors_shrink_more():
    rng = np.random.default_rng(3)
    same = 4.0 * rng.chisquare(5, 20_000) / 5
    assert variance_prior(same, 5)[0] > 200                  # no spread beyond sampling noise
    moderated = moderated_variances(same, 5)
    assert np.ptp(moderated) < 0.1 * np.ptp(same)
    assert np.median(moderated) == pytest.approx(4.0, rel=0.05)
    # Features that really differ: the same spread read as 3 donors' variances is pulled
    # further toward the prior than read as 12 donors'.
    spread = np.exp(rng.normal(0.0, 1.0, 5_000))
    pull = [np.mean(np.abs(np.log(moderated_variances(spread, d) / spread))) for d in (3, 12)]
    assert pull[0] > pull[1] > 0


def test_degenerate_variances_stay_finite():
    assert np.array_equal(moderated_variances(np.array([0.0, 0.0, 2.0]), 4), [2 / 3] * 3)
    exact = np.array([0.0, 1.0, 4.0, 0.0])
    moderated = moderated_variances(exact, 4)
    assert np.isfinite(moderated).all() and (moderated > 0).all()
    assert np.array_equal(moderated_variances(exact, 0), exact)


def test_scores_are_a_laplace_softmax_mixed_with_the_miss_chance():
    model = ScoreModel(temperature=2.0, miss_chance=0.25)
    scores = model.scores(np.array([3.0, 5.0, 9.0]))
    softmax = np.exp(-np.array([0.0, 1.0, 3.0]))
    assert np.allclose(scores, 0.75 * softmax / softmax.sum() + 0.25 / 3, rtol=1e-12)
    assert scores.sum() == pytest.approx(1.0, rel=1e-12)
    # τ = 0: the nearest alone, tempered by the miss chance.
    hard = ScoreModel(0.0, 0.2).scores(np.array([4.0, 1.0, 7.0, 2.0]))
    assert np.allclose(hard, [0.05, 0.85, 0.05, 0.05], rtol=1e-12)


def test_the_temperature_maximises_the_right_candidates_log_score_and_misses_count():
    """Problems drawn from a known Laplace-softmax: the fitted τ is the likelihood's maximum
    (no grid point of 400 does better), near the τ they were drawn with; ε counts the
    problems whose nearest is wrong by Laplace's rule of succession."""
    rng = np.random.default_rng(11)
    problems, candidates, true_temperature = 400, 400, 2.0
    table = rng.uniform(0.0, 10.0, (problems, candidates))
    # Which candidate is right: drawn with probability softmax(−d / τ) in each row.
    logits = -table / true_temperature
    chances = np.exp(logits - logits.max(axis=1, keepdims=True))
    chances /= chances.sum(axis=1, keepdims=True)
    right = np.array([rng.choice(candidates, p=row) for row in chances])
    # fit_score_model wants the right candidate on the diagonal: swap it there.
    rows = np.arange(problems)
    table[rows, right], table[rows, rows] = table[rows, rows], table[rows, right]
    fitted = fit_score_model(table)
    misses = int(np.sum(np.argmin(table, axis=1) != rows))
    assert fitted.miss_chance == pytest.approx((misses + 1) / (problems + 2))

    def log_score(temperature):
        logits = -table / temperature
        top = logits.max(axis=1, keepdims=True)
        return np.mean(logits[rows, rows] - top[:, 0]
                       - np.log(np.exp(logits - top).sum(axis=1)))

    grid = np.geomspace(0.2, 20.0, 400)
    assert log_score(fitted.temperature) >= max(log_score(t) for t in grid) - 1e-9
    assert fitted.temperature == pytest.approx(true_temperature, rel=0.2)


def test_separable_problems_give_the_nearest_alone_and_too_few_give_nothing():
    table = np.full((5, 5), 3.0) - 2.0 * np.eye(5)
    assert fit_score_model(table) == ScoreModel(0.0, 1.0 / 7.0)
    assert fit_score_model(table[:2, :2]) is None
    table[1, 3] = np.nan
    assert fit_score_model(table) is None
