"""The built-in data the package installs and uses (``data/`` at the top of the checkout:
marker-set presets, example scenes), found the same way in a checkout and an installed copy.

An installed copy holds it inside the package (``mocap/data``, mapped by ``pyproject.toml``);
a checkout, and an editable install, at the top of the tree beside ``mocap/``.
"""
from __future__ import annotations

from pathlib import Path


def data_path(*parts: str) -> Path:
    """Path of built-in data, e.g. ``data_path("markersets", "synthetic15.toml")``.

    >>> data_path("scenes").is_dir()
    True
    """
    package = Path(__file__).resolve().parent
    installed = package / "data"
    root = installed if installed.is_dir() else package.parent / "data"
    return root.joinpath(*parts)
