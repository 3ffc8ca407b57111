"""Stick-figure previews of real rigs (issue 26): only bones are drawn (no line from the
hips to a root joint at the floor origin), the figure is framed (as large as fits, nothing
cut), and the GIF shows it there."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from dynamics.viz.animate import animate_motion
from dynamics.viz.preview import (COLOURS, MARGIN, TITLE_BAND, Framing, drawn_bones,
                                  figure_screens)
from mocap.body.segments import default_skeleton
from mocap.io.motion import read_motion
from mocap.skeleton import Motion
from tests.conftest import realdata_path

SIZE = (200, 160)


@pytest.fixture(scope="module")
def walk():
    return read_motion(realdata_path("bandai2", "dataset-2_walk_active_001.bvh"))


def _drawn(motion):
    world = motion.forward_kinematics()
    end_index, ends = motion.end_site_positions(world)
    points = np.concatenate([world[1], ends], axis=1)
    bones, marked = drawn_bones(motion.skeleton)
    return points, bones, marked


def test_the_placeholder_root_is_not_drawn(walk):
    points, bones, marked = _drawn(walk)
    assert walk.skeleton.names[0] == "joint_Root"
    assert np.ptp(points[:, 0], axis=0).max() == 0.0            # it never moves …
    hips = walk.skeleton.names.index("Hips")
    assert np.linalg.norm(points[:, hips] - points[:, 0], axis=1).max() > 2.0   # … metres off
    assert 0 not in bones and 0 not in marked
    # every other joint and end site hangs from its parent by a bone: all but two points
    assert len(bones) == len(points[0]) - 2


def test_a_root_that_is_the_body_keeps_every_bone():
    skeleton = default_skeleton(1.75)
    frames = 5
    root = np.zeros((frames, 3))
    motion = Motion(skeleton, root, np.tile(np.eye(3), (frames, skeleton.count, 1, 1)), 50.0)
    points, bones, marked = _drawn(motion)          # still, but branching at the pelvis
    assert len(bones) == len(points[0]) - 1 and marked.tolist() == list(range(skeleton.count))


def test_framing_fills_the_picture_and_cuts_nothing(walk):
    points, bones, marked = _drawn(walk)
    centres = points[:, marked[0]].copy()
    centres[:, 1] = 0.0
    screens = figure_screens(points, bones, centres)
    pixels = Framing(screens, SIZE).pixels(screens[0])
    low, high = pixels.reshape(-1, 2).min(axis=0), pixels.reshape(-1, 2).max(axis=0)
    room_low = np.array([MARGIN * SIZE[0], (TITLE_BAND + MARGIN) * SIZE[1]])
    room_high = np.array([(1 - MARGIN) * SIZE[0], (1 - MARGIN) * SIZE[1]])
    assert (low >= room_low - 1e-9).all() and (high <= room_high + 1e-9).all()
    # as large as fits: the drawing spans the whole room in one direction
    assert np.isclose(high - low, room_high - room_low).any()


def test_the_gif_draws_the_framed_figure(walk, tmp_path):
    gif = tmp_path / "walk.gif"
    assert animate_motion(walk, gif, max_frames=4, dpi=40, size=(SIZE[0] / 40, SIZE[1] / 40)) == 4
    bone = np.array(COLOURS["bone"])
    with Image.open(gif) as image:
        assert image.size == SIZE and image.n_frames == 4
        for k in range(image.n_frames):
            image.seek(k)
            rows, columns = np.nonzero((np.asarray(image.convert("RGB")) == bone).all(axis=2))
            assert rows.size
            # the figure fills most of the height below the title (the walk stands upright)
            assert np.ptp(rows) > 0.6 * SIZE[1]
            assert columns.min() > 0 and columns.max() < SIZE[0] - 1
            assert rows.min() > TITLE_BAND * SIZE[1] - 3 and rows.max() < SIZE[1] - 1


def test_the_viewer_draws_no_line_from_the_transform_root(walk):
    from mocap.view.scene import skeleton_layer

    layer = skeleton_layer(walk)
    assert len(layer.bones) and 0 not in layer.bones
    assert walk.skeleton.transform_root()
