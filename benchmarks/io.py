"""Marker-file reading speed: our checked C3D reader against ezc3d and the ``c3d`` package.

Prints, for a few real files (../shared/realdata) and a large synthetic one,
the time per read of

- ``mocap.io.read`` (structure check + our vectorised decoder, the default),
- the structure check alone (``inspect_c3d``),
- ezc3d in the same process (no check),
- ezc3d in a child process, which is what a guard against ezc3d crashes would cost,
- the pure-Python ``c3d`` package (first 300 frames, scaled to the file),

and, for TRC and CSV files of 20 000 frames × 60 markers (2 % gaps), the write and read
times of the toolkit beside, in the same run, a plain numpy reference (``np.savetxt`` with
the same 6 decimals, ``np.loadtxt``) and the toolkit's previous text code (``repr`` per
cell, ``np.loadtxt`` with a Python split per row for rows with gaps). Ratios are against
``mocap.io.read`` in the same run. Never asserts; run ``python benchmarks/io.py``.
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mocap.io import read, write                      # noqa: E402
from mocap.io.c3d.layout import inspect_c3d           # noqa: E402
from mocap.trial import Trial                         # noqa: E402
from timing import best_of   # benchmarks/timing.py

REALDATA = ROOT.parent / "shared" / "realdata"
FILES = [
    "biomechzoo_sample_study/HC030A/Turn/HC030A22.c3d",      # Vicon PiG, 556 × 290 points
    "c3dorg_via_c3dio/sample_34/AlbertoINT.c3d",             # Xsens, 4921 frames, integers
    "ezc3d_testFiles/Vicon.c3d",                             # 580 frames + 38 analog channels
    "c3dorg_via_c3dio/sample_22/BKINtechnologies.c3d",       # KINARM, 5065 frames
]


def ezc3d_in_process(path: Path) -> None:
    import ezc3d

    ezc3d.c3d(str(path), extract_forceplat_data=False)


def ezc3d_in_child(path: Path) -> None:
    code = ("import sys, ezc3d, numpy; c = ezc3d.c3d(sys.argv[1]); "
            "sys.stdout.buffer.write(numpy.ascontiguousarray(c['data']['points']).tobytes()[:16])")
    subprocess.run([sys.executable, "-c", code, str(path)], check=True, capture_output=True,
                   timeout=600)


def c3d_package(path: Path, frames: int = 300) -> float:
    """Seconds for the whole file, extrapolated from the first ``frames`` frames."""
    import c3d

    with open(path, "rb") as handle, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reader = c3d.Reader(handle)
        total = reader.frame_count
        start = time.perf_counter()
        count = 0
        for _ in reader.read_frames():
            count += 1
            if count == frames:
                break
        return (time.perf_counter() - start) * total / max(count, 1)


def report(name: str, path: Path, slow_ezc3d: bool = False) -> None:
    ours = best_of(lambda: read(path), repeats=5)
    check = best_of(lambda: inspect_c3d(path), repeats=5)
    print(f"{name:58s} mocap.io.read {1e3 * ours:8.1f} ms   check alone {1e3 * check:6.1f} ms")
    if slow_ezc3d:
        print(f"{'':58s} ezc3d: skipped (stalls ~30 s before raising on this file)")
    else:
        inside = best_of(lambda: ezc3d_in_process(path), 3)
        child = best_of(lambda: ezc3d_in_child(path), 2)
        print(f"{'':58s} ezc3d in process {1e3 * inside:8.1f} ms ({inside / ours:5.1f}×)   "
              f"in a child {1e3 * child:8.1f} ms ({child / ours:5.1f}×)")
    try:
        package = c3d_package(path)
    except Exception as error:      # the package refuses some valid files
        print(f"{'':58s} c3d package refuses the file: {type(error).__name__}")
        return
    print(f"{'':58s} c3d package {1e3 * package:10.1f} ms ({package / ours:7.1f}×)")


def main() -> None:
    print(f"python {sys.version.split()[0]}, numpy {np.__version__}")
    with tempfile.TemporaryDirectory() as folder:
        rng = np.random.default_rng(0)
        frames, markers = 20000, 60
        points = rng.normal(0.0, 1.0, (frames, markers, 3))
        points[rng.random((frames, markers)) < 0.02] = np.nan
        trial = Trial([f"M{i:02d}" for i in range(markers)], points, 200.0)
        big = Path(folder) / "big.c3d"
        write(trial, big)
        report(f"synthetic {frames} frames × {markers} markers (float)", big)
        for relative in FILES:
            path = REALDATA / relative
            if path.exists():
                report(relative, path, slow_ezc3d="BKIN" in relative)
        text_formats(trial, Path(folder))


def previous_format_rows(columns: np.ndarray, delimiter: str) -> str:
    """The toolkit's text writer before the compiled one: ``repr`` of every cell."""
    rows, cols = columns.shape
    cells = ["" if value != value else repr(value) for value in columns.ravel().tolist()]
    return "".join(delimiter.join(cells[r * cols:(r + 1) * cols]) + "\n"
                   for r in range(rows))


