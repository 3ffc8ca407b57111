"""Vicon's model outputs stored as points are not markers: ``mocap info`` counts them apart
and ``mocap convert`` writes the markers only (issue 26)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from mocap.cli import main
from mocap.io import read
from mocap.io.c3d.outputs import AXES, CENTRE_OF_MASS, CENTRES, computed_positions
from tests.conftest import realdata_path

WALK = ("biomechzoo_sample_study", "HC002D", "Straight", "HC002D06.c3d")
#: Plug-in Gait's segments with axis points (origin, anterior, lateral, proximal).
PIG_SEGMENTS = ["HED", "TRX", "PEL"] + [side + s for side in "LR"
                                        for s in ("CL", "FE", "FO", "HN", "HU", "RA", "TI", "TO")]
#: The markers of the Plug-in Gait full body and Oxford Foot Model sets this walk carries.
PIG_OFM_MARKERS = (["LFHD", "RFHD", "LBHD", "RBHD", "C7", "T2", "T6", "T10", "T12", "RBAK",
                    "CLAV", "STRN", "SACR", "RASI", "LASI"]
                   + [side + m for side in "LR" for m in (
                       "SHO", "ELB", "WRA", "WRB", "FIN", "THI", "KNE", "HFB", "TUB", "TIB",
                       "SHN", "ANK", "HEE", "CPG", "LCA", "STL", "NAV", "P1M", "P5M", "D5M",
                       "TOE", "HLX")])


def test_info_counts_markers_and_model_outputs_apart(capsys):
    path = realdata_path(*WALK)
    assert main(["info", str(path), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert sorted(summary["markers"]) == sorted(PIG_OFM_MARKERS)      # 59, not 179
    computed = summary["computed_points"]
    for segment in PIG_SEGMENTS:
        for suffix in "OALP":
            assert computed[segment + suffix] == AXES
    assert computed["CentreOfMass"] == computed["CentreOfMassFloor"] == CENTRE_OF_MASS
    assert computed["LHJC"] == computed["RAJC"] == CENTRES
    assert set(summary["missing"]) == set(summary["markers"])
    assert main(["info", str(path)]) == 0
    text = capsys.readouterr().out
    assert "markers:   59 " in text
    assert "76" not in text.split("outputs:")[0].split("markers:")[1]
    assert "106 axis points" in text and "55 angles" in text


def test_convert_writes_the_markers_only(tmp_path, capsys):
    path = realdata_path(*WALK)
    out = tmp_path / "walk.trc"
    assert main(["convert", str(path), str(out), "--up", "y"]) == 0
    err = capsys.readouterr().err
    assert "computed positions" in err and "not written" in err
    written = read(out)
    assert sorted(written.labels) == sorted(PIG_OFM_MARKERS)
    source = read(path)
    for label in ("LASI", "RHEE"):       # the markers themselves unchanged (lab turned to y up)
        a = source.marker(label)
        b = written.marker(label)
        ok = np.isfinite(a).all(axis=1)
        assert np.allclose(b[ok], np.column_stack([a[ok, 0], a[ok, 2], -a[ok, 1]]), atol=1e-6)


@pytest.mark.filterwarnings("ignore::mocap.errors.MocapWarning")     # Optotrak's truncation
def test_numbered_marker_clusters_stay_markers():
    """Rigid clusters numbered from 1 (ArmL1 … ArmL4, Probe1 …, Marker_1 …) are markers;
    only a whole 0-3 set (the Oxford Foot Model's LFOF0 … LFOF3) is an axis set."""
    for local in ("kineticstoolkit/kinematics/racing_full.c3d", "ezc3d_testFiles/Optotrak.c3d",
                  "c3dorg_via_c3dio/sample_26/Standing_Hybrid_1.c3d"):
        assert computed_positions(read(realdata_path(local)).labels) == {}
    assert computed_positions(["LFOF0", "LFOF1", "LFOF2", "LFOF3", "LFOF4"]) == {
        f"LFOF{k}": AXES for k in range(4)}
    assert computed_positions(["Matt:LHJC", "LKJC_CGM_2.4", "LKJ"]) == {
        "Matt:LHJC": CENTRES, "LKJC_CGM_2.4": CENTRES}


def test_a_marker_set_of_origin_anterior_left_markers_keeps_them():
    """synthetic15 places three markers per segment named like Plug-in Gait's axis points
    (PELO, PELA, PELL) but without the fourth (P): they are markers, every one."""
    from mocap.markersets import load_markerset

    names = [m for segment in load_markerset("synthetic15").segments for m in segment.markers]
    assert "PELO" in names and "HEDA" in names
    assert computed_positions(names) == {}


def test_opensim_reads_the_markers_only(tmp_path, capsys):
    """The TRC that ``convert --up y`` hands to OpenSim holds the walk's markers, not
    Vicon's axis points (OpenSim's IK would track HEDO … as markers)."""
    from tests.conftest import require_module

    opensim = require_module("opensim")
    out = tmp_path / "walk.trc"
    assert main(["convert", str(realdata_path(*WALK)), str(out), "--up", "y"]) == 0
    table = opensim.TimeSeriesTableVec3(str(out))
    assert sorted(table.getColumnLabels()) == sorted(PIG_OFM_MARKERS)


def test_the_viewer_draws_model_outputs_as_computed_points():
    from mocap.view.scene import marker_layer

    layer = marker_layer(read(realdata_path(*WALK)), markerset="none")
    flagged = {label for label, v in zip(layer.labels, layer.virtual) if v}
    assert {"PELO", "HEDO", "CentreOfMass", "LHJC"} <= flagged
    assert not flagged & set(PIG_OFM_MARKERS)
