"""InteractionModel: rank 0 is the additive model exactly; the interaction is used only when
held-out donors reward it."""
from __future__ import annotations

import numpy as np
import pytest

from synthesis.interaction import ALPHAS, InteractionModel, action_weight_grid, action_weights


def main_effects(people=9, actions=5, features=60, seed=0):
    """``μ_a + α_p`` per cell (shape (people, actions, features)) and a generator."""
    rng = np.random.default_rng(seed)
    return (rng.normal(0, 10, (1, actions, features)) + rng.normal(0, 5, (people, 1, features)),
            rng)


def test_rank_zero_is_the_additive_model_exactly():
    data, rng = main_effects()
    data = data + rng.normal(0, 3, data.shape)            # an interaction of any kind
    data[2, 1] = np.nan
    data[5, 3] = np.nan                                     # two incomplete people
    additive = InteractionModel(max_rank=0).fit(data)
    for person, action in [(2, 1), (5, 3), (0, 4), (7, 0)]:
        masked = data.copy()
        masked[person, action] = np.nan
        model = InteractionModel(max_rank=0).fit(masked)
        others = [a for a in range(5) if a != action and np.isfinite(masked[person, a]).all()]
        keep = np.isfinite(masked).all(axis=2)
        keep[person] = False
        means = np.array([masked[keep[:, a], a].mean(axis=0) for a in range(5)])
        expected = means[action] + np.mean([masked[person, a] - means[a] for a in others],
                                           axis=0)
        prediction, chosen = model.predict(person, action)
        assert np.array_equal(prediction, model.additive(person, action))
        assert np.allclose(prediction, expected, atol=1e-12)
        assert chosen.rank == 0 and chosen.mode == "additive"
    assert additive.predict(2, 1)[0] == pytest.approx(additive.additive(2, 1), abs=0)
    # The action-mode weights of rank 0 are the additive model's 1/m.
    assert np.allclose(action_weights(np.zeros((4, 0)), 0.3), 1 / 3)


def test_the_batched_action_grid_is_every_single_fit():
    rng = np.random.default_rng(1)
    for m in (1, 2, 4):
        vectors, _ = np.linalg.qr(rng.normal(size=(m + 1, m)))
        grid = action_weight_grid(vectors)
        for rank in range(1, m + 1):
            for i, alpha in enumerate(ALPHAS):
                assert np.allclose(grid[rank - 1, i], action_weights(vectors[:, :rank], alpha),
                                   atol=1e-12)


def test_the_paired_nested_selection_is_the_selection_without_each_donor():
    """The nested check shares one batched prediction per pair of donors; it must equal, for
    each donor k, the plain leave-one-donor-out selection run on the other donors (means
    without k), and the predictions in the cells' basis must equal those in feature space."""
    data, rng = main_effects(people=8, features=40)
    data = data + np.einsum("p,a,f->paf", rng.normal(size=8), rng.normal(size=5),
                            rng.normal(0, 3, 40)) + rng.normal(0, 1, data.shape)
    model = InteractionModel("both").fit(data)
    target, observed = 4, (0, 1, 2, 3)
    cells, sums, counts = model._donors(target, observed, None)
    labels, folds, _ = model._folds(cells, sums, counts, 4, 40)
    nested = folds[np.arange(cells.shape[0]), model._nested(cells, sums, counts, 4, 40, labels)]
    for k in range(cells.shape[0]):
        others = np.arange(cells.shape[0]) != k
        inner_labels, inner, _ = model._folds(cells[others], sums - cells[k], counts - 1, 4, 40)
        assert nested[k] == pytest.approx(
            folds[k, labels.index(inner_labels[model._choose(inner)])], rel=1e-12)
    # The same folds computed on the cells themselves (no basis) give the same errors.
    plain = InteractionModel("both").fit(data)
    plain.basis_, plain.coords_ = np.eye(40), data
    cells, sums, counts = plain._donors(target, observed, None)
    assert np.allclose(plain._folds(cells, sums, counts, 4, 40)[1], folds, rtol=1e-10)
    assert model.basis_.shape[1] <= 8 * 5


