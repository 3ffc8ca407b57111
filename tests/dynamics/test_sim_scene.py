"""Scene files and ``mocap simulate``: shipped examples, output contract, bad input."""
from __future__ import annotations

import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest

from mocap.cli import main
from mocap.errors import MocapError

from dynamics.scenes.build import build_scene, load_scene
from dynamics.scenes.run import load_result, run_scene
from dynamics.scenes.schema import SCENES_DIR

EXAMPLES = sorted(p.stem for p in SCENES_DIR.glob("*.toml"))


def test_the_five_examples_are_shipped():
    assert EXAMPLES == ["fluid-drop", "hanging-cloth", "melting-block", "spinning-box",
                        "swinging-rope"]


@pytest.mark.parametrize("name", EXAMPLES)
def test_examples_load_and_run_a_few_steps(name):
    scene = load_scene(SCENES_DIR / f"{name}.toml")
    scene.steps, scene.save_every = 6, 3
    result = run_scene(scene, show_progress=False)
    assert result.times.shape == (3,)
    np.testing.assert_allclose(result.times, [0, 3 * scene.dt, 6 * scene.dt])
    assert np.all(np.isfinite(result.positions))
    if name == "melting-block":
        assert result.temperature.shape == result.positions.shape[:2]
    if name == "spinning-box":
        assert result.rigid_vertices.shape == (3, 1, 8, 3)


def test_cli_writes_the_npz_contract_and_a_gif(tmp_path, capsys):
    out, gif = tmp_path / "rope.npz", tmp_path / "rope.gif"
    status = main(["simulate", "swinging-rope", "-o", str(out), "--gif", str(gif),
                   "--steps", "40", "--save-every", "10", "--no-progress", "--max-frames", "3"])
    assert status == 0
    with np.load(out) as data:
        assert data["times"].shape == (5,)
        assert data["positions"].shape == (5, 30, 3)
        assert data["springs"].shape[1] == 2
        assert data["energy"].shape == (5, 4)
        assert "temperature" not in data.files
        # pinned start never moves; the rope falls
        np.testing.assert_allclose(data["positions"][:, 0], [[0, 2, 0]] * 5)
        assert data["positions"][-1, -1, 1] < 2.0
    assert gif.read_bytes()[:6] == b"GIF89a"
    assert "40 steps" in capsys.readouterr().err


def test_cli_heat_scene_saves_temperature(tmp_path):
    out, gif = tmp_path / "melt.npz", tmp_path / "melt.gif"
    assert main(["simulate", str(SCENES_DIR / "melting-block.toml"), "-o", str(out),
                 "--steps", "20", "--save-every", "10", "--no-progress", "--gif", str(gif),
                 "--max-frames", "2"]) == 0
    data = load_result(out)
    assert data["temperature"].shape == (3, 512)
    assert data["temperature"].max() == pytest.approx(500.0)       # the hot plate
    assert data["boxes"].shape == (1, 6) and data["planes"].shape == (1, 6)
    assert gif.stat().st_size > 0


def write(tmp_path, text: str) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


BAD_SCENES = [
    ("[simulation]\ndt = -1\n[[particle]]\nposition = [0, 0, 0]\n", "'dt' must be > 0"),
    ("[simulation]\nintegrator = \"verlet\"\n[[particle]]\nposition = [0, 0, 0]\n",
     "'integrator' must be one of"),
    ("[[particle]]\nposition = [0, 0]\n", "'position' must be a list of 3 numbers"),
    ("[[particle]]\nposition = [0, 0, 0]\nmas = 1.0\n", "unknown key(s) 'mas'"),
    ("[[particle]]\nposition = [0, 0, 0]\n[[spring]]\nbetween = [0, 5]\nstiffness = 1.0\n",
     "refers to particle 5"),
    ("[[cloth]]\norigin = [0, 0, 0]\nsize = [1, 1]\nresolution = [1, 4]\n",
     "'resolution' must have every entry >= 2"),
    ("[[cloth]]\norigin = [0, 0, 0]\nsize = [1, 1]\npin = [\"middle\"]\n",
     "unknown particle name 'middle'"),
    ("[gravity]\ng = [0, -9.81, 0]\n", "nothing to simulate"),
    ("[[particle]]\nposition = [0, 0, 0]\n[heat]\nconductivity = 1.0\ncapacity = 1.0\n",
     "structural springs"),
    ("[[rigid]]\nmass = 1.0\nsize = [1, 0, 1]\n", "'size' must be positive"),
    ("[[particle]]\nposition = [0, 0, 0]\n[fog]\n", "unknown table(s) 'fog'"),
    ("[[particle]]\nposition = [0, 0, 0\n", "not valid TOML"),
]


