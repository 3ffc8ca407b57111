"""Run one function over many trials in parallel: processes on one machine or a Dask cluster.

The executor only: what a row holds is the caller's (``mocap batch``'s rows are built by
:mod:`mocap.cli.batch_rows`).  A row function turns its failures into rows, so one bad
trial never stops the others, and the same rows come out whichever executor ran them, in
the order of the input paths.
"""
from __future__ import annotations

import contextlib
import csv
import io as _io
import logging
import os
import shutil
import signal
import tempfile
import warnings
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

from mocap.atomic import interrupts_held
from mocap.errors import MocapError
from mocap.progress import progress


def run_batch(row: Callable[..., dict], paths: Sequence[str | os.PathLike], jobs: int = 1,
              dask: bool = False, scheduler: str | None = None,
              show_progress: bool | None = None, lost: Callable[[str, str], dict] | None = None,
              **arguments: Any) -> list[dict]:
    """Run ``row(path, **arguments)`` for every path in parallel; the rows in input order.

    Parameters
    ----------
    row : callable
        ``row(path: str, **arguments) -> dict``; a module-level function (it is pickled
        to the workers), which turns every failure into a row rather than raising.
    paths : sequence of path
    jobs : int
        Worker processes (``1``: in this process).  With ``dask`` and no
        ``scheduler``, the size of the LocalCluster.
    dask : bool
        Run on a Dask distributed cluster (a LocalCluster unless ``scheduler``).
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``); implies ``dask``.
    lost : callable, optional
        ``lost(path, problem) -> dict``: the row of a trial whose worker process died
        (killed by the system); by default ``{"path", "status": "failed", "error"}``.
        The other trials go on in new workers.
    arguments
        Passed to ``row`` after the path.
    """
    names = [str(p) for p in paths]
    if jobs < 1:
        raise MocapError(f"jobs= must be at least 1, got {jobs}")
    if dask or scheduler:
        with warnings.catch_warnings():
            # Dask's warnings are about its own machinery (a dashboard port another
            # cluster holds …), not the user's trials, whose problems are in their rows
            warnings.filterwarnings("ignore", module=r"distributed(\..*)?$")
            return _run_dask(row, names, jobs, scheduler, arguments, show_progress,
                             lost or _lost_row)
    if jobs == 1:
        return [row(p, **arguments)
                for p in progress(names, "analysing trials", enabled=show_progress)]
    return _run_pool(row, names, jobs, arguments, show_progress, lost or _lost_row)


def _lost_row(path: str, problem: str) -> dict:
    """The row of a trial whose worker died: the path, ``failed`` and the problem."""
    return {"path": path, "status": "failed", "error": problem}


def _run_pool(row: Callable[..., dict], names: list[str], jobs: int, arguments: dict,
              show_progress: bool | None, lost: Callable[[str, str], dict]) -> list[dict]:
    """:func:`run_batch` on worker processes of this machine, through the death of one.

    A worker killed from outside (the out-of-memory killer, ``kill -9``) breaks the whole
    pool: every trial not yet collected fails with ``BrokenProcessPool`` (which was a
    traceback). Each worker marks the trial it is running in a file of its own, removed
    when the trial ends and when the pool stops a worker (SIGTERM); so the marks left after
    a break are the trials whose worker died. Those get ``lost``'s row naming them; the
    trials done are kept and the others run again in a new pool.
    """
    rows: list[dict | None] = [None] * len(names)
    pending = list(range(len(names)))
    with tempfile.TemporaryDirectory(prefix="mocap-batch-") as marks:
        while pending:
            broken = False
            with ProcessPoolExecutor(max_workers=min(jobs, len(pending)),
                                     initializer=_worker_start,
                                     initargs=(os.getpid(), marks)) as pool:
                futures = {pool.submit(_tracked, row, names[i], i, marks, arguments): i
                           for i in pending}
                for future in progress(as_completed(futures), "analysing trials",
                                       total=len(futures), enabled=show_progress):
                    try:
                        rows[futures[future]] = future.result()
                    except BrokenProcessPool:
                        broken = True
            dead = [int(Path(marks, name).read_text() or -1) for name in os.listdir(marks)]
            for mark in os.listdir(marks):
                os.unlink(os.path.join(marks, mark))
            for i in dead:
                if 0 <= i < len(names) and rows[i] is None:
                    rows[i] = lost(names[i], f"{names[i]}: the worker analysing this trial "
                                             f"was killed (by the system: out of memory?); "
                                             f"the other trials went on")
            pending = [i for i in pending if rows[i] is None]
            if broken and not dead:         # a death no mark names: stop with what is done
                for i in pending:
                    rows[i] = lost(names[i], f"{names[i]}: not analysed: a worker of the "
                                             f"batch died and the batch stopped")
                pending = []
    return rows  # type: ignore[return-value]


