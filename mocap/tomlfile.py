"""TOML documents (scenes, marker sets, joint maps, rotation tables) as dicts, refusing
what would crash the standard library's parser, with one-line errors naming the file."""
from __future__ import annotations

import os

from mocap.errors import MocapError


def parse_toml(text: str, path: str | os.PathLike | None = None, what: str = "file") -> dict:
    """A TOML document as a dict; invalid TOML is a :class:`MocapError` naming the file.

    Nesting deeper than :data:`TOML_MAX_DEPTH` arrays or inline tables is refused before
    parsing: the standard library's parser descends one Python call per level, so a few
    thousand ``[`` made it fail with a ``RecursionError`` traceback.

    Examples
    --------
    >>> parse_toml('dt = 0.01')
    {'dt': 0.01}
    >>> parse_toml('x = ' + '[' * 500 + ']' * 500, 'deep.toml', 'scene')  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    mocap.errors.MocapError: deep.toml: not a valid scene: arrays or inline tables nested more ...
    """
    import tomllib   # deferred: only the commands reading TOML need it

    if _toml_depth(text) > TOML_MAX_DEPTH:
        raise MocapError(f"not a valid {what}: arrays or inline tables nested more than "
                         f"{TOML_MAX_DEPTH} deep", path)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise MocapError(f"not valid TOML: {error}", path) from None
    except RecursionError:          # a nesting the bracket count below did not see
        raise MocapError(f"not a valid {what}: nested too deeply", path) from None


#: Deepest nesting of arrays and inline tables accepted in a TOML file (scenes, marker
#: sets, joint maps and hierarchies use 3 at most).
TOML_MAX_DEPTH = 100


def _toml_depth(text: str) -> int:
    """An upper bound of the nesting of ``[``/``{`` in TOML text (brackets inside strings
    and comments count too, which can only overestimate)."""
    depth = deepest = 0
    for char in text:
        if char in "[{":
            depth += 1
            if depth > deepest:
                deepest = depth
        elif char in "]}":
            depth = max(depth - 1, 0)
    return deepest
