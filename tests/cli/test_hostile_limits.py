"""What hostile files ask for beyond reason is refused at the boundary every command shares
(issue 23): absurd skeletons, scenes that ask for too much, damaged model files, a batch
worker killed. Each refusal is one line naming the file, exit 2, nothing written, quickly;
each test failed on the code before issue 23 (a hang past 10 s, or a traceback)."""
from __future__ import annotations

from pathlib import Path

from mocap.cli import main

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def _refusal(argv: list[str], capsys) -> str:
    """The one error line of ``argv``, exit 2 (how quickly: ``benchmarks/hostile.py``)."""
    assert main(argv) == 2
    return _one_error_line(capsys)


# ---------------------------------------------------------------- absurd skeletons

def _bones(names: list[str]) -> str:
    return "".join(f"begin\n id {k + 1}\n name {name}\n direction 0 1 0\n length 1\n"
                   f" axis 0 0 0 XYZ\n dof rx ry rz\nend\n" for k, name in enumerate(names))


def _asf_chain(path: Path, count: int) -> Path:
    """The lambada ASF's header with a chain of ``count`` bones."""
    text = (DATA / "cmu_lambada.asf").read_text()
    names = [f"b{k}" for k in range(count)]
    hierarchy = ":hierarchy\n begin\n root b0\n" + "".join(
        f" {a} {b}\n" for a, b in zip(names, names[1:])) + " end\n"
    path.write_text(text[:text.index(":bonedata")] + ":bonedata\n" + _bones(names) + hierarchy)
    return path


def test_an_amc_of_two_million_empty_frames_is_refused_before_it_is_parsed(tmp_path, capsys):
    (tmp_path / "s.asf").write_text((DATA / "cmu_lambada.asf").read_text())
    amc = tmp_path / "s_01.amc"
    amc.write_text(":FULLY-SPECIFIED\n:DEGREES\n" +
                   "\n".join(str(k) for k in range(1, 2_000_001)) + "\n")
    line = _refusal(["export", str(amc), "-f", "bvh", "-o", str(tmp_path / "o.bvh")],
                          capsys)
    assert "s_01.amc" in line and "2000000 frames × 31 joints" in line, line
    assert not (tmp_path / "o.bvh").exists()


def test_an_asf_chain_of_ten_thousand_bones_or_one_too_deep_is_refused(tmp_path, capsys):
    amc = tmp_path / "c_01.amc"
    amc.write_text(":FULLY-SPECIFIED\n:DEGREES\n1\nroot 0 0 0 0 0 0\n")
    for count, words in ((10_000, "10000 bones, more than 4999"), (600, "deeper than 500")):
        asf = _asf_chain(tmp_path / "c.asf", count)
        line = _refusal(["export", str(amc), "--asf", str(asf), "-f", "bvh", "-o",
                               str(tmp_path / "o.bvh")], capsys)
        assert "c.asf" in line and words in line, line
    assert not (tmp_path / "o.bvh").exists()


# ---------------------------------------------------------------- scenes

SCENES = ROOT / "data" / "scenes"


def test_a_cloth_beyond_the_memory_budget_is_refused_before_it_is_built(tmp_path, capsys):
    """1414 × 1414 is under the 2·10⁶-particle limit but with its saved frames took 2.4 GB
    (an ArrayMemoryError traceback) or 10 s before the output check refused it."""
    scene = tmp_path / "cloth.toml"
    scene.write_text((SCENES / "hanging-cloth.toml").read_text().replace(
        "resolution = [32, 32]", "resolution = [1414, 1414]"))
    line = _refusal(["simulate", str(scene), "-o", str(tmp_path / "o.npz")], capsys)
    assert "cloth.toml: [[cloth]] #1: 'resolution' would make 1999396 particles" in line
    assert "more than the budget of 1000 MB" in line, line
    assert not (tmp_path / "o.npz").exists()


def test_a_singular_rigid_body_is_refused_with_its_name(tmp_path, capsys):
    """A box too small (or too thin) to invert its inertia: LinAlgError: Singular matrix."""
    source = (SCENES / "spinning-box.toml").read_text()
    for size in ("[1e-200, 1e-200, 1e-200]", "[0.3, 1e-9, 1e-9]"):
        scene = tmp_path / "box.toml"
        scene.write_text(source.replace("size = [0.3, 0.12, 0.04]", f"size = {size}"))
        line = _refusal(["simulate", str(scene), "-o", str(tmp_path / "o.npz")],
                              capsys)
        assert "box.toml: [[rigid]] #1: 'size'" in line and "cannot be inverted" in line, line
    assert not (tmp_path / "o.npz").exists()


# ---------------------------------------------------------------- model files

