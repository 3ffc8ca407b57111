"""``mocap view`` pages in a real headless chromium (Debian's, installed by .ci/run).

Each page is opened from disk (file://, no server, no network) and driven as a user would:
the play button clicked, the scrubber moved, the mouse over a marker. Without chromium the
tests skip, except under CI (MOCAP_REQUIRE_REALDATA=1) where they fail.
"""
from __future__ import annotations

import io
import json
import re
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

from mocap.cli import main
from mocap.io import read, write
from mocap.io.motion import read_motion
from mocap.view.scene import plate_tracks
from tests.conftest import realdata_path
from tests.view.chromium import file_url

DATA = Path(__file__).resolve().parents[1] / "data"
WALK = ("biomechzoo_sample_study", "HC002D", "Straight", "HC002D06.c3d")


def image(png: bytes) -> np.ndarray:
    """RGB pixels (rows, columns, 3) of a PNG."""
    from PIL import Image
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=int)


def blue_pixels(pixels: np.ndarray) -> int:
    """Pixels of the first layer's colour (#2f7fc1, shaded): clearly bluer than red. The
    background, the grid and the plate outlines are grey, the force arrows red."""
    return int(((pixels[..., 2] - pixels[..., 0]) > 60).sum())


def settle(browser) -> None:
    """Wait until the page has drawn two more animation frames."""
    browser.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")


def scrub_to(browser, frame: int) -> None:
    """Move the scrubber as a user's drag does: set its value, fire its input event."""
    browser.evaluate(f"(() => {{ const s = document.getElementById('mv-scrub'); s.value = {frame};"
                     " s.dispatchEvent(new Event('input', {bubbles: true})); })()")
    settle(browser)


def counter(browser) -> tuple[int, int]:
    """The frame counter as the page shows it: (frame, of frames)."""
    text = browser.evaluate("document.getElementById('mv-frame').textContent")
    found = re.match(r"frame (\d+) / (\d+)", text)
    assert found, text
    return int(found[1]), int(found[2])


@pytest.fixture(scope="module")
def walk_page(tmp_path_factory):
    """A real Plug-in Gait walk with two force plates, and its joint angles as curves."""
    c3d = realdata_path(*WALK)
    folder = tmp_path_factory.mktemp("walk")
    angles = folder / "angles.csv"
    assert main(["angles", str(c3d), "-m", "plugingait-lower", "-o", str(angles)]) == 0
    page = folder / "walk.html"
    assert main(["view", str(c3d), "--angles", str(angles), "-o", str(page)]) == 0
    return page, read(c3d)


def test_the_page_loads_from_disk_without_error_and_draws_the_markers(browser, walk_page):
    page, trial = walk_page
    browser.open(file_url(page))
    settle(browser)
    assert browser.errors() == []
    assert counter(browser) == (1, trial.frames)
    pixels = image(browser.screenshot("#mv-canvas"))
    assert pixels.shape[0] > 200 and pixels.shape[1] > 400
    assert blue_pixels(pixels) > 300                    # markers and segments, not just a grid
    # nothing was fetched: every resource of the page is the file itself
    resources = browser.evaluate("performance.getEntriesByType('resource').map(e => e.name)")
    assert resources == []


def test_play_advances_the_frame_counter_in_real_time(browser, walk_page):
    page, trial = walk_page
    browser.open(file_url(page))
    settle(browser)
    browser.click("#mv-play")
    start = time.monotonic()
    time.sleep(0.8)
    frame, frames = counter(browser)
    elapsed = time.monotonic() - start
    assert browser.evaluate("mocapView.playing") is True
    # 100 Hz at real speed: about 80 frames in 0.8 s (rendering may lag, never run ahead)
    assert 0.4 * elapsed * trial.rate < frame - 1 < 1.2 * elapsed * trial.rate + 3, (frame, elapsed)
    browser.click("#mv-play")                           # pause: the counter stops
    paused = counter(browser)
    time.sleep(0.2)
    assert counter(browser) == paused
    assert browser.errors() == []


def test_speed_and_frame_step(browser, walk_page):
    page, trial = walk_page
    browser.open(file_url(page))
    browser.evaluate("(() => { const s = document.getElementById('mv-speed'); s.value = '0.25';"
                     " s.dispatchEvent(new Event('change')); })()")
    browser.click("#mv-play")
    start = time.monotonic()
    time.sleep(0.8)
    frame, _ = counter(browser)
    elapsed = time.monotonic() - start
    assert frame - 1 < 0.25 * 1.2 * elapsed * trial.rate + 3, (frame, elapsed)
    browser.click("#mv-play")
    scrub_to(browser, 40)
    browser.click("#mv-next")
    browser.click("#mv-next")
    browser.click("#mv-prev")
    assert counter(browser)[0] == 42                    # frame 41 (0-based), shown from 1


