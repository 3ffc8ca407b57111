"""The ``mocap`` command's entry point: ``python -m mocap`` and the console script
(``[project.scripts]`` in pyproject.toml names :func:`run`).

Ctrl-C is one line and exit status 130 from the first moment. Before anything heavy is
imported, SIGINT gets :func:`interrupted_at_start`, which says so and leaves at once: nothing
has been read or written yet, so there is nothing to clean up, and no KeyboardInterrupt can
surface half-way through an import as a traceback (or as another exception, or as
"Exception ignored in …" text). Once the command's options are parsed, :func:`mocap.cli.main`
puts its own handler in its place, which lets the command's clean-up run.

The handler is installed when this module is imported, which only the entry points do. It
imports only ``os`` and ``_signal`` (both loaded by the interpreter itself) and ``import
mocap`` imports nothing, so the window before the handler is the interpreter's own start-up
(``site``, ``.pth`` files, the console script's ``import re``), which no Python code can
guard.
"""
import os

import _signal      # the C module behind ``signal``: built in and already loaded, so free


def interrupted_at_start(signum, frame) -> None:
    """SIGINT before the command has started work: one line, exit status 130, at once."""
    os.write(2, b"mocap: interrupted\n")
    os._exit(130)


#: :func:`mocap.cli.main` replaces a SIGINT handler marked so (as it does Python's default).
interrupted_at_start.replaceable = True


def _catch_interrupts_at_start() -> None:
    if _signal.getsignal(_signal.SIGINT) is _signal.default_int_handler:   # not when ignored
        _signal.signal(_signal.SIGINT, interrupted_at_start)


# at import: the console script imports this module first, then calls run()
_catch_interrupts_at_start()


def run() -> None:
    """The ``mocap`` command: the start-up handler, then the shell (:func:`mocap.cli.run`)."""
    _catch_interrupts_at_start()
    from mocap.cli import run as shell
    shell()


if __name__ == "__main__":
    run()
