"""synthesis.methods: every registered method behind one interface; the CLI's --method is the
registry; a saved model refits its method from the stored cells and answers the same."""
from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from mocap.cli import main
from mocap.errors import MocapError
from synthesis.interaction import InteractionModel
from synthesis.methods import METHODS, CellMethod, make_method, method_name
from synthesis.model import MotionModel
from synthesis.model_file import load_model, save_model
from synthesis.recognition import (distances, donor_distances, held_out_distances, match_scale,
                                   moderated_variances, recognition_weights, unknown_limit)
from tests.synthesis.test_model import multilinear_corpus

ROOT = Path(__file__).resolve().parents[2]


def cells(people=8, actions=4, features=30, seed=1):
    """Main effects plus a rank-1 people × actions interaction: the full tensor and a copy
    with two cells missing (shape (people, actions, features))."""
    rng = np.random.default_rng(seed)
    full = (rng.normal(0, 10, (1, actions, features)) + rng.normal(0, 5, (people, 1, features))
            + np.einsum("p,a,f->paf", rng.normal(size=people), rng.normal(size=actions),
                        rng.normal(0, 4, features)))
    data = full.copy()
    data[1, 2] = np.nan
    data[4, 0] = np.nan
    return full, data


@pytest.fixture(scope="module")
def fitted():
    full, data = cells()
    return full, data, {name: make_method(name).fit(data) for name in METHODS}


def test_registry_names_and_auto():
    assert set(METHODS) == {"interaction", "signature", "transfer"}
    assert method_name("auto") == "interaction"
    assert all(issubclass(method, CellMethod) and method.name == name
               for name, method in METHODS.items())
    with pytest.raises(MocapError, match="interaction, signature, transfer"):
        make_method("nmode")


@pytest.mark.parametrize("name", sorted(METHODS))
def test_every_method_answers_the_interface(fitted, name):
    _, data, methods = fitted
    method = methods[name]
    keep = np.isfinite(data).all(axis=2)
    # Captured cells come back as they are; missing ones are predicted, finite.
    assert np.array_equal(method.cell(0, 1), data[0, 1])
    assert np.isfinite(method.cell(1, 2)).all() and np.isfinite(method.cell(4, 0)).all()
    # The additive prediction of a missing cell: the action's mean over the other people plus
    # the person's mean offset from those means.
    person, action = 1, 2
    others = keep.copy()
    others[person] = False
    means = np.array([data[others[:, a], a].mean(axis=0) for a in range(data.shape[1])])
    observed = [a for a in range(data.shape[1]) if a != action and keep[person, a]]
    expected = means[action] + np.mean([data[person, a] - means[a] for a in observed], axis=0)
    assert np.allclose(method.additive(person, action), expected, atol=1e-12)
    # Recognition templates: where someone's cell of the action is missing, a captured cell
    # is modelled from the person's other cells and never echoes the capture; where every
    # person captured the action, the captures themselves.
    assert not keep[:, 2].all() and keep[0, 2] and keep[:, 1].all()
    assert not np.allclose(method.template(0, 2), data[0, 2])
    assert np.array_equal(method.template(0, 1), data[0, 1])
    variance, donors = method.feature_variance(1)
    assert variance.shape == (data.shape[2],) and (variance > 0).all()
    # ... averaged over the people who have every action (the donors of action 1).
    assert donors == int(keep.all(axis=1).sum())


def test_the_interaction_methods_beat_the_additive_model_on_a_rank_one_interaction(fitted):
    full, _, methods = fitted
    for name in ("interaction", "signature"):
        method = methods[name]
        for person, action in [(1, 2), (4, 0)]:
            error = np.abs(method.cell(person, action) - full[person, action]).mean()
            additive = np.abs(method.additive(person, action) - full[person, action]).mean()
            assert error < 0.5 * additive, (name, person, action)


@pytest.mark.parametrize("name", ["interaction", "transfer"])
def test_a_saved_model_refits_its_method_and_answers_the_same(tmp_path, name):
    corpus = multilinear_corpus(people=6).without_cell("p2", "run")
    model = MotionModel(method=name).fit(corpus)
    save_model(model, tmp_path / "model.npz")
    again = load_model(tmp_path / "model.npz")
    assert type(again.cells_) is METHODS[name] and again.method_ == name
    for person in ("p2", "p4"):
        first, second = model.synthesize(person, "run"), again.synthesize(person, "run")
        assert np.array_equal(first[0], second[0]) and first[1] == second[1]
    assert again.recognize(corpus.angles[4, 1]).distances == \
        model.recognize(corpus.angles[4, 1]).distances