def test_two_frames_give_two_different_pictures(browser, walk_page):
    page, _ = walk_page
    browser.open(file_url(page))
    scrub_to(browser, 20)
    first = image(browser.screenshot("#mv-canvas"))
    scrub_to(browser, 20)
    assert (image(browser.screenshot("#mv-canvas")) == first).all()     # same frame, same picture
    scrub_to(browser, 150)
    assert counter(browser)[0] == 151
    second = image(browser.screenshot("#mv-canvas"))
    changed = (np.abs(second - first).sum(axis=2) > 60).sum()
    assert changed > 500, changed


def test_the_angle_cursor_follows_the_scrubber(browser, walk_page):
    page, trial = walk_page
    browser.open(file_url(page))
    assert browser.evaluate("document.getElementById('mv-curves').hidden") is False
    paths = browser.evaluate("[...document.querySelectorAll('#mv-plot path')]"
                             ".map(p => p.dataset.column)")
    assert paths == ["l_hip.flexion", "l_knee.flexion", "l_ankle.flexion", "r_hip.flexion",
                     "r_knee.flexion", "r_ankle.flexion"]
    box = browser.evaluate("(() => { const r = document.querySelector('#mv-plot rect');"
                           " return [+r.getAttribute('x'), +r.getAttribute('width')]; })()")
    cursor = "+document.getElementById('mv-cursor').getAttribute('x1')"
    legend = "document.getElementById('mv-curve-legend').textContent"
    positions, texts = [], []
    for frame in (0, 100, 221):
        scrub_to(browser, frame)
        positions.append(browser.evaluate(cursor))
        texts.append(browser.evaluate(legend))
    duration = (trial.frames - 1) / trial.rate
    expected = [box[0] + (f / trial.rate) / duration * box[1] for f in (0, 100, 221)]
    assert np.allclose(positions, expected, atol=0.05), (positions, expected)
    assert texts[0] != texts[1]                          # the values at the cursor change
    # a click on the curves moves the frame there
    x, y = browser.evaluate("(() => { const r = document.getElementById('mv-plot')"
                            ".getBoundingClientRect(); return [r.x, r.y + r.height / 2]; })()")
    browser.mouse("mousePressed", x + box[0] + box[1] / 2, y, button="left", clickCount=1)
    browser.mouse("mouseReleased", x + box[0] + box[1] / 2, y, button="left", clickCount=1)
    assert abs(counter(browser)[0] - 1 - (trial.frames - 1) / 2) <= 1.5
    assert browser.errors() == []


def test_hovering_a_marker_shows_its_label(browser, walk_page):
    page, trial = walk_page
    browser.open(file_url(page))
    scrub_to(browser, 60)
    screen = browser.evaluate(f"[...Array({len(trial.labels)}).keys()]"
                              ".map(i => mocapView.screenPosition(0, i))")
    head = int(np.nanargmax(trial.points[60, :, 2]))          # the highest marker
    x, y = screen[head]
    browser.mouse("mouseMoved", x, y)
    settle(browser)
    tip = browser.evaluate("(() => { const t = document.getElementById('mv-tip');"
                           " return t.hidden ? null : t.textContent; })()")
    near = {trial.labels[i] for i, p in enumerate(screen)
            if p is not None and np.hypot(p[0] - x, p[1] - y) < 6}
    assert tip is not None and tip.endswith(" · HC002D06.c3d"), tip
    assert tip.split(" · ")[0] in near, (tip, near)
    browser.mouse("mouseMoved", 5, 5)                          # away: the label goes
    settle(browser)
    assert browser.evaluate("document.getElementById('mv-tip').hidden") is True


