"""``mocap view`` without a browser: what the page carries, its size, and bad input."""
from __future__ import annotations

import base64
import html
import json
import re
from pathlib import Path

import numpy as np
import pytest

from mocap.body.retarget import motion_from_trial
from mocap.cli import main
from mocap.io import write
from mocap.markersets import load_markerset
from mocap.synthetic.corpus import synthesize_trial
from mocap.trial import Trial
from mocap.view import View, marker_layer, skeleton_layer, view_files
from mocap.view.page import scene_payload
from mocap.view.scene import Scene, detect_up

DATA = Path(__file__).resolve().parents[1] / "data"


def _floats(text: str) -> np.ndarray:
    return np.frombuffer(base64.b64decode(text), dtype="<f4")


@pytest.fixture(scope="module")
def walk():
    trial, _ = synthesize_trial(0, "walk", people=3, seed=2, gap_fraction=0.02)
    return trial


def test_the_page_carries_the_markers_gaps_and_segments(walk):
    layer = marker_layer(walk)                       # auto: the generator's synthetic15 set
    assert layer.skeleton == "synthetic15" and layer.up == "z"
    payload = scene_payload(Scene([layer]))["layers"][0]
    points = _floats(payload["points"]).reshape(walk.frames, len(walk.labels), 3)
    assert np.array_equal(np.isnan(points), np.isnan(walk.points))     # gaps stay gaps
    assert np.allclose(points, walk.points, atol=1e-6, equal_nan=True)
    assert payload["labels"] == walk.labels
    bones = {tuple(sorted(walk.labels[i] for i in pair))
             for pair in np.reshape(payload["bones"], (-1, 2))}
    # the pelvis's own lines, and its child the thigh hung from its origin
    assert {("PELA", "PELO"), ("PELL", "PELO"), ("LTHO", "PELO")} <= bones
    assert marker_layer(walk, "none").bones.size == 0


def test_a_motion_from_a_trial_lands_on_its_markers(walk):
    """A Y-up motion overlaid on the Z-up trial it was built from: the pelvis joint sits on
    the pelvis origin marker (the one turn between the two labs)."""
    motion = motion_from_trial(walk, load_markerset("synthetic15"))
    joints = skeleton_layer(motion).turned("z")
    pelvis = joints.points[:, joints.labels.index("pelvis")]
    recorded = np.isfinite(walk.marker("PELO")).all(axis=1)
    assert np.allclose(pelvis[recorded], walk.marker("PELO")[recorded], atol=1e-6)


def test_the_up_axis_of_markers(walk):
    assert detect_up(walk.points) == "z"
    turned = walk.points[..., [0, 2, 1]]
    assert detect_up(turned) == "y"
    trc = Trial(walk.labels, turned, walk.rate)
    assert marker_layer(trc).up == "y"
    assert marker_layer(trc, up="z").up == "z"


def test_a_ten_second_forty_marker_trial_is_well_under_five_megabytes(tmp_path):
    rng = np.random.default_rng(0)
    points = rng.normal(size=(1000, 40, 3)) * 0.3 + [0, 0, 1]
    trial = Trial([f"M{i:02d}" for i in range(40)], points, 100.0)
    view = View(Scene([marker_layer(trial, "none")]))
    size = view.write(tmp_path / "v.html")
    # 120 000 coordinates × 4 bytes in base64, beside three.js (0.57 MB)
    assert size < 1.5e6, size
    assert (tmp_path / "v.html").stat().st_size == size


def test_jupyter_shows_the_page_in_an_iframe(walk):
    view = View(Scene([marker_layer(walk)]))
    shown = view._repr_html_()
    found = re.fullmatch(r'<iframe srcdoc="([^"]*)" [^>]*></iframe>', shown, re.S)
    assert found and html.unescape(found[1]) == view.html()


def test_view_command_writes_one_html_file(tmp_path, capsys, walk):
    c3d = tmp_path / "walk.c3d"
    write(walk, c3d)
    out = tmp_path / "page.html"
    assert main(["view", str(c3d), str(DATA / "mocapbank_walk.bvh"), "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    data = json.loads(re.search(r'<script type="application/json" id="mocap-view-data">(.*?)'
                                r"</script>", text, re.S)[1])
    assert data["up"] == "z" and [l["name"] for l in data["layers"]] == ["walk.c3d",
                                                                         "mocapbank_walk.bvh"]
    # nothing to fetch: no script, style or image comes from elsewhere
    assert re.search(r"<(script|link|img|iframe)\b[^>]*\b(src|href)=", text) is None
    assert text.count("<script") == 3                     # data, three.js, the viewer
    assert "wrote" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["page.html", "walk.c3d"]