def test_noise_without_interaction_keeps_the_additive_model():
    """Main effects plus white noise: nothing for the interaction to learn, and the donors'
    leave-one-out says so for (almost) every cell."""
    data, rng = main_effects(people=10)
    data = data + rng.normal(0, 2, data.shape)
    chosen = []
    for person in range(10):
        for action in range(5):
            masked = data.copy()
            masked[person, action] = np.nan
            model = InteractionModel("both").fit(masked)
            chosen.append(model.predict(person, action)[1].rank)
    assert np.mean(np.array(chosen) == 0) >= 0.9


@pytest.mark.parametrize("mode", ["actions", "nmode", "both"])
def test_an_action_mode_interaction_is_found_and_used(mode):
    """Cells ``μ_a + α_p + v_a c_p`` (rank-1 action-mode interaction, small noise): the held-out
    cell is predicted far better than by the additive model, with rank 1."""
    data, rng = main_effects(people=8)
    v = np.array([2.0, -1.0, 1.5, -0.5, -2.0])
    data = data + v[None, :, None] * rng.normal(0, 4, (8, 1, 60)) + rng.normal(0, 0.1, data.shape)
    errors, additive = [], []
    for person, action in [(0, 0), (3, 2), (6, 4)]:
        masked = data.copy()
        masked[person, action] = np.nan
        model = InteractionModel(mode).fit(masked)
        prediction, chosen = model.predict(person, action)
        assert chosen.rank >= 1 and chosen.loo_rms < 0.5 * chosen.additive_loo_rms
        errors.append(np.sqrt(np.mean((prediction - data[person, action]) ** 2)))
        additive.append(np.sqrt(np.mean((model.additive(person, action)
                                         - data[person, action]) ** 2)))
    assert max(errors) < 0.2 * min(additive)


@pytest.mark.parametrize("actions", [2, 4])
def test_a_fraction_of_the_offset_that_carries_is_found_by_the_ridge_map(actions):
    """Cells ``μ_a + z_p`` in the observed actions and ``μ_b + ½ z_p`` in the target: half of a
    person's offset carries. The offsets are formed from means without the person, and the
    target offset is still exactly half the observed ones' mean, so the ridge map across
    actions (weights ``1/(2m)``, from the donors alone) predicts the held-out cell exactly —
    the additive model is ``½ z`` off and no action-mode or people-mode rank is exact — and the
    default's selection picks it; with one observed action it stands where the action mode
    has no person basis."""
    rng = np.random.default_rng(5)
    people, features = 9, 60
    offsets = rng.normal(0, 5, (people, 1, features))
    carried = np.r_[np.ones(actions - 1), 0.5]
    data = rng.normal(0, 10, (1, actions, features)) + carried[None, :, None] * offsets
    for person in (0, 4, 8):
        masked = data.copy()
        masked[person, -1] = np.nan
        model = InteractionModel("both").fit(masked)
        prediction, chosen = model.predict(person, actions - 1)
        assert (chosen.mode, chosen.rank, chosen.alpha) == ("regression", actions - 1, 0.0)
        truth = data[person, -1]
        assert np.abs(prediction - truth).max() < 1e-9 * np.abs(data).max()
        additive = model.additive(person, actions - 1)
        assert np.sqrt(np.mean((additive - truth) ** 2)) > 1.0
        if actions == 2:     # no action-mode candidate where one action is observed
            cells, sums, counts = model._donors(actions - 1, (0,), person)
            labels, _, _ = model._folds(cells, sums, counts, 1, features)
            assert not [label for label in labels if label[0] == "actions"]


def test_a_person_beyond_the_donors_range_keeps_the_additive_prediction():
    """Two actions, people whose offsets in one say little about the other (the donors teach
    a shrink toward the mean), and one person whose every cell carries a persistent offset
    ten times a typical one (a marker on the other side of a limb does that). With one
    observed action nothing in the person's own cells can check the shrink, so that person
    gets the additive prediction exactly — right here, to the action-specific part — while a
    person inside the donors' range keeps the correction."""
    rng = np.random.default_rng(3)
    data = rng.normal(0, 10, (1, 2, 60)) + rng.normal(0, 5, (12, 2, 60))
    data[0] += 50.0 * rng.normal(0, 1, 60)
    for person, outside in ((0, True), (3, False)):
        # (the inside person among the others only: the outlier as a donor vetoes the shrink)
        masked = data.copy() if outside else data[1:].copy()
        person -= 0 if outside else 1
        masked[person, 1] = np.nan
        model = InteractionModel("both").fit(masked)
        x = (model.coords_[person, 0] - model._means(person, coords=True)[0])[None]
        assert model.outside_donors(1, (0,), person, x) == outside
        prediction, chosen = model.predict(person, 1)
        assert chosen.rank >= 1                                 # chosen on the donors
        assert np.array_equal(prediction, model.additive(person, 1)) == outside
        if outside:
            error = np.sqrt(np.mean((prediction - data[0, 1]) ** 2))
            assert error < 10 < 30 < np.sqrt(np.mean(data[0, 1] ** 2))


