"""Progress bars for long work (tqdm), quiet when output is not a terminal.

tqdm is imported only when a bar is shown (it costs ~40 ms of start-up, more than a quick
``mocap info`` spends on its work).
"""
from __future__ import annotations

import contextlib
import sys
from typing import Iterable, Iterator, TypeVar

T = TypeVar("T")


def progress(items: Iterable[T], description: str, total: int | None = None,
             enabled: bool | None = None) -> Iterator[T]:
    """Iterate over ``items`` with a progress bar on stderr.

    Parameters
    ----------
    items : iterable
    description : str
        Shown before the bar (``"reading trials"``).
    total : int, optional
        Number of items when ``items`` has no ``len``.
    enabled : bool, optional
        Force the bar on or off; by default it shows only when stderr is a terminal.
    """
    if enabled is None:
        enabled = sys.stderr.isatty()
    if not enabled:
        return iter(items)
    from tqdm.auto import tqdm
    return iter(tqdm(items, desc=description, total=total, disable=not enabled,
                     file=sys.stderr, leave=False, dynamic_ncols=True))


def write_line(text: str) -> None:
    """Print ``text`` on stderr above any progress bar."""
    if "tqdm" in sys.modules:
        from tqdm.auto import tqdm
        tqdm.write(text, file=sys.stderr)
    else:
        print(text, file=sys.stderr)


class _NoBar:
    def update(self, count: int = 1) -> None:
        pass


@contextlib.contextmanager
def progress_bar(total: int, description: str, enabled: bool | None = None):
    """A bar of ``total`` steps for work that is not a loop of ours (``bar.update(1)``);
    shown only on a terminal unless ``enabled``."""
    if enabled is None:
        enabled = sys.stderr.isatty()
    if not enabled:
        yield _NoBar()
        return
    from tqdm.auto import tqdm
    with tqdm(total=total, desc=description, file=sys.stderr, leave=False,
              dynamic_ncols=True) as bar:
        yield bar