def previous_parse_rows(lines: list[str], delimiter: str, width: int) -> np.ndarray:
    """The toolkit's text reader before the compiled one (loadtxt, else a split per row)."""
    try:
        table = np.loadtxt(lines, delimiter=delimiter, ndmin=2, dtype=float)
        if table.shape[1] >= width:
            return table[:, :width]
    except ValueError:
        pass
    table = np.full((len(lines), width), np.nan)
    for row, line in enumerate(lines):
        for column, cell in enumerate(line.split(delimiter)[:width]):
            cell = cell.strip()
            if cell:
                try:
                    table[row, column] = float(cell)
                except ValueError:
                    pass
    return table


def text_formats(trial: Trial, folder: Path) -> None:
    """TRC and CSV write/read of the toolkit, numpy's savetxt/loadtxt and the previous code."""
    from mocap.io.text_table import parse_table
    from mocap.io.text_format import format_table

    frames, markers = trial.points.shape[:2]
    table = np.column_stack([trial.times, trial.points.reshape(frames, -1) * 1000.0])
    write(trial, folder / "warm.trc")               # compiled loops: load once
    read(folder / "warm.trc")
    print(f"\ntext tables, {frames} frames × {markers} markers, 2 % gaps (best of 3):")
    ours = {}
    for suffix in (".trc", ".csv"):
        target = folder / f"big{suffix}"
        ours_write = best_of(lambda: write(trial, target), 3)
        ours_read = best_of(lambda: read(target), 3)
        ours[suffix] = (ours_write, ours_read)
        back = read(target)
        error = np.nanmax(np.abs(back.points - trial.points))
        print(f"  mocap {suffix}: write {ours_write:6.3f} s, read {ours_read:6.3f} s "
              f"({frames * markers / ours_read / 1e6:5.2f} M marker-frames/s); "
              f"largest round-trip error {error:.2e} m (1 nm precision: <= 5e-10)")
    delimiter = "\t"
    reference = folder / "numpy.txt"
    np_write = best_of(lambda: np.savetxt(reference, table, fmt="%.6f", delimiter=delimiter), 3)
    np_read = best_of(lambda: np.loadtxt(reference, delimiter=delimiter), 3)
    print(f"  numpy savetxt('%.6f') / loadtxt of the same table: write {np_write:6.3f} s, "
          f"read {np_read:6.3f} s")
    kernel_write = best_of(lambda: format_table(table, 6, delimiter), 3)
    text = format_table(table, 6, delimiter)
    kernel_read = best_of(lambda: parse_table(text, delimiter, table.shape[1]), 3)
    print(f"  mocap format_table / parse_table alone: write {kernel_write:6.3f} s, "
          f"read {kernel_read:6.3f} s")
    old_write = best_of(lambda: previous_format_rows(table, delimiter), 1)
    old_text = previous_format_rows(table, delimiter)
    lines = old_text.splitlines()
    old_read = best_of(lambda: previous_parse_rows(lines, delimiter, table.shape[1]), 1)
    trc_write, trc_read = ours[".trc"]
    print(f"  previous text code (repr cells, loadtxt/split): write {old_write:6.3f} s, read "
          f"{old_read:6.3f} s -> mocap TRC now {old_write / trc_write:4.1f}x faster writing, "
          f"{old_read / trc_read:4.1f}x reading")


if __name__ == "__main__":
    main()
