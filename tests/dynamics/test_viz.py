"""Pictures of runs and motions are built without pyplot: a user's matplotlib state survives."""
from __future__ import annotations

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
from PIL import Image

from mocap.body.segments import default_skeleton
from mocap.skeleton import Motion
from dynamics.humanoid.check import check_motion
from dynamics.scenes.build import load_scene
from dynamics.scenes.run import run_scene
from dynamics.scenes.schema import SCENES_DIR
from dynamics.viz.animate import animate_motion, plot_check
from dynamics.viz.render import render_animation


@pytest.fixture
def svg_backend():
    """A user who chose the 'svg' backend (library code that forces Agg would switch it)."""
    before = matplotlib.get_backend()
    matplotlib.use("svg")
    yield
    matplotlib.use(before)


def test_plots_and_animations_leave_the_matplotlib_state_alone(svg_backend, tmp_path):
    skeleton = default_skeleton(1.75)
    frames = 12
    motion = Motion(skeleton, np.zeros((frames, 3)),
                    np.tile(np.eye(3), (frames, skeleton.count, 1, 1)), 50.0)
    open_figures = plt.get_fignums()

    figure = plot_check(check_motion(motion), tmp_path / "check.png", dpi=20)
    assert len(figure.axes) == 5                    # force, torque, reactions, joints, floor
    force_axis, torque_axis = figure.axes[0], figure.axes[1]
    assert "% BW" in force_axis.get_ylabel() and "N·m" in torque_axis.get_ylabel()
    assert force_axis.get_lines()[0].get_color() != torque_axis.get_lines()[0].get_color()
    for axis in figure.axes:                        # time ticks on every panel
        assert axis.get_xlabel() == "time (s)"
        assert axis.xaxis.get_tick_params()["labelbottom"]
    with Image.open(tmp_path / "check.png") as image:
        assert image.size == (160, 240)                 # 8 × 12 inches at 20 dpi
    assert plot_check(check_motion(motion)).axes[4].get_xlabel() == "time (s)"   # no file

    gif = tmp_path / "motion.gif"
    assert animate_motion(motion, gif, max_frames=3, dpi=20, size=(2, 2)) == 3
    with Image.open(gif) as image:
        assert image.n_frames == 3 and image.size == (40, 40)

    scene = load_scene(SCENES_DIR / "hanging-cloth.toml")
    scene.steps, scene.save_every = 4, 2
    run = tmp_path / "run.gif"
    assert render_animation(run_scene(scene, show_progress=False).arrays(), run,
                            max_frames=3, dpi=20, fps=30.0) == 3
    with Image.open(run) as image:
        assert image.n_frames == 3 and image.size == (128, 96)

    assert matplotlib.get_backend() == "svg"
    assert plt.get_fignums() == open_figures
