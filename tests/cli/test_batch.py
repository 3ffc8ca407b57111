"""mocap batch: the same table on processes and on a Dask LocalCluster, damaged file reported."""
from __future__ import annotations

import csv
import io

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