def test_the_cli_offers_exactly_the_registry(capsys):
    assert main(["evaluate", "--method", "nmode", "--leave-one-out", "x"]) == 2
    message = capsys.readouterr().err
    assert all(f"'{name}'" in message for name in ("auto",) + tuple(METHODS))


def test_models_and_methods_never_read_files():
    """Only the loaders (corpus, model_file, skeletons' trial reading) import the readers."""
    for module in ("model", "methods", "recognition", "interaction", "transfer",
                   "regression", "signature", "nmode", "evaluate"):
        tree = ast.parse((ROOT / "synthesis" / f"{module}.py").read_text())
        imported = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
        imported |= {alias.name for node in ast.walk(tree) if isinstance(node, ast.Import)
                     for alias in node.names}
        assert not any(name.startswith("mocap.io") for name in imported), module
        assert "synthesis.model_file" not in imported, module
        calls = {getattr(node.func, "id", getattr(node.func, "attr", None))
                 for node in ast.walk(tree) if isinstance(node, ast.Call)}
        assert not calls & {"open", "load", "read_text", "read_motion", "read_npz"}, module


def test_the_signature_method_recognises_by_the_persons_main_effects(fitted):
    """Signature recognition templates of actions someone lacks are the person's additive
    prediction from their other actions (mean of the others + the person's mean offset),
    computed here by hand; its synthesis of a missing cell keeps the interaction's
    correction."""
    _, data, methods = fitted
    method = methods["signature"]
    for person, action in [(0, 2), (6, 0)]:
        assert np.isfinite(data[person, action]).all()
        assert not np.isfinite(data[:, action]).all()
        others = [q for q in range(data.shape[0]) if q != person]
        means = np.nanmean(data[others], axis=0)
        offset = np.mean([data[person, a] - means[a] for a in range(data.shape[1])
                          if a != action and np.isfinite(data[person, a]).all()], axis=0)
        assert np.allclose(method.template(person, action), means[action] + offset)
    assert not np.allclose(method.cell(1, 2), method.additive(1, 2))


def test_recognition_distance_is_the_weighted_mean_absolute_difference(fitted):
    """A trial's distance to a person is ``mean_f |x_f − t_f| √(w_f / mean w)`` (t: that
    person's template, w: the action's weights), computed here by hand; and one feature
    missed by far does not outweigh a small miss everywhere, as it would in an RMS."""
    _, data, methods = fitted
    method = methods["interaction"]
    action = 1
    weights = recognition_weights(method, action)
    assert weights is not None and weights.shape == (data.shape[2],)
    trial = method.template(3, action) + np.linspace(-2.0, 2.0, data.shape[2])
    table = distances(method, trial[None], [action])
    for person in range(data.shape[0]):
        difference = np.abs(method.template(person, action) - trial)
        expected = np.mean(difference * np.sqrt(weights / weights.mean()))
        assert table[person, action] == pytest.approx(expected, rel=1e-12)
    assert np.isnan(table[:, [0, 2, 3]]).all()
    # One feature missed by 20° is nearer than every feature missed by 2°; an RMS would
    # have it the other way round.
    scale = np.sqrt(weights / weights.mean())
    near = method.template(0, action)
    outlier = near.copy()
    outlier[0] += 20.0 / scale[0]
    spread = near + 2.0 / scale
    assert distances(method, outlier[None], [action])[0, action] == \
        pytest.approx(20.0 / data.shape[2])
    assert distances(method, spread[None], [action])[0, action] == pytest.approx(2.0)
    assert 20.0 / np.sqrt(data.shape[2]) > 2.0          # the outlier's RMS distance


def _means_without(data, keep, person):
    """Action means over the people other than ``person`` who have each action."""
    others = [q for q in range(data.shape[0]) if q != person]
    return np.array([data[[q for q in others if keep[q, a]], a].mean(axis=0)
                     for a in range(data.shape[1])])


