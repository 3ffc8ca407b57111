"""The one exception type for users' mistakes (bad files, bad options), and the rule.

The rule
--------
- :class:`MocapError` is raised for a bad *file* (damaged, truncated, of the wrong kind, not
  found) and a bad *user value* (a rate of 0, an unknown Euler sequence, an option out of
  range). It is a :class:`ValueError`, so library users can catch either.
- Built-in exceptions (``ValueError``, ``TypeError``, ``IndexError`` …) are for programming
  errors: arrays of the wrong shape handed in by code, broken invariants. The command line
  lets those through as tracebacks, because they are bugs to report.
- Library messages name the Python parameter (``cutoff_hz must be below the Nyquist
  frequency``); the command line words them as its flags where it validates its options.
- Messages are one line, name the file when there is one, and say what would be right.
- What a reader notices but can work around (a header that announces more frames than the
  file holds, a unit guessed) is kept in ``Trial.metadata["warnings"]`` and issued as a
  :class:`MocapWarning` by :func:`mocap.io.read`, so it reaches the user of every command.
"""
from __future__ import annotations

import contextlib
import os
from typing import Iterator


class MocapError(ValueError):
    """A problem with the user's input: a file, an option or a combination.

    The command line prints it as one line (``mocap COMMAND: error: <path>: <problem>``)
    and exits with status 2; no traceback is shown.

    Parameters
    ----------
    problem : str
        What is wrong, in words a user understands.
    path : str or os.PathLike, optional
        The file the problem is in.

    Examples
    --------
    >>> str(MocapError("truncated data section", "walk.c3d"))
    'walk.c3d: truncated data section'
    >>> isinstance(MocapError("bad"), ValueError)
    True
    """

    def __init__(self, problem: str, path: str | os.PathLike | None = None):
        self.problem = problem
        self.path = None if path is None else os.fspath(path)
        super().__init__(f"{self.path}: {problem}" if self.path else problem)


#: Characters that would break a message's one line, or the terminal, as their escapes
#: (``\n``, ``\r``, ``\x1b`` …), the way ``repr`` writes them.
_ESCAPES = {code: repr(chr(code))[1:-1]
            for code in [*range(32), *range(127, 160), 0x2028, 0x2029]}


def one_line(text: str) -> str:
    """``text`` with line breaks and other control characters escaped, so a message that
    echoes a user's value (a file name, a label) stays one line. The command line passes
    every error and warning it prints through here.

    Examples
    --------
    >>> one_line("bad\\nname.c3d: no such file")
    'bad\\\\nname.c3d: no such file'
    """
    return text.translate(_ESCAPES)


class MocapWarning(UserWarning):
    """Something about the user's input that did not stop the work but may matter (a file
    shorter than its header says, a unit that had to be guessed …).

    The command line prints each one as ``mocap COMMAND: warning: <message>``.
    """


@contextlib.contextmanager
def reading(path: str | os.PathLike, what: str = "file",
            missing: str = "no such file") -> Iterator[None]:
    """Turn the operating system's refusals while reading ``path`` into one-line
    :class:`MocapError` exceptions naming the file: ``missing`` for a file that is not there, "is a
    directory, not a <what>", "cannot read <what>: <reason>" (unreadable, undecodable).

    Examples
    --------
    >>> with reading("no/such.c3d", "C3D file"):         # doctest: +ELLIPSIS
    ...     open("no/such.c3d", "rb")
    Traceback (most recent call last):
    mocap.errors.MocapError: no/such.c3d: no such file
    """
    try:
        yield
    except FileNotFoundError:
        raise MocapError(missing, path) from None
    except IsADirectoryError:
        raise MocapError(f"is a directory, not a {what}", path) from None
    except (OSError, UnicodeDecodeError) as error:
        reason = getattr(error, "strerror", None) or error
        raise MocapError(f"cannot read {what}: {reason}", path) from None


def import_pandas():
    """pandas, which the ``to_dataframe`` methods need and the core install leaves out;
    its absence is an ImportError that says how to install it."""
    try:
        import pandas
    except ImportError:
        raise ImportError('tables as DataFrames need pandas: pip install "mocap-toolkit[tables]" '
                          '(or pip install pandas)') from None
    return pandas