@pytest.mark.parametrize("arguments, words", [
    (["nope.c3d"], "nope.c3d: file not found"),
    ([str(DATA / "cmu_lambada.asf")], "skeleton only"),
    ([str(DATA / "README.md")], "cannot show this file"),
    ([str(DATA / "mocapbank_walk.bvh"), "--check", str(DATA / "mocapbank_walk.bvh")],
     "is not JSON"),
    ([str(DATA / "mocapbank_walk.bvh"), "--check", "{tmp}/other.json"],
     "is not the output of mocap check --json"),
    ([str(DATA / "mocapbank_walk.bvh"), "--curves", "a.Y"], "--curves chooses columns of --angles"),
    ([str(DATA / "mocapbank_walk.bvh"), "--angles", "{tmp}/angles.csv", "--curves", "knee.Q"],
     "no angle column knee.Q"),
    (["{tmp}/clinical.csv"], "give it with --angles"),
    (["{tmp}/walk.c3d", "-m", "nosuchset"], "nosuchset"),
    (["{tmp}/walk.c3d", "-m", "plugingait-lower"], "needs"),
])
def test_bad_input_is_one_line_and_exit_two(tmp_path, capsys, arguments, words, walk):
    write(walk, tmp_path / "walk.c3d")
    (tmp_path / "other.json").write_text(json.dumps({"verdict": "plausible"}))
    from mocap.rotations.angles import JointAngles
    from mocap.io.angles_csv import write_angles_csv
    write_angles_csv(JointAngles(np.arange(3) / 100.0, np.zeros((3, 1, 3)), ["knee"], "ZXY",
                                 [-1]), tmp_path / "angles.csv")
    (tmp_path / "clinical.csv").write_text("time,l_knee.flexion,l_knee.adduction,"
                                           "l_knee.rotation\n0,1,2,3\n")
    arguments = [a.replace("{tmp}", str(tmp_path)) for a in arguments]
    out = tmp_path / "v.html"
    code = main(["view", *arguments, "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2, err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in err, err
    assert not out.exists()


def test_the_output_must_be_html(tmp_path, capsys):
    assert main(["view", str(DATA / "mocapbank_walk.bvh"), "-o", str(tmp_path / "v.png")]) == 2
    assert "must be a .html or .htm file" in capsys.readouterr().err


def test_plates_turn_with_their_trial_into_a_z_up_lab(walk):
    """A Y-up C3D (its plates in the same Y-up lab) shown beside a Z-up trial: markers and
    plates turn together, so the reaction still acts where the feet are."""
    from mocap.view.scene import PlateTrack
    from mocap.io.lab import Z_TO_Y_UP
    corners = np.array([[0.0, 0, 0], [0.5, 0, 0], [0.5, 0, 0.6], [0.0, 0, 0.6]])   # y = 0 floor
    plate = PlateTrack("plate 1", corners, np.array([[0.0, 700.0, 0.0]]),
                       np.array([[0.25, 0.0, 0.3]]), 100.0)
    turned = plate.turned("z", "y")
    assert np.allclose(turned.force, [[0, 0, 700.0]])           # up stays up
    assert np.allclose(turned.corners[:, 2], 0)                 # on the Z-up floor
    assert np.allclose(turned.cop, plate.cop @ Z_TO_Y_UP)
    assert plate.turned("y", "y") is plate


def test_a_checks_reaction_lands_where_the_plates_measure_it(tmp_path, capsys):
    """The check of a real C3D walk works in its own Y-up world; shown over the Z-up lab, its
    estimated reaction acts within centimetres of the plates' measured centre of pressure
    and is about as large, in the frames one plate carries the body alone."""
    from tests.conftest import realdata_path
    c3d = realdata_path("biomechzoo_sample_study", "HC002D", "Straight", "HC002D06.c3d")
    capsys.readouterr()
    assert main(["check", str(c3d), "-m", "plugingait-lower", "--json"]) == 0
    check = json.loads(capsys.readouterr().out)
    scene = view_files([c3d], check=check).scene
    feet, plates = scene.forces, scene.plates
    assert [f.name for f in feet] == ["check l_foot", "check r_foot"] and len(plates) == 2
    assert len(feet[0].force) == len(plates[0].force)
    for plate, other in (plates, plates[::-1]):
        alone = (plate.force[:, 2] > 150) & ~(other.force[:, 2] > 20)
        assert alone.sum() > 30
        # the foot on the plate: the one whose reaction acts nearest its centre of pressure
        apart = np.stack([np.linalg.norm(f.point[alone, :2] - plate.cop[alone, :2], axis=1)
                          for f in feet])
        foot = int(np.argmin(np.nanmedian(apart, axis=1)))
        assert np.nanmedian(apart[foot]) < 0.10, np.nanmedian(apart, axis=1)
        ratio = np.median(feet[foot].force[alone, 2] / plate.force[alone, 2])
        assert 0.8 < ratio < 1.25, ratio
        # and the other foot carries (almost) nothing there
        assert np.median(feet[1 - foot].force[alone, 2]) < 0.1 * np.median(plate.force[alone, 2])


def test_without_chromium_the_browser_tests_skip_but_fail_under_ci(monkeypatch):
    from tests.view import conftest
    monkeypatch.setattr(conftest, "find_chromium", lambda: None)
    monkeypatch.setattr(conftest, "REQUIRE_REALDATA", False)
    with pytest.raises(pytest.skip.Exception, match="chromium is not installed"):
        conftest.require_chromium()
    monkeypatch.setattr(conftest, "REQUIRE_REALDATA", True)
    with pytest.raises(pytest.fail.Exception, match="MOCAP_REQUIRE_REALDATA=1"):
        conftest.require_chromium()