@pytest.mark.parametrize("text, message", BAD_SCENES)
def test_bad_scene_is_one_line_exit_2_and_no_output(tmp_path, capsys, text, message):
    scene, out = write(tmp_path, text), tmp_path / "out.npz"
    assert main(["simulate", str(scene), "-o", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert message in err and str(scene) in err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists() and list(tmp_path.iterdir()) == [scene]


def test_unstable_scene_names_the_step_and_writes_nothing(tmp_path, capsys):
    text = tomllib.loads((SCENES_DIR / "swinging-rope.toml").read_text())
    text["simulation"]["dt"] = 0.02
    path = tmp_path / "fast.toml"
    import json
    # write the modified document back as TOML (all values are numbers, lists, strings)
    lines = []
    for key, value in text.items():
        if isinstance(value, dict):
            lines.append(f"[{key}]")
            lines += [f"{k} = {json.dumps(v)}" for k, v in value.items()]
        elif isinstance(value, list):
            for item in value:
                lines.append(f"[[{key}]]")
                lines += [f"{k} = {json.dumps(v)}" for k, v in item.items()]
        else:
            lines.insert(0, f"{key} = {json.dumps(value)}")
    path.write_text("\n".join(lines) + "\n")
    out = tmp_path / "out.npz"
    assert main(["simulate", str(path), "-o", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "unstable at step" in err and "implicit-euler" in err and str(path) in err
    assert not out.exists()


def test_cli_option_errors(tmp_path, capsys):
    out = tmp_path / "o.npz"
    assert main(["simulate", "no-such-scene", "-o", str(out)]) == 2
    assert "examples: fluid-drop" in capsys.readouterr().err
    assert main(["simulate", "swinging-rope", "-o", str(out), "--gif", str(tmp_path / "a.png")]) == 2
    assert "--gif needs a file ending in .gif" in capsys.readouterr().err
    assert main(["simulate", "swinging-rope", "-o", str(out), "--dt", "0"]) == 2
    assert main(["simulate", "--list-examples"]) == 0
    assert "hanging-cloth" in capsys.readouterr().out
    if shutil.which("ffmpeg") is None:
        assert main(["simulate", "swinging-rope", "-o", str(out), "--mp4",
                     str(tmp_path / "a.mp4")]) == 2
        assert "ffmpeg" in capsys.readouterr().err
    assert not out.exists()


def test_build_scene_particle_order_and_springs():
    document = {
        "particle": [{"position": [0, 0, 0], "pinned": True}, {"position": [0, -1, 0]}],
        "rope": [{"start": [1, 0, 0], "end": [2, 0, 0], "particles": 3, "pin": []}],
        "spring": [{"between": [1, 2], "stiffness": 10.0}],
        "simulation": {"steps": 1},
    }
    scene = build_scene(document)
    p = scene.system.particles
    np.testing.assert_allclose(p.position[2], [1, 0, 0])       # particles first, then ropes
    assert p.pinned.tolist() == [True, False, False, False, False]
    springs = scene.system.springs
    assert springs.pairs.tolist()[-1] == [1, 2]
    assert springs.rest_length[-1] == pytest.approx(np.sqrt(2))
    with pytest.raises(MocapError, match="'pin' must be a list"):
        build_scene({"rope": [{"start": [0, 0, 0], "end": [1, 0, 0], "pin": 3}]})


def test_size_guards_and_molten_fluid_needs_heat(tmp_path):
    with pytest.raises(MocapError, match="at most 2000000"):
        build_scene({"cloth": [{"origin": [0, 0, 0], "size": [1, 1],
                                "resolution": [5000, 5000]}]})
    # a fluid block so large that its particle count is inf in floating point (found by
    # the hostile re-run: an OverflowError traceback instead of the limit)
    with pytest.raises(MocapError, match="infinitely many particles.*at most 2000000"):
        build_scene({"fluid": [{"origin": [0, 0, 0], "size": [1e9, 1e9, 1e9],
                                "spacing": 1e-300}]})
    with pytest.raises(MocapError, match="would make 1000000000 particles"):
        build_scene({"fluid": [{"origin": [0, 0, 0], "size": [999, 999, 999],
                                "spacing": 1.0}]})
    with pytest.raises(MocapError, match="'size' must be positive"):
        build_scene({"lattice": [{"origin": [0, 0, 0], "size": [1, 0, 1]}]})
    with pytest.raises(MocapError, match="needs \\[heat\\]"):
        build_scene({"lattice": [{"origin": [0, 0, 0], "size": [1, 1, 1],
                                  "molten_fluid": {"alpha": 1.0}}]})
    scene = build_scene({"particle": [{"position": [0, 0, 0]}],
                         "simulation": {"steps": 10 ** 9, "save_every": 1}})
    with pytest.raises(MocapError, match="save_every"):
        run_scene(scene, show_progress=False)