@pytest.mark.parametrize("name", sorted(METHODS))
def test_a_trial_is_as_near_as_the_persons_nearest_template(fitted, name):
    """For an action someone lacks (templates modelled from other actions), a person's
    templates are the method's template and the additive prediction from each of their
    other actions alone, ``m_b + d_{p,a} − m_a`` (means over the other people); each is
    measured against its own spread — the method's, ``1 / √w``, or the view's, from the
    donors' held-out view errors moderated alike — as
    ``ŝ [mean |x − t| / s_t + mean log(s_t / s)]``, and the distance is to the nearest; all
    by hand. A trial equal to one of person 3's views is recognised as person 3, through
    that view rather than their template. For an action everyone captured, the capture is the only
    template and the distance is the weighted mean absolute difference."""
    _, data, methods = fitted
    method = methods[name]
    keep = np.isfinite(data).all(axis=2)
    people, actions = keep.shape
    action = 2
    assert not keep[:, action].all()
    for person in (0, 1, 4):             # captured; the missing cell; one other action missing
        means = _means_without(data, keep, person)
        sources = [a for a in range(actions) if a != action and keep[person, a]]
        templates, found = method.templates(person, action)
        assert found == [None] + sources
        assert np.array_equal(templates[0], method.template(person, action))
        assert np.allclose(templates[1:], [means[action] + data[person, a] - means[a]
                                           for a in sources], rtol=1e-12, atol=1e-10)
    donors = [q for q in range(people) if keep[q].all()]
    spreads = {None: 1.0 / np.sqrt(recognition_weights(method, action))}
    for a in range(actions):
        if a != action:
            errors = np.array([_means_without(data, keep, q)[action] + data[q, a]
                               - _means_without(data, keep, q)[a] - data[q, action]
                               for q in donors])
            spreads[a] = np.sqrt(moderated_variances((errors ** 2).mean(axis=0),
                                                     len(donors)))
    unit = 1.0 / np.sqrt(np.mean(spreads[None] ** -2.0))

    def by_hand(trial, person):
        templates, sources = method.templates(person, action)
        return min(unit * (np.mean(np.abs(trial - t) / spreads[source])
                           + np.mean(np.log(spreads[source] / spreads[None])))
                   for t, source in zip(templates, sources))

    templates, sources = method.templates(3, action)
    trial = templates[1]
    table = distances(method, trial[None], [action])
    for person in range(people):
        assert table[person, action] == pytest.approx(by_hand(trial, person), rel=1e-10)
    assert np.nanargmin(table[:, action]) == 3
    scale = np.sqrt(recognition_weights(method, action) / recognition_weights(method,
                                                                             action).mean())
    assert np.mean(np.abs(method.template(3, action) - trial) * scale) > table[3, action]
    for p in range(people):
        assert np.array_equal(method.templates(p, 1)[0], data[p, 1][None])


@pytest.mark.parametrize("name", sorted(METHODS))
def test_a_view_that_is_the_template_is_not_a_second_template(name):
    """Two actions: a person with one other action whose template is their main effects has
    one template (their one view is the same motion), in a trial's problem and in the
    donors' problems; the person whose cell is missing keeps the view beside the synthesis
    when the two differ."""
    full, _ = cells(people=8)
    data = full[:, :2].copy()
    data[5, 1] = np.nan
    method = make_method(name).fit(data)
    single = 0
    for person in range(8):
        templates, sources = method.templates(person, 1)
        if person == 5:
            views, _ = method.additive_views(5, 1)
            expected = [None] if np.array_equal(views[0], templates[0]) else [None, 0]
            assert sources == expected
        elif np.array_equal(templates[0], method.additive(person, 1)):
            assert sources == [None] and templates.shape[0] == 1
            single += 1
        else:
            assert sources == [None, 0]
    # The interaction's templates of a person with one other action are their main effects.
    if name in ("interaction", "signature"):
        assert single == 7
    captures, held_out = method.held_out_templates(1)
    for q, template in zip(method.held_out_donors(1), held_out):
        rows, sources = method.beside_views(template, q, 1)
        if np.array_equal(template, method.additive(q, 1)):
            assert sources == [None]


@pytest.mark.parametrize("name", sorted(METHODS))
def test_recognition_weights_are_the_inverse_moderated_variances(fitted, name):
    """Each method's recognition weights: the inverse of its leave-one-person-out variances
    moderated with as many degrees of freedom as it had donors."""
    _, data, methods = fitted
    method = methods[name]
    variance, donors = method.template_variance(0)
    assert donors >= 3
    if name != "signature":             # templates are the method's own predictions
        assert all(np.array_equal(a, b) for a, b in zip((variance, donors),
                                                        method.feature_variance(0)))
    weights = recognition_weights(method, 0)
    assert np.allclose(weights, 1.0 / moderated_variances(variance, donors), rtol=1e-12)
    # Moderation pulls the variances together: the weights spread less than the raw inverse.
    assert np.ptp(np.log(weights)) < np.ptp(np.log(1.0 / variance))