def _tracked(row: Callable[..., dict], path: str, index: int, marks: str,
             arguments: dict) -> dict:
    """``row(path, **arguments)`` in a worker, with the trial's mark (see :func:`_run_pool`)
    in place while it runs."""
    mark = os.path.join(marks, str(os.getpid()))
    with open(mark, "w") as handle:
        handle.write(str(index))
    try:
        return row(path, **arguments)
    finally:
        with contextlib.suppress(OSError):
            os.unlink(mark)


def _run_dask(row: Callable[..., dict], names: list[str], jobs: int, scheduler: str | None, arguments: dict,
              show_progress: bool | None, lost: Callable[[str, str], dict]) -> list[dict]:
    try:   # deferred: dask is an optional extra, and slow to import
        from dask.distributed import Client, LocalCluster
        from dask.distributed import as_completed as dask_completed
    except ImportError:
        raise MocapError("Dask is not installed: pip install 'mocap-toolkit[distributed]'") from None
    cluster = None
    scratch = None
    try:
        if scheduler:
            try:
                client = Client(scheduler, timeout="10s")
            except (OSError, ValueError) as error:      # unreachable, or not an address
                raise MocapError(f"cannot reach the Dask scheduler at {scheduler!r}: "
                                 f"{error}") from None
        else:
            # the workers' scratch space in a folder of ours, removed afterwards (a
            # LocalCluster leaves dask-scratch-space/ in the temporary folder otherwise);
            # a Ctrl-C meanwhile waits until the folder is known and the cluster can be
            # closed, and the workers, started with SIGINT blocked, leave it to us.  The
            # resource tracker is started first: starting it unblocks SIGINT in the
            # thread that does so, which would be the one starting the workers.
            import dask
            if os.name == "posix":
                from multiprocessing import resource_tracker
                resource_tracker.ensure_running()
            with interrupts_held(children=True):
                scratch = tempfile.mkdtemp(prefix="mocap-dask-")
                with dask.config.set({"temporary-directory": scratch}):
                    cluster = LocalCluster(n_workers=jobs, threads_per_worker=1,
                                           processes=True, dashboard_address=None,
                                           local_directory=scratch)
            client = Client(cluster)
        with client:
            futures = [client.submit(row, p, pure=False, **arguments) for p in names]
            index = {f.key: i for i, f in enumerate(futures)}
            rows: list[dict | None] = [None] * len(names)
            for future in progress(dask_completed(futures), "analysing trials (dask)",
                                   total=len(names), enabled=show_progress):
                i = index[future.key]
                try:
                    rows[i] = future.result()
                except Exception as error:      # row() never raises: the worker died
                    rows[i] = lost(names[i], f"{names[i]}: the Dask worker analysing this "
                                             f"trial died ({type(error).__name__}); the "
                                             f"other trials went on")
        return rows  # type: ignore[return-value]
    finally:
        # to the end even through Ctrl-C (held, then raised): the cluster closed without
        # its shutdown chatter, the scratch folder removed
        with interrupts_held(), _quiet_logger("distributed"):
            if cluster is not None:
                cluster.close()
            if scratch is not None:
                shutil.rmtree(scratch, ignore_errors=True)


def _worker_start(parent: int, marks: str | None = None) -> None:
    """Worker initializer: Ctrl-C goes to the parent, which stops the pool (workers print
    no tracebacks of their own); a worker ends with its parent; and a worker stopped by the
    pool (SIGTERM, when another died) removes its trial's mark in ``marks`` first.

    A parent killed outright (SIGKILL, the out-of-memory killer) cannot stop its pool: the
    workers, forked with both ends of their task queue, waited on it for ever (found by
    the hostile re-run of issue 11). On Linux the kernel sends each worker SIGKILL when
    the parent dies (``PR_SET_PDEATHSIG``); elsewhere a thread checks every second.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if marks is not None:
        def stopped(signum, frame) -> None:
            with contextlib.suppress(OSError):
                os.unlink(os.path.join(marks, str(os.getpid())))
            os._exit(1)

        signal.signal(signal.SIGTERM, stopped)
    if not _kill_with_parent():
        import threading

        def watch() -> None:
            while os.getppid() == parent:
                threading.Event().wait(1.0)
            os._exit(1)

        threading.Thread(target=watch, daemon=True).start()
    if os.getppid() != parent:              # the parent died before the guard was set
        os._exit(1)


def _kill_with_parent() -> bool:
    """Ask Linux to SIGKILL this process when its parent dies; False where it cannot."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(1, int(signal.SIGKILL), 0, 0, 0) == 0      # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return False


@contextlib.contextmanager
def _quiet_logger(name: str):
    logger = logging.getLogger(name)
    level = logger.level
    logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        logger.setLevel(level)


def rows_to_csv(rows: Iterable[dict], leading: Sequence[str] = ()) -> str:
    """The table as CSV text: the ``leading`` columns, then every other column in the order
    first seen."""
    rows = list(rows)
    columns = list(leading)
    for row in rows:
        columns += [k for k in row if k not in columns]
    buffer = _io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, restval="", lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buffer.getvalue()
