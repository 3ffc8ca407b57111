"""The ``mocap`` command's entry point: ``python -m mocap`` and the console script
(``[project.scripts]`` in pyproject.toml names :func:`run`).

Ctrl-C is one line and exit status 130 from the first moment. The synthesis commands get one
BLAS thread unless the user set a count (:func:`one_blas_thread`), before numpy is imported. Before anything heavy is
imported, SIGINT gets :func:`interrupted_at_start`, which says so and leaves at once: nothing
has been read or written yet, so there is nothing to clean up, and no KeyboardInterrupt can
surface half-way through an import as a traceback (or as another exception, or as
"Exception ignored in …" text). Once the command's options are parsed, :func:`mocap.cli.main`
puts its own handler in its place, which lets the command's clean-up run.

The handler is installed when this module is imported, which only the entry points do. It
imports only ``os``, ``sys`` and ``_signal`` (all loaded by the interpreter itself) and ``import
mocap`` imports nothing, so the window before the handler is the interpreter's own start-up
(``site``, ``.pth`` files, the console script's ``import re``), which no Python code can
guard.
"""
import os
import sys

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

#: Commands whose linear algebra is thousands of small products (the synthesis model's
#: leave-one-out selections, matrices of a few dozen rows): a threaded BLAS only spins on
#: them. On bandai2, ``evaluate --leave-one-out`` took 8.7 s CPU with OpenBLAS's threads and
#: 5.4 s with one, in the same wall time; ``decompose`` 3.2 s and 2.8 s
#: (benchmarks/synthesis_corpus.py).
SMALL_ALGEBRA_COMMANDS = ("decompose", "evaluate", "recognize", "synthesize")
#: The variables the BLAS libraries numpy is built with read for their thread count.
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def one_blas_thread(arguments: list, environment) -> None:
    """For a command of :data:`SMALL_ALGEBRA_COMMANDS`, one BLAS thread unless the user set
    a count: sets each of :data:`BLAS_THREAD_VARIABLES` not already in ``environment`` (the
    process's ``os.environ`` before numpy is imported; a mapping in tests)."""
    if len(arguments) > 1 and arguments[1] in SMALL_ALGEBRA_COMMANDS:
        for name in BLAS_THREAD_VARIABLES:
            environment.setdefault(name, "1")


def run() -> None:
    """The ``mocap`` command: the start-up handler, then the shell (:func:`mocap.cli.run`)."""
    _catch_interrupts_at_start()
    one_blas_thread(sys.argv, os.environ)
    from mocap.cli import run as shell
    shell()


if __name__ == "__main__":
    run()