def test_main_effect_templates_are_measured_against_their_own_errors(fitted):
    """Where recognition models a captured cell by the person's main effects (the signature,
    always), its weights are the main effects' own held-out errors, by hand: each donor's
    action mean plus their mean offset, the means formed without that donor."""
    _, data, methods = fitted
    method = methods["signature"]
    keep = np.isfinite(data).all(axis=2)
    action = 2
    donors = method.held_out_donors(action)
    errors = []
    for q in donors:
        pool = keep & (np.arange(len(data)) != q)[:, None]
        means = np.array([data[pool[:, a], a].mean(axis=0) for a in range(data.shape[1])])
        others = [a for a in range(data.shape[1]) if a != action and keep[q, a]]
        predicted = means[action] + np.mean(data[q, others] - means[others], axis=0)
        errors.append(predicted - data[q, action])
    errors = np.array(errors)
    assert np.allclose(method.template_errors(action), errors, atol=1e-9)
    variance, dof = method.template_variance(action)
    assert dof == len(donors) and np.allclose(variance, (errors ** 2).mean(axis=0))
    assert np.allclose(recognition_weights(method, action),
                       1.0 / moderated_variances(variance, dof), rtol=1e-12)
    # Not the spread of the signature's own prediction, which is never a template here.
    assert not np.allclose(variance, method.feature_variance(action)[0])


@pytest.mark.parametrize("name", sorted(METHODS))
def test_held_out_errors_are_those_of_the_variances(fitted, name):
    _, data, methods = fitted
    method = methods[name]
    errors = method.held_out_errors(2)
    variance, donors = method.feature_variance(2)
    assert errors.shape == (donors, data.shape[2])
    assert np.allclose((errors ** 2).mean(axis=0), variance, rtol=1e-10)


def test_score_scale_and_unknown_limit_by_hand(fitted):
    """For an action everyone captured: half the median distance from a capture to the
    nearest other person's, both the scores' scale and the limit beyond which a trial is
    nobody known. For one someone lacks: each donor's held-out error, weighted by the other
    donors' errors alone; its median is the scale, its largest the limit."""
    _, data, methods = fitted
    method = methods["interaction"]
    keep = np.isfinite(data).all(axis=2)
    assert keep[:, 1].all() and not keep[:, 2].all()
    nearest = []
    for p in range(data.shape[0]):
        row = distances(method, data[p, 1][None], [1])[:, 1]
        row[p] = np.nan
        nearest.append(np.nanmin(row))
    assert match_scale(method, 1) == pytest.approx(0.5 * np.median(nearest), rel=1e-12)
    assert unknown_limit(method, 1) == match_scale(method, 1)
    errors = method.held_out_errors(2)
    captures, _ = method.held_out_templates(2)
    by_hand = []
    for k, donor in enumerate(method.held_out_donors(2)):
        rest = np.delete(errors, k, axis=0)
        weights = 1.0 / moderated_variances((rest ** 2).mean(axis=0), rest.shape[0])
        scale = np.sqrt(weights / weights.mean())
        # The nearest of the donor's held-out template and their single-action views,
        # each against the spread of the other donors' errors of its kind.
        own = np.sqrt(moderated_variances((rest ** 2).mean(axis=0), rest.shape[0]))
        views, sources = method.additive_views(donor, 2)
        _, view_errors = method.view_errors(2)
        candidates = [np.mean(np.abs(errors[k]) * scale)]
        for view, e in zip(views, view_errors):
            spread = np.sqrt(moderated_variances((np.delete(e, k, axis=0) ** 2).mean(axis=0),
                                                 rest.shape[0]))
            candidates.append(np.mean(np.abs(view - captures[k]) / spread + np.log(spread / own))
                              / np.sqrt(np.mean(own ** -2.0)))
        by_hand.append(min(candidates))
    assert np.allclose(held_out_distances(method, 2), by_hand, rtol=1e-12)
    assert match_scale(method, 2) == pytest.approx(np.median(by_hand), rel=1e-12)
    assert unknown_limit(method, 2) == pytest.approx(max(by_hand), rel=1e-12)


