"""Trial file names of a corpus: ``<person>_<action>[_<anything>].<suffix>``."""
from __future__ import annotations

from pathlib import Path

from mocap.errors import MocapError


def parse_trial_name(path: str | Path) -> tuple[str, str]:
    """``(person, action)`` from a file named ``<person>_<action>[_<anything>].<suffix>``.

    Raises
    ------
    MocapError
        When the name has no ``_`` separating a person from an action.

    Examples
    --------
    >>> parse_trial_name("data/ana_walk_02.c3d")
    ('ana', 'walk')
    """
    parts = Path(path).stem.split("_")
    if len(parts) < 2 or not parts[0] or not parts[1]:
        raise MocapError("trial name must be <person>_<action>[_anything].<suffix> "
                         "(or use --manifest FILE.csv with columns path,person,action)", path)
    return parts[0], parts[1]
