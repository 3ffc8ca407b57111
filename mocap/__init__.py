"""mocap: motion capture analysis, synthesis and dynamics — marker data in, angles out.

Read C3D/CSV/TRC marker files into a :class:`~mocap.trial.Trial`, fill gaps and
filter, build segment frames from three markers per segment and extract joint
angles in any Euler sequence, or Plug-in Gait's clinical angles.

The everyday calls are here at the top:

>>> import mocap
>>> sorted(name for name in mocap.__all__ if name[0].islower())   # doctest: +NORMALIZE_WHITESPACE
['clinical_angles', 'file_kind', 'fill_gaps', 'joint_angles', 'load_markerset', 'lowpass',
 'marker_file_angles', 'read', 'read_motion', 'write']

``import mocap`` is light (numpy and the readers load on first use), so the ``mocap``
command starts quickly and Ctrl-C at start-up is caught by it.
"""
#: Public name -> module that defines it (imported on first use).
_HOMES = {
    "MocapError": "mocap.errors",
    "MocapWarning": "mocap.errors",
    "Trial": "mocap.trial",
    "read": "mocap.io",
    "write": "mocap.io",
    "file_kind": "mocap.io",
    "read_motion": "mocap.io.motion",
    "load_markerset": "mocap.markersets",
    "joint_angles": "mocap.rotations.angles",
    "fill_gaps": "mocap.clean.gapfill",
    "lowpass": "mocap.clean.filtering",
    "marker_file_angles": "mocap.pipeline",
    "clinical_angles": "mocap.pipeline",
    "Cleaning": "mocap.pipeline",
}

__all__ = ["Cleaning", "MocapError", "MocapWarning", "Trial", "clinical_angles", "file_kind",
           "fill_gaps", "joint_angles", "load_markerset", "lowpass", "marker_file_angles",
           "read", "read_motion", "write"]


def __getattr__(name: str):
    # deferred: ``import mocap`` imports nothing, so the ``mocap`` command's Ctrl-C
    # handler (mocap/__main__.py) is in place before any import can be cut
    if name in _HOMES:
        import importlib
        return getattr(importlib.import_module(_HOMES[name]), name)
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version
        try:
            return version("mocap-toolkit")     # the one version string: pyproject.toml
        except PackageNotFoundError:            # a source tree that is not installed
            return "unknown"
    raise AttributeError(f"module 'mocap' has no attribute {name!r}")