@pytest.mark.parametrize("name", sorted(METHODS))
def test_held_out_templates_are_the_donors_modelled_as_recognition_models_them(fitted, name):
    """The donors' templates for calibrating scores: for the signature (whose recognition
    templates are a person's main effects), each donor's additive prediction with the means
    taken without them, by hand; for the others, their held-out prediction, capture +
    held-out error."""
    _, data, methods = fitted
    method = methods[name]
    captures, templates = method.held_out_templates(2)
    keep = np.isfinite(data).all(axis=2)
    donors = [q for q in range(data.shape[0]) if keep[q].all()]
    assert np.array_equal(captures, data[donors, 2])
    if name == "signature":
        by_hand = []
        for q in donors:
            others = keep.copy()
            others[q] = False
            means = np.array([data[others[:, a], a].mean(axis=0) for a in range(4)])
            offset = np.mean([data[q, a] - means[a] for a in (0, 1, 3)], axis=0)
            by_hand.append(means[2] + offset)
        assert np.allclose(templates, by_hand, rtol=1e-10, atol=1e-10)
    else:
        assert np.allclose(templates - captures, method.held_out_errors(2), atol=1e-10)
    # The donors' own recognition problems: the diagonal is the held-out distance.
    table = donor_distances(method, 2)
    assert table.shape == (len(donors), len(donors))
    assert np.array_equal(np.diagonal(table), held_out_distances(method, 2))


def test_additive_errors_and_held_out_comparison_by_hand():
    """The additive model's held-out error of a cell (means without the person, the offset
    from their other cells) and the per-action comparison, against a hand computation."""
    from synthesis.imputation import additive_errors, held_out_by_action
    data = np.array([[[1.0], [2.0], [4.0]],
                     [[3.0], [3.0], [np.nan]],
                     [[5.0], [7.0], [6.0]]])
    observed = np.isfinite(data).all(axis=2)
    # Person 0, action 2 from actions 0 and 1: means without person 0 are 4, 5 and 6.
    # Offsets −3 and −3, so the prediction is 6 − 3 = 3 and the error (3 − 4)² = 1.
    # Person 1 has no cell of action 2 here, so it never enters action 2's mean.
    errors = additive_errors(data, observed, [(0, 2), (2, 0), (1, 2)])
    assert errors[0] == pytest.approx(1.0)
    # Person 2, action 0 from actions 1 and 2: means without person 2 are 2, 2.5 and 4;
    # offsets 4.5 and 2, prediction 2 + 3.25 = 5.25, error 0.0625.
    assert errors[1] == pytest.approx(0.0625)
    assert np.isnan(errors[2])                     # a cell to predict needs its capture
    table = held_out_by_action(np.array([0, 0, 2]), np.array([1.0, 9.0, 4.0]),
                               np.array([4.0, 1.0, 1.0]), 3)
    assert np.allclose(table[:, 0], [np.sqrt(5.0), np.sqrt(2.5), 0.5, 2])
    assert np.isnan(table[:, 1]).all()
    assert np.allclose(table[:, 2], [2.0, 1.0, 0.0, 1])
    robust = held_out_by_action(np.array([0, 0, 0]), np.array([1.0, 4.0, 100.0]),
                                np.array([9.0, 9.0, 9.0]), 1, robust=True)
    assert np.allclose(robust[:, 0], [2.0, 3.0, 2 / 3, 3])


def test_posture_views_are_the_offsets_averaged_over_the_cycle():
    """With curves of ``samples`` frames, each single-action view comes with its posture view:
    the action mean (over the other people) plus the view's offset from it averaged over the
    cycle, by hand; without ``samples`` there are none."""
    _, data = cells(features=30)
    samples = 10
    method = make_method("interaction").fit(data, samples=samples)
    plain = make_method("interaction").fit(data)
    person, action = 0, 2
    views, sources = method.additive_views(person, action)
    alone, alone_sources = plain.additive_views(person, action)
    count = len(alone_sources)
    assert count == 3 and sources == alone_sources + [("posture", a) for a in alone_sources]
    assert np.array_equal(views[:count], alone)
    keep = np.isfinite(data).all(axis=2)
    others = keep[:, action] & (np.arange(len(data)) != person)
    mean = data[others, action].mean(axis=0).reshape(samples, -1)
    for view, posture in zip(alone, views[count:]):
        offset = (view.reshape(samples, -1) - mean).mean(axis=0)
        assert np.allclose(posture.reshape(samples, -1), mean + offset, atol=1e-12)
    with pytest.raises(MocapError, match="not curves of 7 samples"):
        make_method("interaction").fit(data, samples=7)


