"""Sub-commands of this package for the ``mocap`` command line."""
from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add this package's sub-commands to ``subparsers``."""
