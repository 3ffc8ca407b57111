"""The synthetic generator: ground truth, planted feet, signatures, corpus files."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.synthetic import (ACTIONS, MARKER_LABELS, SEGMENT_NAMES, generate_corpus,
                             make_people, person_angles, synthesize_trial, truth_angles)


def test_same_seed_same_trial_other_seed_other_trial():
    first, _ = synthesize_trial(1, "walk", seed=3, noise_mm=1.0)
    again, _ = synthesize_trial(1, "walk", seed=3, noise_mm=1.0)
    other, _ = synthesize_trial(1, "walk", seed=4, noise_mm=1.0)
    np.testing.assert_array_equal(first.points, again.points)
    assert first.points.shape != other.points.shape or not np.allclose(first.points, other.points)


@pytest.mark.parametrize("action", ACTIONS)
def test_marker_frames_recover_the_ground_truth(action):
    from mocap.frames import segment_frames
    from mocap.markerset import load_markerset

    trial, truth = synthesize_trial(2, action)
    rotations, origins = segment_frames(trial, load_markerset("synthetic15"))
    np.testing.assert_allclose(rotations, truth.segment_rotations, atol=1e-9)
    np.testing.assert_allclose(origins, truth.origins, atol=1e-12)


def test_extracted_angles_equal_ground_truth_csv(tmp_path):
    from mocap.angles import joint_angles, read_angles_csv
    from mocap.markerset import load_markerset

    files = generate_corpus(tmp_path, people=2, actions=["walk", "run"], seed=5, sequence="YXZ")
    assert [f.name for f in files] == [
        f"{p.name}_{a}.c3d" for p in make_people(2, 5) for a in ("walk", "run")]
    from mocap import io
    trial = io.read(files[1])
    assert trial.labels == list(MARKER_LABELS)
    measured = joint_angles(trial, load_markerset("synthetic15"), sequence="YXZ")
    truth = read_angles_csv(tmp_path / "truth" / files[1].name.replace(".c3d", "_angles.csv"))
    assert measured.segments == truth.segments == list(SEGMENT_NAMES)
    # C3D stores single-precision floats: 1e-7 m on 0.1 m marker spacing ~ 1e-4 degrees
    np.testing.assert_allclose(measured.values, truth.values, atol=2e-3)
    assert (tmp_path / "truth" / "people.csv").read_text().startswith("person,height_m")


def _feet(truth):
    """Contact points per foot, (frames, 2 points, 3), right then left."""
    return [np.stack([truth.contact_points[f"{side}_heel"], truth.contact_points[f"{side}_toe"]],
                     axis=1) for side in "rl"]


@pytest.mark.parametrize("action", ["walk", "run"])
@pytest.mark.parametrize("person", [0, 2, 4])
def test_stance_foot_is_planted_on_the_floor(action, person):
    _, truth = synthesize_trial(person, action, cycles=2)
    points = np.concatenate(_feet(truth), axis=1)                        # (frames, 4, 3)
    on_floor = np.abs(points[:, :, 2]) < 1e-9
    assert points[:, :, 2].min() > -1e-4                                  # never below it
    # a point on the floor in two consecutive frames has not moved
    held = on_floor[1:] & on_floor[:-1]
    slide = np.linalg.norm(points[1:] - points[:-1], axis=2)[held]
    assert held.sum() > 0.5 * len(points)
    np.testing.assert_allclose(slide, 0.0, atol=1e-9)
    supported = on_floor.any(axis=1)
    if action == "walk":
        assert supported.all()                                            # always a foot down
    else:                                                                 # short flight phases
        assert 0.1 < 1 - supported.mean() < 0.35
        assert points[~supported, :, 2].min(axis=1).max() > 0.01
    forward = truth.origins[-1, 0, 0] - truth.origins[0, 0, 0]
    assert forward > (2.0 if action == "walk" else 3.0)                   # metres in two cycles


def test_people_have_signatures_that_carry_across_actions():
    people = make_people(6, seed=0)
    phase = np.linspace(0, 1, 100, endpoint=False)
    cells = np.array([[person_angles(p, a, phase) for a in ACTIONS] for p in people])
    deviation = cells - cells.mean(axis=0, keepdims=True)                # person effect
    pairwise = np.sqrt(((cells[:, None] - cells[None]) ** 2).mean(axis=(2, 3, 4, 5)))
    assert pairwise[~np.eye(6, dtype=bool)].min() > 1.0                   # everyone is distinct
    # a person's deviation in one action predicts the sign pattern in another
    flat = deviation.reshape(6, len(ACTIONS), -1)
    correlations = [np.corrcoef(flat[p, 0], flat[p, a])[0, 1] for p in range(6) for a in (1, 2, 3)]
    assert np.median(correlations) > 0.3
    assert len({round(p.lengths["thigh"], 5) for p in people}) == 6


def test_noise_and_gaps():
    clean, _ = synthesize_trial(0, "walk", cycles=3)
    noisy, _ = synthesize_trial(0, "walk", cycles=3, noise_mm=2.0, gap_fraction=0.05)
    missing = np.isnan(noisy.points[..., 0])
    assert 0.05 <= missing.mean() < 0.07
    error = (noisy.points - clean.points)[~missing]
    assert 1.5e-3 < error.std() < 2.5e-3


def test_generate_command_writes_corpus_and_rejects_bad_options(tmp_path, capsys):
    from mocap.cli import main

    assert main(["generate", str(tmp_path / "c"), "--people", "2", "--actions", "walk,descend",
                 "--format", "trc"]) == 0
    assert sorted(p.name for p in (tmp_path / "c").glob("*.trc")) == sorted(
        f"{p.name}_{a}.trc" for p in make_people(2) for a in ("walk", "descend"))
    assert main(["generate", str(tmp_path / "d"), "--actions", "walk,swim"]) == 2
    assert "swim" in capsys.readouterr().err
    assert not (tmp_path / "d").exists() or not any((tmp_path / "d").glob("*.c3d"))
