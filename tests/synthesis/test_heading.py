"""Euler (marker) corpora are heading-free: a trial turned about the lab vertical gives the
same features (synthesis.rotations.remove_mean_heading, through the corpus and the model)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocap.errors import MocapError
from mocap.io import read
from mocap.io.angles_csv import write_angles_csv
from mocap.markersets import load_markerset
from mocap.pipeline import marker_file_angles
from mocap.synthetic import synthesize_trial
from synthesis.corpus import CorpusEntry, corpus_from_angles, read_trial_angles
from synthesis.model import MotionModel
from synthesis.model_file import load_model, save_model
from synthesis.rotations import LAB_UP, hierarchy_known, mean_heading, remove_mean_heading
from tests.conftest import realdata_path


def turned(trial, degrees: float):
    """The trial with every marker turned by ``degrees`` about the lab's vertical (Z)."""
    turn = Rotation.from_euler("z", degrees, degrees=True).as_matrix()
    return replace(trial, points=np.einsum("ij,fmj->fmi", turn, trial.points))


def corpus_of(trials, markerset, **options):
    """Cells ana/ben × walk/other: ben's trials are ana's, turned by 180° about the vertical."""
    cells = [("ana", "walk", trials[0]), ("ana", "other", trials[1]),
             ("ben", "walk", turned(trials[0], 180.0)), ("ben", "other", turned(trials[1], 180.0))]
    read_angles = [(CorpusEntry(trial.path or f"{person}_{action}", person, action),
                    marker_file_angles(trial, markerset).angles)
                   for person, action, trial in cells]
    return corpus_from_angles(read_angles, samples=40, **options)


@pytest.fixture(scope="module")
def synthetic15():
    return load_markerset("synthetic15")


@pytest.fixture(scope="module")
def generated(synthetic15):
    """Two generated walks of different people (a Z-up lab, walking along +X)."""
    return [synthesize_trial(0, "walk")[0], synthesize_trial(1, "walk")[0]]


def test_a_generated_trial_turned_by_half_a_turn_has_the_same_features(generated, synthetic15):
    corpus = corpus_of(generated, synthetic15)
    assert corpus.heading_removed
    ana, ben = corpus.people.index("ana"), corpus.people.index("ben")
    np.testing.assert_allclose(corpus.angles[ben], corpus.angles[ana], atol=1e-9)
    # the same corpus with the heading kept: the pelvis faces the other way
    kept = corpus_of(generated, synthetic15, remove_heading=False)
    assert not kept.heading_removed
    pelvis = kept.columns.index("pelvis.Z")
    gap = np.abs(kept.angles[ben, :, :, pelvis] - kept.angles[ana, :, :, pelvis])
    assert np.allclose(gap, 180.0, atol=1e-6)


def test_the_heading_removed_is_the_mean_and_any_turn_leaves_the_rest(generated, synthetic15):
    angles = marker_file_angles(generated[0], synthetic15).angles
    free = remove_mean_heading(angles)
    pelvis = angles.segments.index("pelvis")
    world = Rotation.from_euler(angles.sequence, free.values[:, pelvis], degrees=True)
    assert mean_heading(world.as_matrix(), LAB_UP) == pytest.approx(0.0, abs=1e-9)
    # joints relative to a parent do not change; within-trial pelvic rotation stays
    np.testing.assert_array_equal(free.values[:, pelvis + 1:], angles.values[:, pelvis + 1:])
    assert np.ptp(free.values[:, pelvis, 0]) == pytest.approx(np.ptp(angles.values[:, pelvis, 0]),
                                                              abs=1e-6)
    for degrees in (37.0, -120.0):
        again = remove_mean_heading(marker_file_angles(turned(generated[0], degrees),
                                                       synthetic15).angles)
        np.testing.assert_allclose(again.values, free.values, atol=1e-9)


def test_a_model_turns_a_new_trial_as_its_corpus_and_keeps_that_in_its_file(
        generated, synthetic15, tmp_path):
    corpus = corpus_of(generated, synthetic15)
    model = MotionModel().fit(corpus)
    assert model.summary()["heading_removed"]
    save_model(model, tmp_path / "model.npz")
    loaded = load_model(tmp_path / "model.npz")
    assert loaded.heading_removed
    ana, walk = corpus.people.index("ana"), corpus.actions.index("walk")
    curve, _ = loaded.normalise(marker_file_angles(turned(generated[0], 90.0),
                                                   synthetic15).angles)
    np.testing.assert_allclose(curve, corpus.angles[ana, walk], atol=1e-9)
    # a trial whose root cannot be told (every parent -1) cannot be turned: refused
    angles = marker_file_angles(generated[0], synthetic15).angles
    with pytest.raises(MocapError, match="hierarchy is unknown"):
        loaded.normalise(replace(angles, parents=[-1] * len(angles.segments)))


def test_an_angle_csv_takes_the_hierarchy_of_its_marker_set(generated, synthetic15, tmp_path):
    angles = marker_file_angles(generated[0], synthetic15).angles
    write_angles_csv(angles, tmp_path / "ana_walk.csv")
    without = read_trial_angles(tmp_path / "ana_walk.csv")
    assert not hierarchy_known(without)                    # every parent -1: no root known
    with_set = read_trial_angles(tmp_path / "ana_walk.csv", "synthetic15")
    assert with_set.parents == list(synthetic15.parent_index) and hierarchy_known(with_set)


def test_a_real_walk_turned_by_half_a_turn_has_the_same_features():
    """HC036A walked the other way through the lab (pelvis heading −93° where the other
    subjects' straight walks are at +87…+96°)."""
    markerset = load_markerset("plugingait-lower")
    walk = read(realdata_path("biomechzoo_sample_study", "HC036A", "Straight", "HC036A10.c3d"))
    turn = read(realdata_path("biomechzoo_sample_study", "HC036A", "Turn", "HC036A23.c3d"))
    corpus = corpus_of([walk, turn], markerset)
    ana, ben = corpus.people.index("ana"), corpus.people.index("ben")
    np.testing.assert_allclose(corpus.angles[ben], corpus.angles[ana], atol=1e-6)
    pelvis = corpus.columns.index("pelvis.Z")
    # the straight walk's pelvis now faces the lab's +X: mean heading 0 (it was −93°)
    assert abs(np.mean(corpus.angles[ana, corpus.actions.index("walk"), :, pelvis])) < 5.0
