"""Shared fixtures: the real-data corpus beside the checkout and small helpers."""
from __future__ import annotations

import os
from pathlib import Path

import pytest

#: ../shared/realdata relative to the checkout (CI puts shared/ beside it).
REALDATA = Path(__file__).resolve().parents[1].parent / "shared" / "realdata"
#: Set by .ci/run: a missing corpus is then a failure, never a silent skip.
REQUIRE_REALDATA = os.environ.get("MOCAP_REQUIRE_REALDATA") == "1"


def realdata_path(*parts: str) -> Path:
    """Path inside ../shared/realdata; skips (or fails under CI) when it is absent."""
    path = REALDATA.joinpath(*parts)
    if not path.exists():
        message = f"real-data corpus not found: {path}"
        if REQUIRE_REALDATA:
            pytest.fail(message + " (MOCAP_REQUIRE_REALDATA=1)")
        pytest.skip(message)
    return path


@pytest.fixture
def realdata() -> Path:
    """The ../shared/realdata folder (skip or fail when absent, see realdata_path)."""
    return realdata_path()


def require_module(name: str):
    """Import an external tool the interop tests run (opensim, bvhio).

    Skips when it is not installed, except under CI (MOCAP_REQUIRE_REALDATA=1, set by
    .ci/run, which installs the ``interop`` extra): there a missing tool fails.
    """
    import importlib

    try:
        return importlib.import_module(name)
    except ImportError as error:
        message = f"{name} is not installed ({error}); pip install '.[interop]'"
        if REQUIRE_REALDATA:
            pytest.fail(message + " (MOCAP_REQUIRE_REALDATA=1)")
        pytest.skip(message)
