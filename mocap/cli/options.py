"""The one home of numeric option checks: argparse ``type=`` validators.

Every numeric option of every command is parsed by :func:`real` or :func:`whole`, so a
value that is not finite or out of range stops the command at parsing with one line that
states the limit (``mocap check: error: argument --mu: must be a finite number >= 0, not
'nan'``) and exit status 2, before any file is read or written.

Examples
--------
>>> rate = real(above=0)
>>> rate("100")
100.0
>>> rate("nan")
Traceback (most recent call last):
...
argparse.ArgumentTypeError: must be a finite number > 0, not 'nan'
>>> whole(0, 10)("11")
Traceback (most recent call last):
...
argparse.ArgumentTypeError: must be a whole number from 0 to 10, not '11'
"""
from __future__ import annotations

import argparse
import math
from typing import Callable

#: Largest seed numpy's generators take from the command line (2**32 - 1).
MAX_SEED = 2 ** 32 - 1


def _limits(minimum, maximum, above, below) -> str:
    words = []
    if above is not None:
        words.append(f"> {above:g}")
    if minimum is not None:
        words.append(f">= {minimum:g}")
    if below is not None:
        words.append(f"< {below:g}")
    if maximum is not None:
        words.append(f"<= {maximum:g}")
    return " and ".join(words)


def real(minimum: float | None = None, maximum: float | None = None, *,
         above: float | None = None, below: float | None = None) -> Callable[[str], float]:
    """A ``type=`` for a finite float within the bounds (``minimum``/``maximum`` inclusive,
    ``above``/``below`` exclusive)."""
    limits = _limits(minimum, maximum, above, below)
    rule = "a finite number" + (f" {limits}" if limits else "")

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {rule}, not {text!r}") from None
        if not (math.isfinite(value)
                and (minimum is None or value >= minimum)
                and (maximum is None or value <= maximum)
                and (above is None or value > above)
                and (below is None or value < below)):
            raise argparse.ArgumentTypeError(f"must be {rule}, not {text!r}")
        return value

    parse.__name__ = "number"
    return parse


def real_or(word: str, minimum: float | None = None, maximum: float | None = None, *,
            above: float | None = None, below: float | None = None) -> Callable[[str], float | str]:
    """A ``type=`` for ``word`` (any case; returned as given in lower case) or a finite float
    within the bounds, as :func:`real` checks it (``--floor auto``, ``--ridge auto``).

    >>> real_or("auto", -1000, 1000)("1e23")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: must be 'auto' or a finite number >= -1000 and <= 1000, not '1e23'
    """
    number = real(minimum, maximum, above=above, below=below)
    rule = f"'{word}' or a finite number {_limits(minimum, maximum, above, below)}".rstrip()

    def parse(text: str) -> float | str:
        if text.strip().lower() == word:
            return word
        try:
            return number(text)
        except argparse.ArgumentTypeError:
            raise argparse.ArgumentTypeError(f"must be {rule}, not {text!r}") from None

    parse.__name__ = f"number or {word}"
    return parse


def whole(minimum: int | None = None, maximum: int | None = None) -> Callable[[str], int]:
    """A ``type=`` for a whole number within ``[minimum, maximum]`` (either may be open)."""
    if minimum is not None and maximum is not None:
        rule = f"a whole number from {minimum} to {maximum}"
    elif minimum is not None:
        rule = f"a whole number >= {minimum}"
    elif maximum is not None:
        rule = f"a whole number <= {maximum}"
    else:
        rule = "a whole number"

    def parse(text: str) -> int:
        try:
            value = int(text.strip().replace("_", ""))
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {rule}, not {text!r}") from None
        if (minimum is not None and value < minimum) or (maximum is not None and value > maximum):
            raise argparse.ArgumentTypeError(f"must be {rule}, not {text!r}")
        return value

    parse.__name__ = "whole number"
    return parse


# The options several commands share, checked the same way everywhere.
#: A sampling or frame rate, Hz. The floor keeps what follows from a rate finite: frame
#: times, finite-difference weights (1/rate to the power of the derivative), GIF delays.
RATE = real(minimum=1e-3, maximum=1e6)
#: A random seed.
SEED = whole(0, MAX_SEED)
#: A body mass, kg. The floor keeps what divides by it finite (% body weight of a
#: denormal mass was infinite: 'check --json --mass 5e-324' traced back in json).
MASS = real(minimum=1e-3, maximum=1000)
#: A gap length in seconds.
SECONDS_GAP = real(minimum=0, maximum=3600)
#: A low-pass cut-off, Hz.
CUTOFF = real(above=0, maximum=1e6)
#: A Butterworth order (scipy designs are unstable long before 20).
FILTER_ORDER = whole(1, 20)
#: People in a generated corpus.
PEOPLE = whole(1, 200)
#: Frames per second of an animation.
FPS = real(minimum=0.01, maximum=100)
#: Worker processes.
JOBS = whole(1, 256)
