"""mocap: marker data in, joint angles out.

Read C3D/CSV/TRC marker files into a :class:`~mocap.trial.Trial`, fill gaps and
filter, build segment frames from three markers per segment and extract joint
angles in any Euler sequence.
"""
from importlib.metadata import PackageNotFoundError as _PackageNotFoundError
from importlib.metadata import version as _version

from mocap.errors import MocapError, MocapWarning
from mocap.trial import Trial

__all__ = ["MocapError", "MocapWarning", "Trial"]

try:
    __version__ = _version("mocap-toolkit")     # the one version string: pyproject.toml
except _PackageNotFoundError:                   # a source tree that is not installed
    __version__ = "unknown"
