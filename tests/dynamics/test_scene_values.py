"""Numbers of a scene (found by the hostile re-run of issue 11). Spring stiffness and
damping of cloth and lattice blocks (a number or a per-kind table)
must be finite (found by the hostile re-run of issue 11: ``damping = inf`` passed the '>= 0'
check and the implicit solver died with scipy's 'Factor is exactly singular' traceback), and
a refused value is said once (the builders' ValueError handler wrapped the table's own
message a second time: 'f.toml: [[cloth]] #1: f.toml: [[cloth]] #1: ...'). And every number
is within +-1e9: 1e300 passed as finite and overflowed later."""
from __future__ import annotations

import numpy as np
import pytest

from dynamics.scenes.schema import SCENES_DIR
from mocap.cli import main


def _simulate_edited(scene: str, old: str, new: str, tmp_path, capsys) -> list[str]:
    """``mocap simulate`` of an example scene with ``old`` replaced by ``new``: it must
    exit 2 and write nothing; returns the lines it printed on stderr."""
    text = (SCENES_DIR / f"{scene}.toml").read_text()
    assert old in text
    path = tmp_path / "s.toml"
    path.write_text(text.replace(old, new, 1))
    assert main(["simulate", str(path), "-o", str(tmp_path / "out.npz"), "--steps", "3",
                 "--no-progress"]) == 2
    assert not (tmp_path / "out.npz").exists()
    return capsys.readouterr().err.strip().splitlines()


@pytest.mark.parametrize("scene, old, new, key", [
    ("hanging-cloth", "damping = { structural = 0.01 }", "damping = { structural = inf }",
     "'damping' structural must be a finite number from 0 to 1e+09, not inf"),
    ("hanging-cloth", "damping = { structural = 0.01 }", "damping = inf",
     "'damping' must be a finite number from 0 to 1e+09"),
    ("hanging-cloth", "damping = { structural = 0.01 }", "damping = { structural = -1 }",
     "'damping' structural must be a finite number from 0 to 1e+09, not -1"),
    ("melting-block", "stiffness = { structural = 2000.0,", "stiffness = { structural = inf,",
     "'stiffness' structural must be a finite number from 0 to 1e+09, not inf"),
])
def test_spring_values_must_be_finite_and_are_refused_once(scene, old, new, key, tmp_path,
                                                         capsys):
    err = _simulate_edited(scene, old, new, tmp_path, capsys)
    assert len(err) == 1 and key in err[0], err
    assert err[0].count("s.toml") == 1, err


@pytest.mark.parametrize("scene, old, new, key", [
    # an OverflowError traceback in the molten fluid's equilibrium_beta
    ("melting-block", "size = [0.2, 0.2, 0.2]", "size = [1e300, 1e300, 1e300]", "'size'"),
    # accepted: a box of 1e300 kg that no push moves
    ("spinning-box", "mass = 1.0", "mass = 1e300", "'mass'"),
    # numpy overflow warnings, then the instability message: three lines
    ("melting-block", "damping = { structural = 0.5, shear = 0.2 }", "damping = 1e300",
     "'damping'"),
    ("swinging-rope", "start = [0.0, 2.0, 0.0]", "start = [0.0, 1e12, 0.0]", "'start'"),
])
def test_numbers_beyond_any_scene_are_refused_at_reading(scene, old, new, key, tmp_path, capsys):
    err = _simulate_edited(scene, old, new, tmp_path, capsys)
    assert len(err) == 1 and key in err[0] and "1e+09" in err[0], err


@pytest.mark.parametrize("size", ["[0, 0, 0]", "[0.01, 0.0, 0.019]"])
def test_fluid_block_under_one_spacing_is_refused(size, tmp_path, capsys):
    """A [[fluid]] block smaller than its spacing (0.02 m) on every axis is one particle:
    refused in one line naming the key (it simulated one falling particle, issue 11)."""
    err = _simulate_edited("fluid-drop", "size = [0.2, 0.2, 0.2]", f"size = {size}",
                           tmp_path, capsys)
    assert len(err) == 1 and "'size'" in err[0] and "one particle" in err[0], err
    assert err[0].count("s.toml") == 1, err


def test_fluid_sheet_one_particle_thick_is_still_a_fluid(tmp_path):
    """A block thin on one axis (a layer 11 x 1 x 11 particles) is accepted."""
    text = (SCENES_DIR / "fluid-drop.toml").read_text().replace(
        "size = [0.2, 0.2, 0.2]", "size = [0.2, 0.0, 0.2]", 1)
    path = tmp_path / "s.toml"
    path.write_text(text)
    assert main(["simulate", str(path), "-o", str(tmp_path / "out.npz"), "--steps", "3",
                 "--no-progress"]) == 0
    assert np.load(tmp_path / "out.npz")["positions"].shape[1] == 121
