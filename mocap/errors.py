"""The one exception type for users' mistakes (bad files, bad options)."""
from __future__ import annotations

import os


class MocapError(Exception):
    """A problem with the user's input: a file, an option or a combination.

    The command line prints it as one line (``mocap: <path>: <problem>``) and
    exits with status 2; no traceback is shown.

    Parameters
    ----------
    problem : str
        What is wrong, in words a user understands.
    path : str or os.PathLike, optional
        The file the problem is in.
    """

    def __init__(self, problem: str, path: str | os.PathLike | None = None):
        self.problem = problem
        self.path = None if path is None else os.fspath(path)
        super().__init__(f"{self.path}: {problem}" if self.path else problem)