@pytest.mark.parametrize("seed", [0, 1])
def test_a_style_that_is_a_posture_is_recognised_in_an_action_never_seen(seed):
    """People who differ by a posture held in every action (sd 2°) under a time course of
    their own in each action (sd 6° per frame, zero mean over the cycle): the course of one
    action says nothing about another's, the posture does. Every cell held out in turn and
    recognised among the eight people: with posture views 22–24 of 24, without 7–16."""
    rng = np.random.default_rng(seed)
    people, actions, samples, columns = 8, 3, 20, 6
    course = rng.normal(0, 6, (people, actions, samples, columns))
    course -= course.mean(axis=2, keepdims=True)
    data = (rng.normal(0, 10, (1, actions, samples, columns))
            + rng.normal(0, 2, (people, 1, 1, columns)) + course).reshape(people, actions, -1)
    named = {None: 0, samples: 0}
    for p in range(people):
        for b in range(actions):
            held = data.copy()
            held[p, b] = np.nan
            for count in named:
                method = make_method("interaction").fit(held, samples=count)
                named[count] += int(np.argmin(distances(method, data[p, b][None], [b])[:, b]) == p)
    assert named[samples] >= 0.9 * people * actions > named[None]


def test_the_default_fills_a_cell_by_the_ridge_map_where_a_fraction_of_the_offset_carries():
    """Half of every person's offset in the first action and a quarter of their offset in
    the second carry into the third: the default (its selection includes the ridge map
    across actions) fills the missing cell exactly, says what filled it, and describes the
    map by those weights; the signature (the N-mode SVD alone, no map) and the additive model
    do not reach it."""
    rng = np.random.default_rng(11)
    first, second = rng.normal(0, 5, (2, 8, 40))
    data = rng.normal(0, 10, (1, 3, 40)) + np.stack([first, second,
                                                     0.5 * first + 0.25 * second], axis=1)
    masked = data.copy()
    masked[2, 2] = np.nan
    default = make_method("auto").fit(masked)
    assert default.filled_by(2, 2) == "the ridge map across actions"
    assert np.abs(default.cell(2, 2) - data[2, 2]).max() < 1e-9 * np.abs(data).max()
    additive = np.sqrt(np.mean((default.additive(2, 2) - data[2, 2]) ** 2))
    signature = make_method("signature").fit(masked)
    assert np.sqrt(np.mean((signature.cell(2, 2) - data[2, 2]) ** 2)) > 0.1 * additive > 0.1
    described = make_method("auto").fit(data).describe()[2]
    assert described["mode"] == "regression"
    assert list(described["map_weights"]) == [0, 1]
    assert np.allclose(list(described["map_weights"].values()), [0.5, 0.25], atol=1e-9)


def test_the_signature_fills_a_cell_by_the_person_basis_where_the_interaction_is_action_mode():
    """Cells ``μ_a + α_p + v_a c_p`` (a rank-1 action-mode interaction, no noise): the
    signature method, which chooses between the N-mode SVD's two modes, fills the held-out
    cell by the person basis exactly; the people mode alone (the signature before the twelfth
    round of docs/synthesis.md) is more than ten times further off."""
    rng = np.random.default_rng(2)
    people, actions, features = 8, 5, 60
    v = np.array([2.0, -1.0, 1.5, -0.5, -2.0])
    data = rng.normal(0, 10, (1, actions, features)) + rng.normal(0, 5, (people, 1, features)) \
        + v[None, :, None] * rng.normal(0, 4, (people, 1, features))
    masked = data.copy()
    masked[3, 2] = np.nan
    signature = make_method("signature").fit(masked)
    assert signature.filled_by(3, 2).startswith("action mode (the person basis), rank")
    error = np.sqrt(np.mean((signature.cell(3, 2) - data[3, 2]) ** 2))
    assert error < 1e-6 * np.abs(data).max()
    people_only = InteractionModel("people", shrink=True).fit(masked)
    assert np.sqrt(np.mean((people_only.predict(3, 2)[0] - data[3, 2]) ** 2)) > 10 * error
