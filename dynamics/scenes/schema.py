"""Scene files (TOML, ``docs/formats/scene-toml.md``): reading them and type-checked access to their tables.

Every key is checked: an unknown key, a wrong type or an impossible value is a
:class:`mocap.errors.MocapError` naming the file, the table and the key (:class:`Table`).
The shipped example scenes (``data/scenes/*.toml``) document every
table; :func:`example_scene_path` finds them by name. :mod:`dynamics.scenes.build` turns
a document into a simulation, :mod:`dynamics.scenes.run` runs it.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from mocap.errors import MocapError
from mocap.io.text_table import read_text
from mocap.resources import data_path
from mocap.tomlfile import parse_toml

#: Largest magnitude of any number in a scene (SI units: metres, kg, N/m, s, K ...). Far
#: beyond every scene's scale, and small enough that sizes cubed, spacings to the 12th power
#: and inertias stay finite: 1e300 passed as a finite number and overflowed later (a lattice
#: of size 1e300 in the fluid pair force, a 1e300 kg box, a 1e300 damping).
MAX_MAGNITUDE = 1e9


def _is_number(value) -> bool:
    """A finite int or float within +-MAX_MAGNITUDE (not a bool)."""
    return (not isinstance(value, bool) and isinstance(value, (int, float))
            and math.isfinite(value) and abs(value) <= MAX_MAGNITUDE)


#: Folder of the example scenes shipped with the package.
SCENES_DIR = data_path("scenes")

TOP_LEVEL_TABLES = {"simulation", "gravity", "damping", "particle", "spring", "cloth", "rope",
              "lattice", "fluid", "heat", "plane", "sphere", "capsule", "box", "wind", "rigid",
              "title", "description"}


# -- validated access to TOML tables ------------------------------------------------------------
class Table:
    """A TOML table whose keys are type-checked and must all be known."""

    def __init__(self, data, where: str, path):
        if not isinstance(data, dict):
            raise MocapError(f"{where} must be a table", path)
        self.data, self.where, self.path = data, where, path
        self.used: set[str] = set()

    def error(self, key: str, problem: str) -> MocapError:
        return MocapError(f"{self.where}: '{key}' {problem}", self.path)

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default=None):
        self.used.add(key)
        return self.data.get(key, default)

    def number(self, key: str, default=None, minimum=None, above=None) -> float:
        self.used.add(key)
        if key not in self.data:
            if default is None:
                raise self.error(key, "is required")
            return float(default)
        value = self.data[key]
        if not _is_number(value):
            raise self.error(key, f"must be a finite number within ±{MAX_MAGNITUDE:g}, not "
                                  f"{value!r}")
        if minimum is not None and value < minimum:
            raise self.error(key, f"must be >= {minimum}, not {value!r}")
        if above is not None and not value > above:
            raise self.error(key, f"must be > {above}, not {value!r}")
        return float(value)

    def integer(self, key: str, default=None, minimum=None) -> int:
        self.used.add(key)
        if key not in self.data:
            if default is None:
                raise self.error(key, "is required")
            return int(default)
        value = self.data[key]
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, f"must be an integer, not {value!r}")
        if minimum is not None and value < minimum:
            raise self.error(key, f"must be >= {minimum}, not {value!r}")
        return int(value)

    def boolean(self, key: str, default: bool) -> bool:
        self.used.add(key)
        value = self.data.get(key, default)
        if not isinstance(value, bool):
            raise self.error(key, f"must be true or false, not {value!r}")
        return value

    def vector(self, key: str, default=None, length: int = 3, integer: bool = False,
               minimum=None) -> np.ndarray:
        self.used.add(key)
        if key not in self.data:
            if default is None:
                raise self.error(key, "is required")
            return np.asarray(default, dtype=int if integer else float)
        value = self.data[key]
        ok = (isinstance(value, list) and len(value) == length and all(
            isinstance(v, int) if integer else isinstance(v, (int, float)) for v in value)
            and not any(isinstance(v, bool) for v in value))
        if not ok or (not integer and not all(_is_number(v) for v in value)):
            kind = "integers" if integer else f"numbers (finite, within ±{MAX_MAGNITUDE:g})"
            raise self.error(key, f"must be a list of {length} {kind}, not {value!r}")
        if minimum is not None and any(v < minimum for v in value):
            raise self.error(key, f"must have every entry >= {minimum}, not {value!r}")
        if integer and any(abs(v) > 2 ** 62 for v in value):
            raise self.error(key, f"has an entry beyond 2**62, not {value!r}")
        return np.asarray(value, dtype=int if integer else float)

    def choice(self, key: str, choices, default=None) -> str:
        self.used.add(key)
        value = self.data.get(key, default)
        if value is None:
            raise self.error(key, "is required")
        if value not in choices:
            raise self.error(key, f"must be one of {', '.join(choices)}; not {value!r}")
        return value

    def per_kind(self, key: str, default) -> dict | float:
        """A finite number from 0 to MAX_MAGNITUDE, or a {structural, shear, bend} table of
        them."""
        self.used.add(key)
        value = self.data.get(key, default)
        if isinstance(value, dict):
            unknown = set(value) - {"structural", "shear", "bend"}
            if unknown:
                raise self.error(key, f"has unknown spring kind(s) {sorted(unknown)}; "
                                      "use structural, shear, bend")
            for kind, v in value.items():
                if not (_is_number(v) and v >= 0):
                    raise self.error(key, f"{kind} must be a finite number from 0 to "
                                          f"{MAX_MAGNITUDE:g}, not {v!r}")
            return {k: float(v) for k, v in value.items()}
        if not (_is_number(value) and value >= 0):
            raise self.error(key, f"must be a finite number from 0 to {MAX_MAGNITUDE:g} or a "
                                  f"table of structural/shear/bend, not {value!r}")
        return float(value)

    def finish(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise MocapError(f"{self.where}: unknown key(s) {', '.join(map(repr, unknown))}",
                             self.path)


def tables_of(document: dict, key: str, path) -> list[Table]:
    value = document.get(key, [])
    if isinstance(value, dict):
        raise MocapError(f"'{key}' must be an array of tables: write [[{key}]]", path)
    return [Table(item, f"[[{key}]] #{n + 1}", path) for n, item in enumerate(value)]


def table_of(document: dict, key: str, path) -> Table | None:
    if key not in document:
        return None
    if isinstance(document[key], list):
        raise MocapError(f"'{key}' must be a single table: write [{key}], not [[{key}]]", path)
    return Table(document[key], f"[{key}]", path)


def example_scene_path(name: str) -> Path:
    """Path of a shipped example scene by name ("hanging-cloth" or "hanging-cloth.toml")."""
    stem = name[:-5] if name.endswith(".toml") else name
    path = SCENES_DIR / f"{stem}.toml"
    if not path.is_file():
        names = ", ".join(sorted(p.stem for p in SCENES_DIR.glob("*.toml")))
        raise MocapError(f"no such scene file or example scene (examples: {names})", name)
    return path


def read_scene_document(path: str | os.PathLike) -> dict:
    """Read a TOML scene file (``docs/formats/scene-toml.md``) as a dict; unreadable or invalid TOML is a
    :class:`~mocap.errors.MocapError` naming the file. :func:`dynamics.scenes.build.load_scene`
    builds the scene from it."""
    path = Path(path)
    return parse_toml(read_text(path, "scene file"), path, "scene file")