def test_a_truncated_or_bomb_model_file_is_one_line(tmp_path, capsys):
    """A model.npz cut short was a zipfile.BadZipFile traceback; a bit flipped in a member a
    zlib.error; an archive declaring 10¹² floats in a few bytes is refused by the budget."""
    import zipfile

    import numpy as np

    model = tmp_path / "model.npz"          # an archive as 'mocap decompose' writes them
    np.savez_compressed(model, meta=np.array('{"format": "mocap-motion-model"}'),
                        angles_core=np.random.default_rng(0).normal(size=20000))
    data = model.read_bytes()
    flipped = bytearray(data)
    flipped[len(data) // 3] ^= 0xFF
    bomb = tmp_path / "bomb.npz"
    with zipfile.ZipFile(bomb, "w") as archive:
        # an .npy header declaring 10^12 float64, and no data behind it
        header = b"{'descr': '<f8', 'fortran_order': False, 'shape': (1000000000000,), }"
        header += b" " * (118 - len(header)) + b"\n"
        archive.writestr("meta.npy", b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little")
                         + header)
    for name, content, words in (("cut.npz", data[:len(data) // 2], "damaged"),
                                 ("flip.npz", bytes(flipped), "damaged"),
                                 ("bomb.npz", None, "more than the reading budget")):
        path = bomb if content is None else tmp_path / name
        if content is not None:
            path.write_bytes(content)
        for argv in (["synthesize", str(path), "--person", "p0", "--action", "walk", "-o",
                      str(tmp_path / "s.csv")], ["recognize", str(path), str(DATA / "mocapbank_walk.bvh")]):
            line = _refusal(argv, capsys)
            assert name in line and words in line, line
    assert not (tmp_path / "s.csv").exists()


# ---------------------------------------------------------------- batch workers

def _dies_on_b(path: str, **arguments) -> dict:
    """A row function whose worker is killed (as the out-of-memory killer does) on 'b'."""
    import os
    import signal

    if Path(path).stem.startswith("b"):
        os.kill(os.getpid(), signal.SIGKILL)
    return {"path": path, "status": "ok", "error": ""}


def test_a_killed_batch_worker_names_its_trial_and_the_batch_goes_on():
    """A worker killed by the system broke the pool: a BrokenProcessPool traceback and no
    table. Now its trial's row names it, and every other trial is analysed."""
    from mocap.batch import run_batch

    names = [f"{letter}{k}.c3d" for k in range(4) for letter in "ab"][:7]
    rows = run_batch(_dies_on_b, names, jobs=2)
    assert [r["path"] for r in rows] == names
    for name, row in zip(names, rows):
        if name.startswith("b"):
            assert row["status"] == "failed" and f"{name}: the worker analysing this trial " \
                   f"was killed" in row["error"], row
        else:
            assert row["status"] == "ok", row


def test_a_killed_worker_on_the_command_line_is_one_failed_row(tmp_path, capsys,
                                                                monkeypatch):
    from mocap.cli import product
    from mocap.io import write
    from mocap.synthetic import synthesize_trial

    trial, _ = synthesize_trial(0, "walk", seed=1)
    for name in ("ann_walk", "bob_walk", "cat_walk"):
        write(trial, tmp_path / f"{name}.c3d")
    monkeypatch.setattr(product, "analyse_trial", _dies_on_b)
    out = tmp_path / "t.csv"
    assert main(["batch", str(tmp_path), "--jobs", "2", "-o", str(out)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-2:] == [f"failed: {tmp_path / 'bob_walk.c3d'}: the worker analysing this "
                        f"trial was killed (by the system: out of memory?); the other trials "
                        f"went on", "2 of 3 trials analysed, 1 failed; table in " + str(out)]
    table = out.read_text().splitlines()
    assert len(table) == 4 and "bob,walk,failed" in table[2], table


def test_a_fluid_cutoff_pairing_every_particle_is_refused(tmp_path, capsys):
    """A cutoff of metres over a spacing of centimetres: every particle paired with every
    other (17 576 particles: past 4 GB and 60 s before)."""
    scene = tmp_path / "fluid.toml"
    scene.write_text((SCENES / "fluid-drop.toml").read_text()
                     .replace("cutoff = 0.025 ", "cutoff = 5.0 ")
                     .replace("size = [0.2, 0.2, 0.2]", "size = [0.5, 0.5, 0.5]"))
    line = _refusal(["simulate", str(scene), "-o", str(tmp_path / "o.npz")], capsys)
    assert "fluid.toml: [[fluid]] #1: 'cutoff' 5 m over a spacing of 0.02 m" in line, line
    assert "MB of pairs, more than the budget" in line
    assert not (tmp_path / "o.npz").exists()
