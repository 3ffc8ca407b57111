"""MotionModel: known answers on an exactly multilinear corpus and on the generator's corpus."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.errors import MocapError
from synthesis.evaluate import leave_one_out
from synthesis.model import MotionModel
from synthesis.model_file import load_model, save_model
from synthesis.corpus import MotionCorpus, angle_columns, load_corpus

SEGMENTS = ["pelvis", "thorax", "r_thigh", "r_shank"]


def multilinear_corpus(people=7, actions=("ascend", "descend", "run", "walk"), samples=40,
                       person_factors=2, action_factors=3, seed=0) -> MotionCorpus:
    """Angles exactly ``template_a + Z ×1 p ×2 a`` per cell; log-durations a rank-1 analogue.

    A few person factors and action factors drive smooth periodic curves; this is the
    structure the model assumes, so held-out cells must be predicted exactly.
    """
    rng = np.random.default_rng(seed)
    columns = 3 * len(SEGMENTS)
    u = np.linspace(0.0, 1.0, samples)
    person = rng.normal(size=(people, person_factors))
    action = rng.normal(size=(len(actions), action_factors))
    harmonics = rng.integers(1, 4, size=(person_factors, action_factors, columns))
    phases = rng.uniform(0, 2 * np.pi, size=(person_factors, action_factors, columns))
    amplitudes = rng.normal(0, 4.0, size=(person_factors, action_factors, columns))
    core = amplitudes[:, :, None] * np.sin(2 * np.pi * harmonics[:, :, None] * u[:, None]
                                           + phases[:, :, None])       # (P', A', samples, C)
    templates = 30 * np.sin(2 * np.pi * u[None, :, None]
                            + rng.uniform(0, 2 * np.pi, size=(len(actions), 1, columns)))
    angles = templates[None] + np.einsum("pi,aj,ijnc->panc", person, action, core)
    # Timing: a cadence-like person factor scales every action's duration by its own power.
    cadence = 0.05 * person[:, 0]
    base = np.linspace(0.7, 1.3, len(actions))
    durations = base[None] * np.exp(np.outer(cadence, rng.uniform(0.7, 1.3, len(actions))))
    return MotionCorpus(people=[f"p{k}" for k in range(people)], actions=list(actions),
                        segments=list(SEGMENTS), parents=[-1, 0, 0, 2], sequence="ZXY",
                        columns=angle_columns(SEGMENTS, "ZXY"), angles=angles,
                        durations=durations, cycle_counts=np.ones((people, len(actions)), int))


def rms(a, b):
    return float(np.sqrt(np.mean((np.asarray(a) - np.asarray(b)) ** 2)))


@pytest.fixture(scope="module")
def corpus():
    return multilinear_corpus()


def test_leave_one_out_on_an_exactly_multilinear_corpus(corpus):
    result = leave_one_out(corpus)
    assert len(result.cells) == 7 * 4 and not result.skipped
    assert result.synthesis_rms < 0.5
    assert max(c.synthesis_rms for c in result.cells) < 0.5
    assert result.recognition_accuracy == 1.0
    assert result.duration_rms < 1e-3
    assert result.baseline_rms > 10 * result.synthesis_rms


def test_fit_finds_the_person_rank_and_reconstructs_the_people(corpus):
    model = MotionModel().fit(corpus)
    assert model.angle_model_.rank == 2                # two person factors
    assert model.loo_rms < 1e-6
    for p, person in enumerate(corpus.people):
        curve, duration = model.synthesize(person, "run")
        assert rms(curve, corpus.angles[p, 2]) < 1e-6
        assert duration == pytest.approx(corpus.durations[p, 2], rel=1e-6)


def test_a_missing_cell_is_predicted_never_echoed(corpus):
    truth = corpus.angles[3, 1].copy()
    model = MotionModel().fit(corpus.without_cell("p3", "descend"))
    assert "p3" not in [model.people[i] for i in model.angle_model_.basis_people_]
    assert rms(model.synthesize("p3", "descend")[0], truth) < 0.5
    # Leave-one-out holds a cell out of everything: a corrupted capture cannot leak into its
    # own prediction, which still matches the uncorrupted truth.
    corrupted = multilinear_corpus()
    corrupted.angles[3, 1] += 50.0
    cell = [c for c in leave_one_out(corrupted).cells if (c.person, c.action) == ("p3", "descend")]
    assert rms(cell[0].synthesised, truth) < 0.5
    assert cell[0].synthesis_rms > 49.0                  # measured against the corrupted capture


def test_a_person_with_only_one_action(corpus):
    reduced = corpus
    for action in ("ascend", "descend", "run"):
        reduced = reduced.without_cell("p6", action)
    model = MotionModel().fit(reduced)
    for a, action in enumerate(corpus.actions):
        curve, duration = model.synthesize("p6", action)
        assert rms(curve, corpus.angles[6, a]) < 0.5
        assert duration == pytest.approx(corpus.durations[6, a], rel=0.01)


def test_new_person_from_a_single_trial(corpus):
    model = MotionModel().fit(corpus.subset(people=corpus.people[:6]))
    signature = model.signature_from([("walk", corpus.angles[6, 3], corpus.durations[6, 3])])
    for a, action in enumerate(corpus.actions):
        curve, duration = model.synthesize(None, action, signature=signature)
        assert rms(curve, corpus.angles[6, a]) < 0.5
        assert duration == pytest.approx(corpus.durations[6, a], rel=0.01)


def test_interpolation_between_two_people_is_linear_in_the_signature(corpus):
    model = MotionModel().fit(corpus)
    first, first_duration = model.synthesize("p0", "walk")
    second, second_duration = model.synthesize("p1", "walk")
    for weight in (0.0, 0.3, 1.0):
        curve, duration = model.synthesize(None, "walk",
                                           signature=model.interpolate("p0", "p1", weight))
        assert np.allclose(curve, (1 - weight) * first + weight * second, atol=1e-9)
        # Timing is modelled in log-duration: the blend is geometric.
        assert duration == pytest.approx(first_duration ** (1 - weight)
                                         * second_duration ** weight, rel=1e-9)


def test_recognition_of_person_and_action(corpus):
    model = MotionModel().fit(corpus)
    result = model.recognize(corpus.angles[4, 2])
    assert (result.person, result.action) == ("p4", "run")
    assert result.scores["p4"] == max(result.scores.values())
    assert sum(result.scores.values()) == pytest.approx(1.0)
    assert result.distances["p4"] < 1e-6


def test_save_and_load_round_trip(corpus, tmp_path):
    model = MotionModel(feature_rank=0.999).fit(corpus.without_cell("p2", "walk"))
    save_model(model, tmp_path / "model.npz")
    loaded = load_model(tmp_path / "model.npz")
    for name in ("people", "actions", "segments", "parents", "columns", "sequence", "samples"):
        assert getattr(loaded, name) == getattr(model, name)
    assert loaded.feature_rank == 0.999
    for person in ("p2", "p5"):
        assert np.array_equal(loaded.synthesize(person, "walk")[0],
                              model.synthesize(person, "walk")[0])
        assert loaded.synthesize(person, "walk")[1] == model.synthesize(person, "walk")[1]
    assert loaded.summary()["missing_cells"] == ["p2_walk"]
    (tmp_path / "bad.npz").write_bytes(b"not a model")
    with pytest.raises(MocapError, match="not a motion model"):
        load_model(tmp_path / "bad.npz")


def test_resampling_the_synthesised_cycle(corpus):
    model = MotionModel().fit(corpus)
    curve, _ = model.synthesize("p0", "run")
    fine, _ = model.synthesize("p0", "run", samples=79)     # 78 = 2 × 39 intervals
    assert fine.shape == (79, curve.shape[1])
    assert np.allclose(fine[::2], curve, atol=1e-12)


def test_every_person_incomplete_imputes_with_a_truncated_people_rank(corpus):
    """No complete person: missing cells are imputed with a cross-validated people rank below
    the number of people (a full rank would let the initial guess reproduce itself)."""
    holed = corpus
    for p, person in enumerate(corpus.people):
        holed = holed.without_cell(person, corpus.actions[p % 4])
    model = MotionModel().fit(holed)
    assert model.angle_model_.imputed_rank_ == 2          # the two person factors
    for p, person in enumerate(corpus.people):
        curve, duration = model.synthesize(person, corpus.actions[p % 4])
        assert rms(curve, corpus.angles[p, p % 4]) < 0.5
        assert duration == pytest.approx(corpus.durations[p, p % 4], rel=0.01)


def test_too_few_people_is_a_clear_error(corpus):
    small = corpus.subset(people=["p0", "p1"]).without_cell("p1", "run")
    with pytest.raises(MocapError, match="need at least 2 people who performed every action"):
        MotionModel().fit(small)
    with pytest.raises(MocapError, match="unknown person 'zed'"):
        MotionModel().fit(corpus).synthesize("zed", "run")


def test_generator_default_corpus_beats_the_baseline_twice(tmp_path):
    """6 people × walk/run/ascend/descend from mocap.synthetic, marker trials → synthetic15."""
    from mocap.synthetic import generate_corpus

    generate_corpus(tmp_path)
    corpus = load_corpus(tmp_path, markerset="synthetic15", sequence="ZXY")
    assert corpus.angles.shape == (6, 4, 100, 45)
    result = leave_one_out(corpus)
    assert len(result.cells) == 24
    assert result.baseline_rms >= 2.0 * result.synthesis_rms
    assert result.recognition_accuracy >= 0.9
    # Durations (cadence is a person trait) are predicted far better than by the mean.
    baseline = np.sqrt(np.mean([(np.mean(np.delete(corpus.durations[:, a], p)) - c.duration) ** 2
                                for c in result.cells
                                for p, a in [(corpus.people.index(c.person),
                                              corpus.actions.index(c.action))]]))
    assert result.duration_rms < 0.5 * baseline


@pytest.mark.parametrize("synthesis, words", [(2.0, "(3.0× lower)"),
                                              (8.0, "(synthesis 1.33× higher)")])
def test_the_summary_says_which_way_the_synthesis_differs_from_the_baseline(synthesis, words):
    from synthesis.evaluate import CellResult, Evaluation
    cell = CellResult("ana", "walk", synthesis_rms=synthesis, baseline_rms=6.0, duration=1.0,
                      predicted_duration=1.0, recognised="ana", additive_rms=5.0)
    text = Evaluation([cell], [], ["x"], method="interaction").table()
    assert f"baseline (mean of the other people) 6.00° {words}" in text
    assert "the additive model is worse than the baseline" not in text
    cell.additive_rms = 6.5
    text = Evaluation([cell], [], ["x"], method="interaction").table()
    assert "the additive model is worse than the baseline here" in text


def test_the_summary_says_what_fills_each_missing_cell(corpus):
    """Every person incomplete: too few donors everywhere, and the imputed signatures,
    vouched for by the imputation's held-out cells, fill every cell (exactly, above). One
    hole among seven people: the interaction has its donors and says its configuration."""
    holed = corpus
    for p, person in enumerate(corpus.people):
        holed = holed.without_cell(person, corpus.actions[p % 4])
    filled = MotionModel().fit(holed).summary()["missing_cells_filled_by"]
    assert sorted(filled) == sorted(f"{person}_{corpus.actions[p % 4]}"
                                    for p, person in enumerate(corpus.people))
    assert all(how.startswith("the N-mode signatures") for how in filled.values())
    one = MotionModel().fit(corpus.without_cell("p3", "run")).summary()
    assert list(one["missing_cells_filled_by"]) == ["p3_run"]
    how = one["missing_cells_filled_by"]["p3_run"]
    assert how == "the additive model" or " mode (the " in how and "), rank " in how
