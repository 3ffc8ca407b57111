"""mocap: marker data in, joint angles out.

Read C3D/CSV/TRC marker files into a :class:`~mocap.trial.Trial`, fill gaps and
filter, build segment frames from three markers per segment and extract joint
angles in any Euler sequence.

``import mocap`` is light (numpy and the readers load on first use), so the ``mocap``
command starts quickly and Ctrl-C at start-up is caught by it.
"""
__all__ = ["MocapError", "MocapWarning", "Trial"]


def __getattr__(name: str):
    if name in ("MocapError", "MocapWarning"):
        # deferred too: ``import mocap`` imports nothing, so the ``mocap`` command's
        # Ctrl-C handler (mocap/__main__.py) is in place before any import can be cut
        import mocap.errors
        return getattr(mocap.errors, name)
    if name == "Trial":
        from mocap.trial import Trial
        return Trial
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version
        try:
            return version("mocap-toolkit")     # the one version string: pyproject.toml
        except PackageNotFoundError:            # a source tree that is not installed
            return "unknown"
    raise AttributeError(f"module 'mocap' has no attribute {name!r}")