@pytest.mark.parametrize("mode", ["people", "nmode"])
def test_a_people_mode_interaction_is_found_by_the_signature_mode(mode):
    """Cells ``μ_a + α_p + B_aᵀ s_p`` (rank-2 signatures): the people mode recovers them, alone
    or chosen beside the action mode (``"nmode"``, the signature method's)."""
    data, rng = main_effects(people=9)
    bases = rng.normal(0, 3, (5, 2, 60))
    signatures = rng.normal(0, 1, (9, 2))
    data = data + np.einsum("pi,aif->paf", signatures, bases)
    masked = data.copy()
    masked[4, 2] = np.nan
    model = InteractionModel(mode).fit(masked)
    prediction, chosen = model.predict(4, 2)
    assert chosen.mode == "people" and chosen.rank >= 2
    assert np.sqrt(np.mean((prediction - data[4, 2]) ** 2)) < 1e-6 * np.abs(data).max()


def test_with_too_few_donors_evaluate_says_the_model_is_the_additive_one():
    """Three people leave two donors per held-out person: every synthesised cell is the
    additive model's, and the paired comparison reports ties only."""
    from synthesis.evaluate import leave_one_out
    from tests.synthesis.test_model import multilinear_corpus

    corpus = multilinear_corpus(people=3)
    result = leave_one_out(corpus).to_json()
    assert result["method"] == "interaction" and len(result["cells"]) == 12
    for cell in result["cells"]:
        assert cell["synthesis_rms_deg"] == pytest.approx(cell["additive_rms_deg"], abs=1e-9)
    assert result["versus_additive"] == {"wins": 0, "losses": 0, "ties": 12,
                                         "median_difference_deg": pytest.approx(0, abs=1e-9)}


def _held_out_squared_errors(model, data):
    """Sum of squared errors of every cell predicted from the person's other cells, by the
    model and by the additive model."""
    people, actions, _ = data.shape
    cells = [(p, a) for p in range(people) for a in range(actions)]
    return (sum(np.sum((model.predict(p, a)[0] - data[p, a]) ** 2) for p, a in cells),
            sum(np.sum((model.additive(p, a) - data[p, a]) ** 2) for p, a in cells))


def test_the_shrunk_signature_does_not_lose_to_the_additive_model_on_noise():
    """Corpora whose person × action interaction is pure (heavy-tailed) noise: nothing for the
    signature to learn, and a few outlying cells to mislead it. The signature model, shrunk
    toward the additive prediction by the held-out κ of its donors, is on the whole no worse
    than the additive model (unshrunk, it is 0.4 % worse over these 20 corpora)."""
    model_error = additive_error = 0.0
    for seed in range(20):
        rng = np.random.default_rng(seed)
        data = rng.normal(0, 5, (1, 2, 30)) + rng.normal(0, 3, (8, 1, 30)) + \
            rng.standard_t(2, (8, 2, 30))
        errors = _held_out_squared_errors(InteractionModel("people", shrink=True).fit(data),
                                          data)
        model_error += errors[0]
        additive_error += errors[1]
    assert model_error <= additive_error


def test_shrinkage_keeps_a_real_interaction():
    """A rank-1 person × action interaction well above the noise: the shrunk signature keeps
    (nearly all of) the correction and predicts far better than the additive model."""
    data, rng = main_effects(people=9, actions=4, features=30)
    data = data + np.einsum("p,a,f->paf", rng.normal(size=9), rng.normal(size=4),
                            rng.normal(0, 4, 30)) + rng.normal(0, 0.3, data.shape)
    model = InteractionModel("people", shrink=True).fit(data)
    model_error, additive_error = _held_out_squared_errors(model, data)
    assert model_error < 0.25 * additive_error
    assert model.interaction(3, (0, 1, 2), 0).shrinkage > 0.8
