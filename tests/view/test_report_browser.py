"""``mocap report`` pages in a real headless chromium (Debian's, installed by .ci/run).

The report of a real walk with Vicon's stored outputs (angles, moments, powers) opens from
disk with no console error and fetches nothing; every figure is present, drawn (its
pixels not blank) and shows both sides' curves. Without chromium the tests skip, except
under CI (MOCAP_REQUIRE_REALDATA=1) where they fail.
"""
from __future__ import annotations

import base64
import io
import re

import numpy as np
import pytest

from mocap.cli import main
from mocap.plugingait.report import SIDE_COLOURS, figure_ids
from tests.conftest import realdata_path
from tests.view.chromium import file_url
from tests.view.conftest import require_chromium

WALK = ("biomechzoo_sample_study", "HC002D", "Straight", "HC002D06.c3d")


def pixels_of(png: bytes) -> np.ndarray:
    from PIL import Image
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=int)


def near(pixels: np.ndarray, colour: str, tolerance: int = 40) -> int:
    """Pixels within ``tolerance`` (each channel) of a #rrggbb colour."""
    rgb = np.array([int(colour[i:i + 2], 16) for i in (1, 3, 5)])
    return int((np.abs(pixels - rgb) <= tolerance).all(axis=-1).sum())


def figure_pixels(browser, ident: str) -> np.ndarray:
    """The figure as the page draws it: a screenshot of its box in page coordinates."""
    box = browser.evaluate(f"(() => {{ const r = document.getElementById('{ident}')"
                           ".getBoundingClientRect(); return [r.x + scrollX, r.y + scrollY, "
                           "r.width, r.height]; })()")
    clip = dict(zip(("x", "y", "width", "height"), box), scale=1)
    shot = browser.send("Page.captureScreenshot", session=True, format="png", clip=clip,
                        captureBeyondViewport=True)
    return pixels_of(base64.b64decode(shot["data"]))


@pytest.fixture(scope="module")
def stored_report(tmp_path_factory):
    """The report of a walk from Vicon's stored outputs, and its PDF (--pdf, chromium)."""
    require_chromium()
    out = tmp_path_factory.mktemp("report") / "HC002D.html"
    assert main(["report", str(realdata_path(*WALK)), "--stored", "-o", str(out),
                 "--pdf", str(out.with_suffix(".pdf"))]) == 0
    return out


def test_the_pdf_holds_the_pages(stored_report):
    data = stored_report.with_suffix(".pdf").read_bytes()
    assert data.startswith(b"%PDF-")
    pages = len(re.findall(rb"/Type\s*/Page[^s]", data))
    # provenance, tables, the profile and four figure groups of 3-7 rows: several A4 pages
    assert pages >= 3, pages


def test_the_report_renders_every_figure_without_error(browser, stored_report):
    ids = figure_ids(stored_report.read_text(encoding="utf-8"))
    assert ids == ["figure-profile", "figure-angles-lower", "figure-angles-upper",
                   "figure-moments", "figure-powers"]
    browser.open(file_url(stored_report))
    assert browser.errors() == []
    assert browser.evaluate("performance.getEntriesByType('resource').map(e => e.name)") == []
    assert browser.evaluate("[...document.querySelectorAll('figure.plot')].map(f => f.id)") == ids
    for ident in ids:
        size = browser.evaluate(f"(() => {{ const r = document.querySelector('#{ident} svg')"
                                ".getBoundingClientRect(); return [r.width, r.height]; })()")
        assert size[0] > 400 and size[1] > 150, (ident, size)
        pixels = figure_pixels(browser, ident)
        inked = int((pixels.sum(axis=-1) < 600).sum())            # not white
        assert inked > 0.01 * pixels.shape[0] * pixels.shape[1], ident
        for side, colour in SIDE_COLOURS.items():                  # left and right drawn
            assert near(pixels, colour) > 50, (ident, side)


def test_the_tables_are_filled(browser, stored_report):
    browser.open(file_url(stored_report))
    cells = browser.evaluate("[...document.querySelectorAll('#scores-table td')]"
                             ".map(c => c.textContent)")
    assert len(cells) == 9 * 4 and all(c != "—" for c in cells)     # 9 GVS rows
    speed = browser.evaluate("[...document.querySelectorAll('#parameters-table tr')]"
                             ".find(r => r.textContent.startsWith('Walking Speed'))"
                             ".textContent")
    assert "m/s" in speed
