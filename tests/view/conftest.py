"""The headless browser of the viewer tests: one chromium per test module."""
from __future__ import annotations

import pytest

from tests.conftest import REQUIRE_REALDATA
from tests.view.chromium import Chromium, find_chromium


def require_chromium() -> str:
    """The chromium executable; skips without it, except under CI (MOCAP_REQUIRE_REALDATA=1,
    set by .ci/run, which installs Debian's chromium): there a missing browser fails."""
    executable = find_chromium()
    if executable is None:
        message = "chromium is not installed (apt-get install chromium)"
        if REQUIRE_REALDATA:
            pytest.fail(message + " (MOCAP_REQUIRE_REALDATA=1)")
        pytest.skip(message)
    return executable


@pytest.fixture(scope="module")
def browser():
    """A headless chromium with one page (tests/view/chromium.py)."""
    with Chromium(require_chromium()) as chromium:
        yield chromium
