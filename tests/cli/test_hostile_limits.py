"""What hostile files ask for beyond reason is refused at the boundary every command shares
(issue 23): absurd skeletons, scenes that ask for too much, damaged model files, a batch
worker killed. Each refusal is one line naming the file, exit 2, nothing written, quickly;
each test failed on the code before issue 23 (a hang past 10 s, or a traceback)."""
from __future__ import annotations

import time
from pathlib import Path

from mocap.cli import main

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def _timed_refusal(argv: list[str], capsys, seconds: float = 2.0) -> str:
    start = time.perf_counter()
    assert main(argv) == 2
    assert time.perf_counter() - start < seconds
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
    line = _timed_refusal(["export", str(amc), "-f", "bvh", "-o", str(tmp_path / "o.bvh")],
                          capsys)
    assert "s_01.amc" in line and "2000000 frames × 31 joints" in line, line
    assert not (tmp_path / "o.bvh").exists()


def test_an_asf_chain_of_ten_thousand_bones_or_one_too_deep_is_refused(tmp_path, capsys):
    amc = tmp_path / "c_01.amc"
    amc.write_text(":FULLY-SPECIFIED\n:DEGREES\n1\nroot 0 0 0 0 0 0\n")
    for count, words in ((10_000, "10000 bones, more than 4999"), (600, "deeper than 500")):
        asf = _asf_chain(tmp_path / "c.asf", count)
        line = _timed_refusal(["export", str(amc), "--asf", str(asf), "-f", "bvh", "-o",
                               str(tmp_path / "o.bvh")], capsys)
        assert "c.asf" in line and words in line, line
    assert not (tmp_path / "o.bvh").exists()


# ---------------------------------------------------------------- scenes

SCENES = ROOT / "dynamics" / "scenes" / "examples"


def test_a_cloth_beyond_the_memory_budget_is_refused_before_it_is_built(tmp_path, capsys):
    """1414 × 1414 is under the 2·10⁶-particle limit but with its saved frames took 2.4 GB
    (an ArrayMemoryError traceback) or 10 s before the output check refused it."""
    scene = tmp_path / "cloth.toml"
    scene.write_text((SCENES / "hanging-cloth.toml").read_text().replace(
        "resolution = [32, 32]", "resolution = [1414, 1414]"))
    line = _timed_refusal(["simulate", str(scene), "-o", str(tmp_path / "o.npz")], capsys)
    assert "cloth.toml: [[cloth]] #1: 'resolution' would make 1999396 particles" in line
    assert "more than the budget of 1000 MB" in line, line
    assert not (tmp_path / "o.npz").exists()


def test_a_singular_rigid_body_is_refused_with_its_name(tmp_path, capsys):
    """A box too small (or too thin) to invert its inertia: LinAlgError: Singular matrix."""
    source = (SCENES / "spinning-box.toml").read_text()
    for size in ("[1e-200, 1e-200, 1e-200]", "[0.3, 1e-9, 1e-9]"):
        scene = tmp_path / "box.toml"
        scene.write_text(source.replace("size = [0.3, 0.12, 0.04]", f"size = {size}"))
        line = _timed_refusal(["simulate", str(scene), "-o", str(tmp_path / "o.npz")],
                              capsys)
        assert "box.toml: [[rigid]] #1: 'size'" in line and "cannot be inverted" in line, line
    assert not (tmp_path / "o.npz").exists()
