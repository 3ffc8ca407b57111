"""Corpus → tensor: names, manifests, angle CSVs, BVH and marker corpora, missing cells."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.rotations.angles import JointAngles
from mocap.io.angles_csv import write_angles_csv
from mocap.errors import MocapError
from mocap.io.discovery import is_angle_csv, parse_trial_name
from synthesis.corpus import (angle_columns, list_corpus_folder, load_corpus,
                              read_manifest)


def write_cycle(path, values, duration, segments=("pelvis", "r_thigh")):
    """Angle CSV of ``values`` (frames, segments·3) spanning ``duration`` seconds."""
    frames = values.shape[0]
    angles = JointAngles(times=np.linspace(0.0, duration, frames),
                         values=values.reshape(frames, len(segments), 3),
                         segments=list(segments), sequence="ZXY", parents=[-1, 0])
    write_angles_csv(angles, path)


def test_trial_names():
    assert parse_trial_name("x/ana_walk.c3d") == ("ana", "walk")
    assert parse_trial_name("ana_walk_trial3.trc") == ("ana", "walk")
    with pytest.raises(MocapError, match="<person>_<action>"):
        parse_trial_name("walking.c3d")


def test_folder_listing_ignores_subfolders_and_other_files(tmp_path):
    (tmp_path / "truth").mkdir()
    (tmp_path / "truth" / "ana_walk_angles.csv").write_text("time\n")
    (tmp_path / "notes.txt").write_text("hello")
    for name in ("ben_run.c3d", "ana_walk_2.trc"):
        (tmp_path / name).write_bytes(b"")
    entries = list_corpus_folder(tmp_path)
    assert [(e.person, e.action) for e in entries] == [("ana", "walk"), ("ben", "run")]


def test_manifest_resolves_relative_paths(tmp_path):
    (tmp_path / "m.csv").write_text("path,person,action\ndata/a.c3d,ana,walk\n/abs/b.c3d,ben,run\n")
    entries = read_manifest(tmp_path / "m.csv")
    assert entries[0].path == tmp_path / "data" / "a.c3d"
    assert str(entries[1].path) == "/abs/b.c3d" and entries[1].action == "run"
    (tmp_path / "bad.csv").write_text("file,who\nx,y\n")
    with pytest.raises(MocapError, match="path,person,action"):
        read_manifest(tmp_path / "bad.csv")




def test_angle_csv_detection(tmp_path):
    write_cycle(tmp_path / "a.csv", np.zeros((5, 6)), 1.0)
    assert is_angle_csv(tmp_path / "a.csv")
    (tmp_path / "m.csv").write_text("time,LASI_x,LASI_y,LASI_z\n0,1,2,3\n")
    assert not is_angle_csv(tmp_path / "m.csv")
    assert angle_columns(["pelvis"], "ZYZ") == ["pelvis.Z", "pelvis.Y", "pelvis.Z2"]


def test_corpus_of_angle_csvs_with_a_missing_cell_and_averaged_repeats(tmp_path):
    rng = np.random.default_rng(0)
    base = rng.normal(size=(20, 6))
    for person, scale in (("ana", 1.0), ("ben", 2.0)):
        for action, duration in (("walk", 1.1), ("run", 0.7)):
            if (person, action) == ("ben", "run"):
                continue
            write_cycle(tmp_path / f"{person}_{action}.csv", scale * base, duration)
    write_cycle(tmp_path / "ana_walk_2.csv", 3.0 * base, 1.3)          # a repeat: averaged
    corpus = load_corpus(tmp_path, samples=20)
    assert corpus.people == ["ana", "ben"] and corpus.actions == ["run", "walk"]
    assert corpus.angles.shape == (2, 2, 20, 6)
    assert corpus.missing_cells() == [("ben", "run")]
    assert np.isnan(corpus.angles[1, 0]).all() and np.isnan(corpus.durations[1, 0])
    assert np.allclose(corpus.angles[0, 1], 2.0 * base, atol=1e-3)   # CSV times: 6 decimals
    assert corpus.durations[0, 1] == pytest.approx(1.2)
    assert corpus.cycle_counts[0, 1] == 2


def test_one_person_or_one_action_is_a_clear_error(tmp_path):
    for action in ("walk", "run"):
        write_cycle(tmp_path / f"ana_{action}.csv", np.zeros((5, 6)), 1.0)
    with pytest.raises(MocapError, match=r"need at least 2 people and 2 actions.*found 1 person "
                                         r"\(ana\) and 2 actions"):
        load_corpus(tmp_path)


def test_marker_csv_with_dotted_axis_names_is_read_as_markers(tmp_path):
    """``PELO.x,PELO.y,PELO.z`` parses as angles in the sequence xyz; with a marker set whose
    markers those are, it is a marker CSV."""
    from mocap import io
    from mocap.markersets import load_markerset
    from mocap.synthetic import synthesize_trial
    from synthesis.corpus import read_trial_angles

    trial, _ = synthesize_trial(0, "walk")
    io.write(trial, tmp_path / "ana_walk.csv")
    text = (tmp_path / "ana_walk.csv").read_text()
    header, _, body = text.partition("\n")
    dotted = ",".join(name[:-2] + "." + name[-1] if name[-2:] in ("_x", "_y", "_z") else name
                      for name in header.split(","))
    (tmp_path / "dotted.csv").write_text(dotted + "\n" + body)
    markerset = load_markerset("synthetic15")
    expected = read_trial_angles(tmp_path / "ana_walk.csv", markerset)
    angles = read_trial_angles(tmp_path / "dotted.csv", markerset)
    assert angles.segments == expected.segments
    assert np.allclose(angles.values, expected.values, atol=1e-6, equal_nan=True)


def test_bvh_corpus_gives_the_marker_corpus_angles(tmp_path):
    """The same trials as C3D markers and as BVH motions (mocap.skeleton) give one tensor."""
    from mocap import io
    from mocap.io.bvh import write_bvh
    from mocap.markersets import load_markerset
    from mocap.body.retarget import motion_from_trial
    from mocap.synthetic import synthesize_trial

    markerset = load_markerset("synthetic15")
    for folder in ("c3d", "bvh"):
        (tmp_path / folder).mkdir()
    for person in (0, 1):
        for action in ("walk", "run"):
            trial, _ = synthesize_trial(person, action)
            name = f"p{person}_{action}"
            io.write(trial, tmp_path / "c3d" / f"{name}.c3d")
            write_bvh(motion_from_trial(trial, markerset), tmp_path / "bvh" / f"{name}.bvh")
    markers = load_corpus(tmp_path / "c3d", markerset=markerset, samples=50)
    motions = load_corpus(tmp_path / "bvh", samples=50, representation="euler")
    assert motions.segments == markers.segments and motions.columns == markers.columns
    assert np.allclose(motions.angles, markers.angles, atol=1e-3)
    assert np.allclose(motions.durations, markers.durations, atol=1e-6)


def test_cycle_detection_on_generated_multi_cycle_trials(tmp_path):
    """Trials of three gait cycles: detected cycles last the generator's period."""
    from mocap import io
    from mocap.synthetic import synthesize_trial

    periods = {}
    for person in (0, 1):
        for action in ("walk", "run"):
            trial, truth = synthesize_trial(person, action, cycles=3.0)
            io.write(trial, tmp_path / f"p{person}_{action}.c3d")
            periods[(f"p{person}", action)] = truth.cycle_seconds
    corpus = load_corpus(tmp_path, markerset="synthetic15", cycles=True)
    assert corpus.cycles and corpus.cycle_column in corpus.columns
    assert (corpus.cycle_counts >= 2).all()
    for (person, action), period in periods.items():
        p, a = corpus.people.index(person), corpus.actions.index(action)
        assert corpus.durations[p, a] == pytest.approx(period, abs=0.005)
