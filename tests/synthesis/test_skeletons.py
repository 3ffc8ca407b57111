"""Skeleton corpora from the small real files in tests/data (ASF/AMC and BVH)."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.cli import main
from synthesis.corpus import load_corpus
from synthesis.cycles import CycleWarning
from synthesis.rotations import body_root, feature_joints, heading_split, root_features, \
    root_path

DATA = __import__("pathlib").Path(__file__).resolve().parents[1] / "data"


def manifest(tmp_path, path, people=("ann", "bob"), actions=("dance", "hop")):
    rows = ["path,person,action"] + [f"{path},{p},{a}" for p in people for a in actions]
    out = tmp_path / "manifest.csv"
    out.write_text("\n".join(rows) + "\n")
    return out


def test_amc_corpus_on_the_rig_with_wrap_free_features(tmp_path):
    corpus = load_corpus(manifest=manifest(tmp_path, DATA / "cmu_lambada.amc"), samples=30)
    assert corpus.representation == "rotvec" and not corpus.rig["on_body"]
    assert corpus.segments[0] == "root" and "lfemur" in corpus.segments
    assert corpus.angles.shape[:3] == (2, 2, 30) and np.isfinite(corpus.angles).all()
    # The same file in every cell: every cell equal, and the mean rotations make it small.
    assert np.allclose(corpus.angles, corpus.angles[0, 0])
    assert np.abs(corpus.angles).max() < 180.0


def test_a_trial_without_cycles_is_used_whole_with_a_warning(tmp_path):
    bvh = DATA / "mocapbank_walk.bvh"
    with pytest.warns(CycleWarning):
        corpus = load_corpus(manifest=manifest(tmp_path, bvh), samples=20, cycles=True)
    assert corpus.cycle_counts.min() >= 1 and np.isfinite(corpus.durations).all()


def test_heading_split_and_root_path_invert_each_other():
    times = np.linspace(0.0, 2.0, 201)
    heading = 0.8 * np.sin(times)                               # radians, turning
    from scipy.spatial.transform import Rotation

    from synthesis.rotations import yaw_matrices
    tilt = Rotation.from_euler("x", 10.0 * np.sin(3 * times)[:, None], degrees=True).as_matrix()
    world = yaw_matrices(heading) @ tilt
    found, rest = heading_split(world)
    assert np.allclose(found, heading) and np.allclose(rest, tilt)
    path = np.column_stack([np.cos(times), 0.9 + 0.02 * np.sin(5 * times), np.sin(2 * times)])
    features = root_features(times, heading, path)
    again_heading, again = root_path(times, features, heading0=heading[0], start=path[0])
    assert np.allclose(again_heading, heading, atol=1e-4)
    assert np.allclose(again, path, atol=2e-3)


def test_body_root_below_a_static_root():
    assert body_root([-1, 0, 1, 1, 1]) == 1
    assert feature_joints([-1, 0, 1, 1, 2]) == [1, 2, 3, 4]


def test_bad_inputs_are_one_line_exit_2(tmp_path, capsys):
    listed = manifest(tmp_path, DATA / "cmu_lambada.amc")
    assert main(["evaluate", "--manifest", str(listed), "--leave-one-out",
                 "--hold-out", "take"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "--hold-out take needs several takes" in err[-1]
    model = tmp_path / "m.npz"
    assert main(["decompose", "--manifest", str(listed), "-o", str(model)]) == 0
    capsys.readouterr()
    assert main(["recognize", str(model), str(DATA / "mocapbank_walk.bvh")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "mocapbank_walk.bvh" in err[0] and "differs from the model" in err[0]


def test_unregister_moves_the_mid_cycle_event_to_the_persons_phase():
    from synthesis.skeletons import unregister_cycle

    samples = 101
    registered = np.linspace(0.0, 1.0, samples)[:, None]       # value = registered phase
    out = unregister_cycle(registered, 0.5, 0.6)
    # At 60 % of the real cycle the registered phase is 0.5 (the event), ends fixed.
    assert np.isclose(out[60, 0], 0.5) and out[0, 0] == 0.0 and out[-1, 0] == 1.0
    assert np.all(np.diff(out[:, 0]) > 0)
    assert np.allclose(unregister_cycle(registered, 0.5, 0.5), registered)
