"""Where Plug-in Gait's subject measurements come from (issue 22 item 1): the static's
PROCESSING group first, then the walk's, then the static's medial markers, then an
estimate from the walk with one warning each; the marker diameter too; and the report's
subject table naming each origin.

A real biomechzoo walk and its static are rewritten with mocap's C3D writer with
PROCESSING groups that disagree on purpose (values written here, so the known answers are
exact).
"""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from mocap.io import read
from mocap.io.c3d.write import write_c3d
from mocap.plugingait.clinical import plugingait_angles, prepare_subject
from mocap.plugingait.estimates import EstimatedMeasurementWarning
from mocap.plugingait.model import Subject
from mocap.plugingait.report import report_html
from mocap.plugingait.walks import analyse_walk
from tests.conftest import realdata_path

SUBJECT = ("biomechzoo_sample_study", "HC030A")
#: Static's knee width (mm) against the walk's: a disagreement the static must win.
STATIC_L_KNEE_MM, WALK_L_KNEE_MM = 118.0, 92.0


def _with_processing(trial, path, **changes):
    """``trial`` written to ``path`` with its PROCESSING entries changed (None deletes)."""
    group = {str(k).upper(): v for k, v in (trial.parameters.get("PROCESSING") or {}).items()}
    for name, value in changes.items():
        group.pop(name.upper(), None)
        if value is not None:
            group[name.upper()] = np.array([float(value)])
    trial.parameters = {**trial.parameters, "PROCESSING": group}
    write_c3d(trial, path)
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Paths: walk and static whose PROCESSING disagree, and variants."""
    folder = realdata_path(*SUBJECT)
    walk = next((folder / "Straight").glob("*.c3d"))
    static = next((folder / "Static").glob("*.c3d"))
    out = tmp_path_factory.mktemp("sources")
    no_widths = {"LAnkleWidth": None, "RAnkleWidth": None, "RKneeWidth": None}
    return {
        # static: L knee 118 mm, 12 mm markers, no leg lengths, no ankle or R knee widths
        "static": _with_processing(read(static), out / "static.c3d",
                                   LKneeWidth=STATIC_L_KNEE_MM, MarkerDiameter=12.0,
                                   LLegLength=None, RLegLength=None, **no_widths),
        # walk: L knee 92 mm, 10 mm markers, leg lengths 830 mm (as recorded)
        "walk": _with_processing(read(walk), out / "walk.c3d", LKneeWidth=WALK_L_KNEE_MM,
                                 **no_widths),
        # the same walk agreeing with the static on the L knee
        "walk_agreeing": _with_processing(read(walk), out / "walk_agreeing.c3d",
                                          LKneeWidth=STATIC_L_KNEE_MM, **no_widths),
        # the static agreeing with the walk: the value must matter
        "static_walks_knee": _with_processing(read(static), out / "static_walks_knee.c3d",
                                              LKneeWidth=WALK_L_KNEE_MM, MarkerDiameter=12.0,
                                              LLegLength=None, RLegLength=None, **no_widths),
        "static_no_diameter": _with_processing(read(static), out / "static_nd.c3d",
                                               MarkerDiameter=None),
        "walk_no_diameter": _with_processing(read(walk), out / "walk_nd.c3d",
                                             MarkerDiameter=None),
        "leg_mm": float(read(walk).parameters["PROCESSING"]["LLEGLENGTH"][0]),
    }


@pytest.fixture(scope="module")
def prepared(files):
    """(subject, warnings) of the disagreeing pair."""
    walk, static = read(files["walk"]), read(files["static"])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        subject = prepare_subject(walk, static=static)
    return subject, [str(w.message) for w in caught
                     if issubclass(w.category, EstimatedMeasurementWarning)]


def test_the_statics_processing_wins_then_the_walks_then_markers_then_estimates(files,
                                                                                   prepared):
    subject, _ = prepared
    assert subject.knee_width["l"] == pytest.approx(STATIC_L_KNEE_MM / 1000, abs=1e-9)
    assert subject.marker_diameter == pytest.approx(0.012, abs=1e-9)
    assert subject.leg_length["l"] == pytest.approx(files["leg_mm"] / 1000, abs=1e-9)
    s = subject.sources
    assert s[("knee_width", "l")] == "static PROCESSING"
    assert s[("marker_diameter", None)] == "static PROCESSING"
    assert s[("leg_length", "l")] == s[("leg_length", "r")] == "walk PROCESSING"
    # LMMA / RMMA in the static measure the ankle widths; no medial knee marker there
    assert s[("ankle_width", "l")] == s[("ankle_width", "r")] == "static medial markers"
    assert s[("knee_width", "r")] == "estimated from the walk"
    assert 0.03 < subject.ankle_width["l"] < 0.10 and 0.06 < subject.knee_width["r"] < 0.16


def test_only_the_estimate_is_warned_and_once(prepared):
    _, said = prepared
    assert len(said) == 1, said
    assert "R knee width not measured: estimated" in said[0]


def test_the_walks_disagreeing_value_changes_no_angle(files):
    """Known answer: the walk's 92 mm L knee is overruled by the static's 118 mm, so the
    angles equal those of a walk recording 118 mm, and differ from a static saying 92."""
    def angles(walk, static):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return plugingait_angles(read(files[walk]), static=read(files[static]),
                                     flat_foot="auto").segment("l_hip")

    disagreeing = angles("walk", "static")
    np.testing.assert_array_equal(disagreeing, angles("walk_agreeing", "static"))
    other = angles("walk", "static_walks_knee")
    assert np.nanmax(np.abs(other - disagreeing)) > 0.1           # degrees: the width matters


def test_a_callers_subject_takes_the_statics_processing(files):
    walk, static = read(files["walk"]), read(files["static"])
    given = Subject(inter_asis=0.21, leg_length={"l": 0.80, "r": 0.81})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        subject = prepare_subject(walk, given, static=static)
    assert subject.leg_length == {"l": 0.80, "r": 0.81} and subject.inter_asis == 0.21
    assert subject.sources[("leg_length", "l")] == "given"
    assert subject.knee_width["l"] == pytest.approx(STATIC_L_KNEE_MM / 1000, abs=1e-9)
    assert subject.sources[("knee_width", "l")] == "static PROCESSING"
    assert subject.marker_diameter == pytest.approx(0.012, abs=1e-9)


def test_an_unrecorded_marker_diameter_is_said_once_and_assumed(files):
    walk, static = read(files["walk_no_diameter"]), read(files["static_no_diameter"])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        subject = prepare_subject(walk, static=static)
    said = [str(w.message) for w in caught
            if issubclass(w.category, EstimatedMeasurementWarning)]
    assert len(said) == 1, said
    assert "marker diameter not measured: assumed 14 mm" in said[0]
    assert subject.marker_diameter == 0.014
    assert subject.sources[("marker_diameter", None)] == "assumed (not recorded)"
    # recorded in the static only: taken from there, nothing said
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        subject = prepare_subject(walk, static=read(files["static"]))
    assert subject.marker_diameter == pytest.approx(0.012, abs=1e-9)
    assert not [w for w in caught if "diameter" in str(w.message)]


def test_the_report_names_each_origin(files):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        analysis = analyse_walk(files["walk"], files["static"])
    rows = {name: (value, origin) for name, value, origin in analysis.subject}
    assert rows["Knee width, left"] == ("118 mm", "static PROCESSING")
    assert rows["Marker diameter"] == ("12 mm", "static PROCESSING")
    assert rows["Leg length, left"][1] == "walk PROCESSING"
    assert rows["Ankle width, left"][1] == "static medial markers"
    assert rows["Knee width, right"][1] == "estimated from the walk"
    assert rows["Body mass"][1] == "static PROCESSING"
    page = report_html([analysis], None, None, date="today")
    for name, (value, origin) in rows.items():
        assert f"<td>{name}</td><td>{value}</td><td>{origin}</td>" in page, name