def test_plates_show_the_ground_reaction_at_the_centre_of_pressure(browser, walk_page):
    page, trial = walk_page
    plates = plate_tracks(trial)
    browser.open(file_url(page))
    loaded = np.flatnonzero(np.isfinite(plates[0].cop).all(axis=1))
    frame = int(loaded[len(loaded) // 2])
    scrub_to(browser, frame)
    arrows = browser.evaluate("mocapView.arrows()")
    assert [a["name"] for a in arrows] == ["plate 1", "plate 2"]
    shown = arrows[0]
    force = plates[0].force[frame]
    assert shown["visible"]
    assert np.allclose(shown["position"], plates[0].cop[frame], atol=1e-5)
    assert shown["length"] == pytest.approx(np.linalg.norm(force) / 1000, rel=1e-5)
    readout = browser.evaluate("document.getElementById('mv-readout').textContent")
    assert f"plate 1: {round(float(np.linalg.norm(force)))} N" in readout
    unloaded = int(np.flatnonzero(~np.isfinite(plates[0].cop).all(axis=1))[0])
    scrub_to(browser, unloaded)
    assert browser.evaluate("mocapView.arrows()")[0]["visible"] is False
    # the red arrow is on the picture while the plate is loaded
    scrub_to(browser, frame)
    pixels = image(browser.screenshot("#mv-canvas"))
    assert ((pixels[..., 0] - pixels[..., 2]) > 80).sum() > 20


# ----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """One file of each kind the issue names, as (name, arguments, frames)."""
    folder = tmp_path_factory.mktemp("inputs")
    from mocap.synthetic.corpus import synthesize_trial
    trial, _ = synthesize_trial(0, "walk", people=3, seed=2, cycles=2, gap_fraction=0.02)
    generated = folder / "generated_walk.c3d"
    write(trial, generated)
    bandai = realdata_path("bandai2", "dataset-2_walk_active_001.bvh")
    synthesised = _synthesised_bvh(folder)
    return {
        "real C3D with plates": ([str(realdata_path(*WALK))], read(realdata_path(*WALK)).frames),
        "bandai2 BVH": ([str(bandai)], read_motion(bandai).frames),
        "ASF/AMC": ([str(DATA / "cmu_lambada.amc")], read_motion(DATA / "cmu_lambada.amc").frames),
        "generated trial": ([str(generated)], trial.frames),
        "synthesised BVH": ([str(synthesised)], read_motion(synthesised).frames),
    }


def _synthesised_bvh(folder: Path) -> Path:
    """A walk synthesised by the N-mode SVD model from a small generated corpus."""
    from mocap.synthetic import generate_corpus
    generate_corpus(folder / "corpus", people=3, actions=["walk", "ascend"], seed=1,
                    file_format="csv")
    angles = folder / "angles"
    angles.mkdir()
    for path in (folder / "corpus" / "truth").glob("*_angles.csv"):
        shutil.copy(path, angles / path.name)
    assert main(["decompose", str(angles), "-o", str(folder / "model.npz")]) == 0
    person = sorted(angles.iterdir())[0].name.split("_")[0]
    bvh = folder / "synthesised.bvh"
    assert main(["synthesize", str(folder / "model.npz"), "--person", person, "--action",
                 "walk", "-o", str(bvh)]) == 0
    return bvh


@pytest.mark.parametrize("kind", ["real C3D with plates", "bandai2 BVH", "ASF/AMC",
                                  "synthesised BVH", "generated trial"])
def test_every_kind_of_input_is_shown(browser, inputs, kind, tmp_path):
    files, frames = inputs[kind]
    page = tmp_path / "view.html"
    assert main(["view", *files, "-o", str(page)]) == 0
    browser.open(file_url(page))
    settle(browser)
    assert browser.errors() == []
    assert counter(browser) == (1, frames)
    assert blue_pixels(image(browser.screenshot("#mv-canvas"))) > 100
    scrub_to(browser, frames - 1)
    assert counter(browser) == (frames, frames)
    assert browser.errors() == []


def test_gaps_are_not_drawn_and_files_overlay_in_their_own_colours(browser, inputs, tmp_path):
    files, frames = inputs["generated trial"]
    trial = read(files[0])
    page = tmp_path / "view.html"
    bvh = inputs["synthesised BVH"][0][0]
    assert main(["view", files[0], bvh, "-o", str(page)]) == 0
    browser.open(file_url(page))
    frame, marker = (int(i[0]) for i in np.nonzero(np.isnan(trial.points[..., 0])))
    present = int(np.flatnonzero(np.isfinite(trial.points[frame, :, 0]))[0])
    scrub_to(browser, frame)
    assert browser.evaluate(f"mocapView.drawn(0, {marker})") is False
    assert browser.evaluate(f"mocapView.drawn(0, {present})") is True
    colours = browser.evaluate("[...document.querySelectorAll('#mv-legend i')]"
                               ".map(i => i.style.background)")
    assert len(colours) == 2 and colours[0] != colours[1]
    pixels = image(browser.screenshot("#mv-canvas"))
    orange = ((pixels[..., 0] - pixels[..., 2]) > 60) & (pixels[..., 1] < 160)   # #e4572e
    assert blue_pixels(pixels) > 50 and orange.sum() > 50
    assert browser.errors() == []


def test_a_check_draws_its_estimated_ground_reaction(browser, tmp_path, capsys):
    bvh = DATA / "mocapbank_walk.bvh"
    capsys.readouterr()
    assert main(["check", str(bvh), "--json"]) == 0
    check = json.loads(capsys.readouterr().out)
    (tmp_path / "check.json").write_text(json.dumps(check))
    page = tmp_path / "view.html"
    assert main(["view", str(bvh), "--check", str(tmp_path / "check.json"), "-o", str(page)]) == 0
    browser.open(file_url(page))
    scrub_to(browser, 3)
    arrows = browser.evaluate("mocapView.arrows()")
    feet = check["ground_reaction"]["feet"]
    assert [a["name"] for a in arrows] == [f"check {foot}" for foot in feet] \
        == ["check l_foot", "check r_foot"]
    for arrow, foot in zip(arrows, feet.values()):
        force = np.linalg.norm(foot["force_N"][3])
        assert arrow["visible"] == (force >= 20)
        if arrow["visible"]:
            assert np.allclose(arrow["position"], foot["point_m"][3], atol=1e-4)
            assert arrow["length"] == pytest.approx(force / 1000, rel=1e-4)
    assert any(a["visible"] for a in arrows)
    # the feet carry the whole estimated reaction
    total = np.sum([f["force_N"][3] for f in feet.values()], axis=0)
    assert np.allclose(total, check["ground_reaction"]["force_N"][3], atol=0.02)
    assert "check: " + check["verdict"] in browser.evaluate(
        "document.getElementById('mv-readout').textContent")
    assert browser.errors() == []
