"""``mocap plugingait``: Nexus-style output read back by ezc3d and by our reader, against
Vicon's stored values; no plates gives kinematics and one line; bad input is one line,
exit 2, nothing written."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.cli import main
from mocap.io import read
from mocap.io.c3d.write import write_c3d
from tests.conftest import realdata_path

WALK = ("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")
STATIC = ("biomechzoo_sample_study", "HC030A", "Static", "HC030A01.c3d")


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pig")
    out, csv = folder / "walk_pig.c3d", folder / "walk_pig.csv"
    status = main([
        "plugingait", str(realdata_path(*WALK)), "--static", str(realdata_path(*STATIC)),
        "-o", str(out), "--csv", str(csv)])
    assert status == 0
    return out, csv


def test_ezc3d_reads_vicons_labels_units_and_analysis(written):
    import ezc3d

    out, _ = written
    c3d = ezc3d.c3d(str(out))
    point = c3d["parameters"]["POINT"]
    labels = point["LABELS"]["value"] + point.get("LABELS2", {}).get("value", [])
    for kind, unit_name, unit, some in (
            ("ANGLES", "ANGLE_UNITS", "deg", "LKneeAngles"),
            ("MOMENTS", "MOMENT_UNITS", "Nmm", "RHipMoment"),
            ("POWERS", "POWER_UNITS", "W", "LAnklePower"),
            ("FORCES", "FORCE_UNITS", "N", "LGroundReactionForce")):
        assert some in point[kind]["value"] and some in labels
        assert point[unit_name]["value"] == [unit]
    assert {"LHJC", "RKJC", "LAJC"} <= set(labels)
    # the walk has the upper-body markers: its angles are there too
    assert {"LThoraxAngles", "RElbowAngles", "LFootProgressAngles"} <= set(point["ANGLES"]["value"])
    analysis = c3d["parameters"]["ANALYSIS"]
    names, contexts = analysis["NAMES"]["value"], analysis["CONTEXTS"]["value"]
    assert "Cadence" in names and {"Left", "Right"} <= set(contexts)
    assert len(analysis["VALUES"]["value"]) == len(names) == len(analysis["UNITS"]["value"])
    assert "Foot Strike" in c3d["parameters"]["EVENT"]["LABELS"]["value"]


def test_written_outputs_equal_vicons_stored_ones(written):
    out, _ = written
    ours, vicon = read(out), read(realdata_path(*WALK))

    def outputs(trial):
        m = trial.modelled
        return {label.rpartition(":")[2]: m["values"][:, k] for k, label in enumerate(m["labels"])}

    a, b = outputs(ours), outputs(vicon)
    for label, limit in (("LKneeAngles", 2.0), ("RHipMoment", 60.0), ("LAnklePower", 0.12)):
        ok = np.isfinite(a[label]).all(1) & np.isfinite(b[label]).all(1)
        assert ok.sum() > 60
        rms = np.sqrt(np.mean((a[label][ok] - b[label][ok]) ** 2, axis=0))
        assert rms.max() < limit, (label, rms)


def test_csv_is_the_same_outputs_as_a_tidy_table(written):
    import pandas

    out, csv = written
    table = pandas.read_csv(csv)
    assert list(table.columns) == ["frame", "time", "label", "kind", "component", "value",
                                   "unit"]
    moment = table[(table.label == "LAnkleMoment") & (table.component == "X")]
    stored = read(out).modelled
    column = stored["values"][:, stored["labels"].index("LAnkleMoment"), 0]
    np.testing.assert_allclose(column[moment.frame.to_numpy()], moment.value, rtol=1e-5,
                               atol=1e-3)
    assert set(moment.unit) == {"N·mm/kg"}


def test_a_lower_body_walk_gets_its_foot_progression(tmp_path, capsys):
    """The walk without its upper-body markers (a gait lab's lower-body set): Plug-in
    Gait's ten lower-body angles, the foot progression among them, within 2 deg RMS of the
    FootProgressAngles Vicon stored in the original file; no upper-body angle."""
    import ezc3d

    from tests.mocap.plugingait.test_foot_progression import lower_body_only

    trial = read(realdata_path(*WALK))
    lower = tmp_path / "lower.c3d"
    write_c3d(lower_body_only(trial), lower)
    out = tmp_path / "out.c3d"
    status, stdout, err = run(capsys, "plugingait", lower, "--static", realdata_path(*STATIC),
                              "-o", out)
    assert status == 0, err
    assert "10 angles" in stdout
    angles = ezc3d.c3d(str(out))["parameters"]["POINT"]["ANGLES"]["value"]
    assert sorted(angles) == sorted(f"{side}{joint}Angles" for side in "LR" for joint in
                                    ("Pelvis", "Hip", "Knee", "Ankle", "FootProgress"))
    ours, vicon = read(out).modelled, trial.modelled
    for label in ("LFootProgressAngles", "RFootProgressAngles"):
        a = ours["values"][:, ours["labels"].index(label)]
        b = vicon["values"][:, vicon["labels"].index(label)]
        ok = np.isfinite(a).all(1) & np.isfinite(b).all(1)
        assert ok.mean() > 0.9
        assert np.sqrt(np.mean((a[ok] - b[ok]) ** 2, axis=0)).max() < 2.0, label


def test_no_plates_gives_kinematics_and_one_line(tmp_path, capsys):
    trial = read(realdata_path(*WALK))
    trial.parameters = {g: v for g, v in trial.parameters.items()
                        if g not in ("FORCE_PLATFORM", "ANALOG")}
    trial.analogs, trial.analog_labels, trial.analog_rate = None, [], None
    bare = tmp_path / "noplates.c3d"
    write_c3d(trial, bare)
    out = tmp_path / "out.c3d"
    status, _, err = run(capsys, "plugingait", bare, "--static", realdata_path(*STATIC),
                         "-o", out)
    assert status == 0 and out.exists()
    lines = [line for line in err.splitlines() if "kinetics skipped" in line]
    assert len(lines) == 1 and "no force plates" in lines[0]
    labels = read(out).modelled["labels"]
    assert "LHipAngles" in labels and "LHipMoment" not in labels


@pytest.mark.parametrize("argv, words", [
    (("plugingait", "{walk}", "-o", "{tmp}/out.csv"), "must be a .c3d file"),
    (("plugingait", "{walk}", "--body-mass", "-3", "-o", "{tmp}/out.c3d"), "body-mass"),
    (("plugingait", "{walk}", "--static", "{tmp}/none.c3d", "-o", "{tmp}/out.c3d"),
     "no such file"),
    (("plugingait", "{other}", "-o", "{tmp}/out.c3d"), "no Plug-in Gait markers"),
])
def test_bad_input_is_one_line_exit_2_nothing_written(tmp_path, capsys, argv, words):
    other = realdata_path("pycgm", "Test_Files", "Static_trial.c3d")  # Plug-in Gait: replaced
    non_pig = tmp_path / "other.c3d"
    trial = read(other)
    write_c3d(trial.with_markers([f"M{k}" for k in range(len(trial.labels))], trial.points),
              non_pig)
    argv = [a.format(walk=realdata_path(*WALK), tmp=tmp_path, other=non_pig) for a in argv]
    status, out, err = run(capsys, *argv)
    assert status == 2
    assert len(err.strip().splitlines()) == 1 and words in err, err
    assert not (tmp_path / "out.c3d").exists() and not (tmp_path / "out.csv").exists()


def test_body_mass_from_the_option_when_the_file_has_none(tmp_path, capsys):
    trial = read(realdata_path(*WALK))
    processing = {k: v for k, v in trial.parameters["PROCESSING"].items()
                  if k.upper() != "BODYMASS"}
    trial.parameters = dict(trial.parameters, PROCESSING=processing)
    light = tmp_path / "nomass.c3d"
    write_c3d(trial, light)
    status, _, err = run(capsys, "plugingait", light, "-o", tmp_path / "a.c3d")
    assert status == 0 and "no body mass" in err and "kinetics skipped" in err
    status, _, err = run(capsys, "plugingait", light, "--body-mass", "45", "-o",
                         tmp_path / "b.c3d")
    assert status == 0 and "kinetics skipped" not in err
    original = read(realdata_path(*WALK))
    ours, theirs = read(tmp_path / "b.c3d").modelled, original.modelled
    # moments scale with 1 / body mass: Vicon's per kg of the recorded mass
    recorded = float(np.ravel(original.parameters["PROCESSING"]["BODYMASS"])[0])
    a = ours["values"][:, ours["labels"].index("LAnkleMoment"), 0]
    b = theirs["values"][:, theirs["labels"].index("LAnkleMoment"), 0]
    ok = np.isfinite(a) & np.isfinite(b)
    ratio = np.sum(a[ok] * b[ok]) / np.sum(b[ok] * b[ok])
    assert ratio == pytest.approx(recorded / 45.0, rel=0.05)


def test_a_walk_without_events_gets_detected_ones_written(tmp_path, capsys):
    import ezc3d

    walk = realdata_path("biomechzoo_sample_study", "HC031A", "Straight", "HC031A06.c3d")
    assert not read(walk).events                          # Vicon stored none
    out = tmp_path / "out.c3d"
    status, _, _ = run(capsys, "plugingait", walk, "-o", out)
    assert status == 0
    event = ezc3d.c3d(str(out))["parameters"]["EVENT"]
    pairs = set(zip(event["LABELS"]["value"], event["CONTEXTS"]["value"]))
    assert {("Foot Strike", "Left"), ("Foot Strike", "Right"), ("Foot Off", "Left")} <= pairs
    written = read(out).events
    assert all(0 <= e["frame"] < read(walk).frames for e in written)
