"""mocap batch: the same table on processes and on a Dask LocalCluster, damaged file reported."""
from __future__ import annotations

import csv
import io
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mocap.cli import main
from mocap.synthetic import generate_corpus


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    folder = tmp_path_factory.mktemp("batch")
    files = generate_corpus(folder, people=2, actions=["walk", "ascend"], seed=1)
    damaged = folder / "zed_walk.c3d"
    damaged.write_bytes(files[0].read_bytes()[:1500])          # truncated inside the data
    return folder


def _table(text: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))


def test_processes_and_dask_give_the_same_table(corpus, tmp_path, capsys):
    pytest.importorskip("dask.distributed")
    on_processes = tmp_path / "processes.csv"
    on_dask = tmp_path / "dask.csv"
    assert main(["batch", str(corpus), "--jobs", "2", "--markerset", "synthetic15",
                 "-o", str(on_processes)]) == 1
    stderr = capsys.readouterr().err
    assert "zed_walk.c3d" in stderr and "4 of 5 trials analysed, 1 failed" in stderr
    assert main(["batch", str(corpus), "--dask", "--jobs", "2", "--markerset", "synthetic15",
                 "-o", str(on_dask)]) == 1
    assert on_processes.read_text() == on_dask.read_text()
    rows = _table(on_processes.read_text())
    assert [r["status"] for r in rows].count("failed") == 1
    failed = next(r for r in rows if r["status"] == "failed")
    assert failed["path"].endswith("zed_walk.c3d") and failed["error"]
    ok = [r for r in rows if r["status"] == "ok"]
    assert {r["action"] for r in ok} == {"walk", "ascend"}
    assert all(int(r["frames"]) > 50 and float(r["rate_hz"]) == 100.0 for r in ok)
    # knee range of motion in a walk: the generator's template swings 50-70 degrees
    walks = [r for r in ok if r["action"] == "walk"]
    assert all(40 < float(r["r_shank_rom_deg"]) < 90 for r in walks)


def test_batch_in_process_matches_and_bad_corpus_is_one_line(corpus, tmp_path, capsys):
    assert main(["batch", str(corpus / "ana_walk.c3d"), str(corpus / "zed_walk.c3d")]) == 1
    out, err = capsys.readouterr()
    rows = _table(out)
    assert [r["status"] for r in rows] == ["ok", "failed"]
    assert main(["batch", str(tmp_path / "nowhere")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nowhere" in err[0]


def _children(pid: int) -> list[int]:
    """Living processes whose parent is ``pid`` (from /proc)."""
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                fields = open(f"/proc/{entry}/stat").read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid and fields[0] != "Z":
                found.append(int(entry))
    return found


def _alive(pid: int) -> bool:
    try:
        return open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_workers_end_when_the_batch_is_killed(corpus, tmp_path):
    """SIGKILL of ``mocap batch -j 2`` (nothing can run in the parent then) ends its worker
    processes too: they waited on their task queue for ever (found by the hostile re-run
    of issue 11, '2 processes of its group still alive')."""
    many = tmp_path / "many"
    many.mkdir()
    for k in range(12):
        for source in sorted(corpus.glob("[!z]*.c3d")):
            (many / f"{source.stem}_{k}.c3d").write_bytes(source.read_bytes())
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    process = subprocess.Popen([sys.executable, "-m", "mocap", "batch", str(many), "-j", "2",
                                "-o", str(tmp_path / "t.csv")], env=env,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    workers: list[int] = []
    while process.poll() is None and len(workers) < 2:
        workers = _children(process.pid)
        time.sleep(0.01)
    process.kill()
    process.wait()
    assert len(workers) == 2, "the batch ended before its workers started"
    deadline = time.monotonic() + 60          # a bound on waiting, not a speed assertion
    while any(_alive(w) for w in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    survivors = [w for w in workers if _alive(w)]
    for worker in survivors:                  # a failing run leaves none behind either
        os.kill(worker, 9)
    assert not survivors
