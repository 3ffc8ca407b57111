"""``mocap angles`` with Plug-in Gait's clinical angles, a static, gait cycles,
and the missing-marker fallbacks (issue 12), end to end on real files."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from mocap.io.angles_csv import read_angles_csv
from mocap.cli import main
from mocap.plugingait.clinical import plugingait_angles
from mocap.plugingait.events import FOOT_STRIKE, detect_events, events_from_file
from mocap.io import read, write
from mocap.markersets.model import MissingMarkerWarning
from mocap.plugingait.model import AnatomicalOffsetWarning
from mocap.trial import Trial
from tests.conftest import realdata_path

WALK = ("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")
STATIC = ("biomechzoo_sample_study", "HC030A", "Static", "HC030A01.c3d")
PYCGM = ("pycgm", "Test_Files", "Movement_trial.c3d")


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_clinical_angles_with_static_and_cycles(tmp_path, capsys):
    out, cycles = tmp_path / "walk.csv", tmp_path / "cycles.csv"
    status, _, err = run(capsys, "angles", realdata_path(*WALK), "-m", "plugingait-lower",
                         "--static", realdata_path(*STATIC), "-o", out, "--cycles", cycles)
    assert status == 0, err
    assert "uncorrected" not in err
    angles = read_angles_csv(out)
    assert angles.segments == [f"{s}_{j}" for s in "lr" for j in ("pelvis", "hip", "knee",
                                                                 "ankle", "foot_progress")]
    assert angles.axes == ["flexion", "adduction", "rotation"]
    # the CSV's knee flexion is Vicon's LKneeAngles X within the lab's 2 degrees
    trial = read(realdata_path(*WALK))
    modelled = trial.modelled
    vicon = modelled["values"][:, modelled["labels"].index("LKneeAngles"), 0]
    ours = angles.segment("l_knee")[:, 0]
    ok = np.isfinite(vicon) & np.isfinite(ours)
    assert np.sqrt(np.mean((ours[ok] - vicon[ok]) ** 2)) < 2.0
    # and its foot progression (no --upper-body) Vicon's LFootProgressAngles, likewise
    vicon = modelled["values"][:, modelled["labels"].index("LFootProgressAngles")]
    ours = angles.segment("l_foot_progress")
    ok = np.isfinite(vicon).all(axis=1) & np.isfinite(ours).all(axis=1)
    assert ok.mean() > 0.9
    assert (np.sqrt(np.mean((ours[ok] - vicon[ok]) ** 2, axis=0)) < 2.0).all()
    # tidy cycles: side, cycle, percent, then each joint's three planes; 101 rows a cycle
    lines = cycles.read_text().splitlines()
    assert lines[0] == "side,cycle,percent," + ",".join(
        f"{j}.{p}" for j in ("pelvis", "hip", "knee", "ankle", "foot_progress")
        for p in ("flexion", "adduction", "rotation"))
    rows = [line.split(",") for line in lines[1:]]
    assert len(rows) % 101 == 0 and {r[0] for r in rows} == {"l", "r"}
    first = [r for r in rows if r[0] == "l" and r[1] == "1"]
    assert len(first) == 101 and first[0][2] == "0.000000" and first[-1][2] == "100.000000"
    knee = np.array([float(r[3 + 6]) for r in first])          # knee flexion
    assert 50 < knee.max() < 75 and knee.argmax() > 60           # swing-phase peak
    with Image.open(cycles.with_suffix(".png")) as image:
        assert image.format == "PNG" and image.size[0] > 800


def test_without_static_the_uncorrected_offsets_are_said_once(tmp_path, capsys):
    status, _, err = run(capsys, "angles", realdata_path(*WALK), realdata_path(*PYCGM),
                         "-m", "plugingait-lower", "-o", tmp_path / "out")
    assert status == 0, err
    assert err.count("anatomical offsets are uncorrected") == 1
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == \
        ["HC030A05.csv", "Movement_trial.csv"]


def test_empty_sacrum_falls_back_to_the_psis_midpoint(tmp_path, capsys):
    """Issue 12: a SACR label without data gave empty pelvis, hips and knees with
    exit status 0 and no warning.  The fallback is keyed on data."""
    trial = read(realdata_path(*PYCGM))
    labels = trial.labels + ["SACR"]
    points = np.concatenate([trial.points, np.full((trial.frames, 1, 3), np.nan)], axis=1)
    empty = trial.with_markers(labels, points)
    empty.path = "nosacr.c3d"
    # the clinical angles: a warning, and the same angles as from the PSIS alone
    with pytest.warns(MissingMarkerWarning, match="SACR has no data"), \
            pytest.warns(AnatomicalOffsetWarning):
        angles = plugingait_angles(empty, flat_foot=False)
    with pytest.warns(AnatomicalOffsetWarning):
        reference = plugingait_angles(trial, flat_foot=False)
    np.testing.assert_array_equal(angles.values, reference.values)
    assert np.isfinite(angles.segment("l_hip")).all(axis=1).mean() > 0.9
    # the segment angles, through the command line
    gappy = tmp_path / "nosacr.c3d"
    write(empty, gappy)
    status, _, err = run(capsys, "angles", gappy, "-m", "plugingait-lower",
                         "-o", tmp_path / "b.csv", "--no-clinical")
    assert status == 0 and "SACR has no data" in err, err
    pelvis = read_angles_csv(tmp_path / "b.csv").segment("pelvis")
    assert np.isfinite(pelvis).all(axis=1).mean() > 0.9


def test_no_feet_markers_still_give_hips_and_knees(tmp_path, capsys):
    trial = read(realdata_path(*WALK))
    keep = [i for i, label in enumerate(trial.labels)
            if label not in ("LHEE", "RHEE", "LTOE", "RTOE")]
    nofeet = Trial([trial.labels[i] for i in keep], trial.points[:, keep], trial.rate,
                   path="nofeet.c3d", metadata=trial.metadata)
    with pytest.warns(MissingMarkerWarning, match="no foot"):
        angles = plugingait_angles(nofeet, static=read(realdata_path(*STATIC)),
                                   flat_foot="auto")
    for side in "lr":
        for joint in ("pelvis", "hip", "knee"):
            assert np.isfinite(angles.segment(f"{side}_{joint}")).all()
        assert np.isnan(angles.segment(f"{side}_ankle")).all()
    # segment angles through the command line: the feet left empty, with a warning
    path = tmp_path / "nofeet.c3d"
    write(nofeet, path)
    out = tmp_path / "segments.csv"
    status, _, err = run(capsys, "angles", path, "-m", "plugingait-lower", "--no-clinical",
                         "-o", out)
    assert status == 0 and "l_foot" in err and "r_foot" in err, err
    angles = read_angles_csv(out)
    assert np.isfinite(angles.segment("l_thigh")).all()
    assert np.isfinite(angles.segment("r_shank")).all()
    assert np.isnan(angles.segment("l_foot")).all()


def test_detected_events_agree_with_the_labelled_ones():
    """Zeni's coordinate method against the lab's own Foot Strike / Foot Off
    events (HC031A23: eight strikes and eight offs labelled)."""
    trial = read(realdata_path("biomechzoo_sample_study", "HC031A", "Turn", "HC031A23.c3d"))
    labelled = events_from_file(trial)
    detected = detect_events(trial)
    assert sum(e.label == FOOT_STRIKE for e in labelled) >= 6
    # every labelled event away from the trial's ends (a peak needs both sides)
    # has a detected one of its kind and side within 6 frames (60 ms)
    inner = [e for e in labelled if 20 <= e.frame <= trial.frames - 20]
    assert len(inner) >= 10
    for event in inner:
        gap = min((abs(d.frame - event.frame) for d in detected
                   if d.side == event.side and d.label == event.label), default=99)
        assert gap <= 6, (event, gap)


def test_cycles_are_resampled_strike_to_strike_at_101_points():
    """A known answer: angles that ramp linearly in frames give, at p % of a cycle
    from strike a to strike b, exactly a + p (b - a) / 100."""
    from mocap.rotations.angles import JointAngles
    from mocap.plugingait.events import FOOT_OFF, GaitEvent, normalise_cycles

    frames = 300
    ramp = np.arange(frames, dtype=float)
    values = np.repeat(ramp[:, None, None], 2, axis=1).repeat(3, axis=2)
    values[:, 1] *= -1.0
    angles = JointAngles(times=ramp / 100.0, values=values, segments=["l_knee", "r_knee"],
                         sequence="YXZ", parents=[-1, -1],
                         axes=["flexion", "adduction", "rotation"])
    events = [GaitEvent("l", FOOT_STRIKE, 10.0), GaitEvent("l", FOOT_OFF, 70.0),
              GaitEvent("l", FOOT_STRIKE, 110.5), GaitEvent("r", FOOT_STRIKE, 60.0),
              GaitEvent("r", FOOT_STRIKE, 160.0), GaitEvent("r", FOOT_STRIKE, 262.0)]
    cycles = normalise_cycles(angles, events)
    assert cycles.side == ["l", "r", "r"] and cycles.number == [1, 1, 2]
    assert cycles.joints == ["knee"] and cycles.values.shape == (3, 101, 1, 3)
    percent = np.linspace(0, 1, 101)
    np.testing.assert_allclose(cycles.values[0, :, 0, 0], 10 + percent * 100.5, atol=1e-9)
    np.testing.assert_allclose(cycles.values[2, :, 0, 1], -(160 + percent * 102), atol=1e-9)
    assert abs(cycles.foot_off[0] - 60 / 1.005) < 1e-9 and np.isnan(cycles.foot_off[1])


def test_the_python_recipe_gives_the_command_lines_angles(tmp_path, capsys):
    """``mocap.pipeline.clinical_angles(walk, static)`` is what ``mocap angles -m
    plugingait-lower --static`` writes, with the same defaults (foot-flat ``auto``):
    HC002D06's ankle flexion was 3.4 degrees RMS from Vicon's from Python (foot-flat off)
    and ~0.1 from the command line."""
    from mocap.pipeline import Cleaning, clinical_angles

    walk = realdata_path("biomechzoo_sample_study", "HC002D", "Straight", "HC002D06.c3d")
    static = realdata_path("biomechzoo_sample_study", "HC002D", "Static", "HC002D02.c3d")
    out = tmp_path / "walk.csv"
    status, _, err = run(capsys, "angles", walk, "-m", "plugingait-lower", "--static", static,
                         "--fill-gaps", "0.1", "-o", out)
    assert status == 0, err
    written = read_angles_csv(out)
    result = clinical_angles(walk, static, cleaning=Cleaning(max_gap_seconds=0.1))
    assert result.angles.segments == written.segments
    np.testing.assert_allclose(result.angles.values, written.values, atol=1e-5,
                               equal_nan=True)          # the CSV keeps 6 decimals
    # and both are Vicon's: the ankle flexion (the foot-flat option's plane)
    modelled = read(walk).modelled
    for side in "LR":
        vicon = modelled["values"][:, modelled["labels"].index(f"{side}AnkleAngles"), 0]
        ours = result.angles.segment(f"{side.lower()}_ankle")[:, 0]
        ok = np.isfinite(vicon) & np.isfinite(ours)
        assert ok.sum() > 100
        assert np.sqrt(np.mean((ours[ok] - vicon[ok]) ** 2)) < 0.5


def test_a_walk_given_as_static_is_a_warning(tmp_path, capsys):
    """A walk passed to --static was calibrated from without a word; a real static is not
    warned about (its pelvis sways a few cm, the walk's travels > 1 m)."""
    out = tmp_path / "walk.csv"
    status, _, err = run(capsys, "angles", realdata_path(*WALK), "-m", "plugingait-lower",
                         "--static", realdata_path(*WALK), "-o", out)
    assert status == 0, err
    assert "during the static trial (standing sway is a few cm): is it a walk?" in err
    assert len([line for line in err.splitlines() if "is it a walk" in line]) == 1
    status, _, err = run(capsys, "angles", realdata_path(*WALK), "-m", "plugingait-lower",
                         "--static", realdata_path(*STATIC), "-o", out)
    assert status == 0 and "is it a walk" not in err
