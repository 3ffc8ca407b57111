"""mocap: marker data in, joint angles out.

Read C3D/CSV/TRC marker files into a :class:`~mocap.trial.Trial`, fill gaps and
filter, build segment frames from three markers per segment and extract joint
angles in any Euler sequence.
"""
from mocap.errors import MocapError
from mocap.trial import Trial

__all__ = ["MocapError", "Trial"]
__version__ = "0.1.0"
