"""Analyse every trial of a corpus in parallel: processes on one machine or a Dask cluster.

Each trial becomes one row of a table (file facts, joint-angle ranges of motion and,
on request, the humanoid dynamics check).  A trial that fails becomes a row with its
error message; the others still finish.  The same rows come out whichever executor ran
them, in the order of the input paths.
"""
from __future__ import annotations

import csv
import io as _io
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Iterable, Sequence

from mocap.errors import MocapError
from mocap.io.discovery import parse_trial_name
from mocap.progress import progress

#: Marker-file suffixes a corpus folder is searched for.
TRIAL_SUFFIXES = (".c3d", ".trc", ".csv")
#: First columns of every row; per-segment range-of-motion columns follow.
BASE_COLUMNS = ["path", "person", "action", "status", "error", "format", "rate_hz", "frames",
                "duration_s", "markers", "missing_pct"]
CHECK_COLUMNS = ["residual_force_rms_pct_bw", "foot_skate_mm", "penetration_mm", "floating_mm",
                 "verdict"]


def find_trials(corpus: str | os.PathLike) -> list[Path]:
    """Marker files directly inside ``corpus`` (a folder) or the file itself, sorted."""
    corpus = Path(corpus)
    if corpus.is_file():
        return [corpus]
    if not corpus.is_dir():
        raise MocapError("no such file or folder", corpus)
    paths = sorted(p for p in corpus.iterdir()
                   if p.is_file() and p.suffix.lower() in TRIAL_SUFFIXES)
    if not paths:
        raise MocapError(f"no marker files ({', '.join(TRIAL_SUFFIXES)}) in this folder", corpus)
    return paths


def analyse_trial(path: str, markerset: str | None = None, sequence: str = "ZXY",
                  check: bool = False, mass_kg: float = 75.0) -> dict:
    """One row of the batch table for the trial at ``path``; never raises for bad input.

    Parameters
    ----------
    path : str
        Marker file.
    markerset : str, optional
        Preset name or TOML path; with it, joint-angle ranges of motion are added
        as ``<segment>_rom_deg`` (largest range of the three angles, degrees).
    sequence : str
        Euler sequence for the angles.
    check : bool
        Also run the humanoid dynamics check (needs a full-body marker set).
    mass_kg : float
        Body mass for the check.

    Returns
    -------
    dict
        Column → value; ``status`` is ``"ok"`` or ``"failed"`` with ``error`` set.
    """
    import numpy as np

    from mocap import io

    try:
        person, action = parse_trial_name(path)
    except MocapError:                  # not a corpus name: the trial is analysed all the same
        person, action = "", ""
    row = {"path": str(path), "person": person, "action": action, "status": "ok", "error": ""}
    try:
        trial = io.read(path)
        missing = np.isnan(trial.points).any(axis=2).mean() if trial.points.size else 0.0
        row.update(format=trial.format, rate_hz=round(trial.rate, 6), frames=trial.frames,
                   duration_s=round(trial.duration, 6), markers=len(trial.labels),
                   missing_pct=round(100.0 * float(missing), 3))
        if markerset:
            from mocap.angles import joint_angles
            from mocap.markersets.model import load_markerset

            chosen = load_markerset(markerset)
            angles = joint_angles(trial, chosen, sequence=sequence)
            ranges = np.nanmax(angles.values, axis=0) - np.nanmin(angles.values, axis=0)
            for segment, span in zip(angles.segments, np.nanmax(ranges, axis=1)):
                row[f"{segment}_rom_deg"] = round(float(span), 3)
            if check:
                from dynamics.humanoid.core import check_motion
                from mocap.skeleton import motion_from_trial

                report = check_motion(motion_from_trial(trial, chosen), body_mass=mass_kg).summary()
                for key in CHECK_COLUMNS:
                    value = report[key]
                    row[key] = round(value, 3) if isinstance(value, float) else value
    except MocapError as error:
        row.update(status="failed", error=str(error))
    except Exception as error:  # a bug of ours or a file no reader anticipated: report, go on
        row.update(status="failed", error=f"{path}: {type(error).__name__}: {error}")
    return row


def run_batch(paths: Sequence[str | os.PathLike], jobs: int = 1, markerset: str | None = None,
              sequence: str = "ZXY", check: bool = False, mass_kg: float = 75.0,
              dask: bool = False, scheduler: str | None = None,
              show_progress: bool | None = None) -> list[dict]:
    """Analyse ``paths`` in parallel and return the rows in input order.

    Parameters
    ----------
    paths : sequence of path
    jobs : int
        Worker processes (``1``: in this process).  With ``dask`` and no
        ``scheduler``, the size of the LocalCluster.
    dask : bool
        Run on a Dask distributed cluster (a LocalCluster unless ``scheduler``).
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``); implies ``dask``.
    markerset, sequence, check, mass_kg
        As in :func:`analyse_trial`.
    """
    arguments = dict(markerset=markerset, sequence=sequence, check=check, mass_kg=mass_kg)
    names = [str(p) for p in paths]
    if jobs < 1:
        raise MocapError(f"--jobs must be at least 1, got {jobs}")
    if dask or scheduler:
        return _run_dask(names, jobs, scheduler, arguments, show_progress)
    if jobs == 1:
        return [analyse_trial(p, **arguments)
                for p in progress(names, "analysing trials", enabled=show_progress)]
    rows: list[dict | None] = [None] * len(names)
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        futures = {pool.submit(analyse_trial, p, **arguments): i for i, p in enumerate(names)}
        for future in progress(as_completed(futures), "analysing trials", total=len(names),
                               enabled=show_progress):
            rows[futures[future]] = future.result()
    return rows  # type: ignore[return-value]


def _run_dask(names: list[str], jobs: int, scheduler: str | None, arguments: dict,
              show_progress: bool | None) -> list[dict]:
    try:
        from dask.distributed import Client, LocalCluster, as_completed as dask_completed
    except ImportError:
        raise MocapError("Dask is not installed: pip install 'mocap-toolkit[distributed]'") from None
    cluster = None
    try:
        if scheduler:
            try:
                client = Client(scheduler, timeout="10s")
            except OSError as error:
                raise MocapError(f"cannot reach the Dask scheduler at {scheduler}: {error}") from None
        else:
            cluster = LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
        with client:
            futures = [client.submit(analyse_trial, p, pure=False, **arguments) for p in names]
            index = {f.key: i for i, f in enumerate(futures)}
            rows: list[dict | None] = [None] * len(names)
            for future in progress(dask_completed(futures), "analysing trials (dask)",
                                   total=len(names), enabled=show_progress):
                rows[index[future.key]] = future.result()
        return rows  # type: ignore[return-value]
    finally:
        if cluster is not None:
            cluster.close()


def rows_to_csv(rows: Iterable[dict]) -> str:
    """The batch table as CSV text: base columns, the check's, then every other column seen."""
    rows = list(rows)
    extra = []
    for row in rows:
        extra += [k for k in row if k not in BASE_COLUMNS and k not in CHECK_COLUMNS
                  and k not in extra]
    columns = BASE_COLUMNS + [c for c in CHECK_COLUMNS if any(c in r for r in rows)] + extra
    buffer = _io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, restval="", lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buffer.getvalue()
