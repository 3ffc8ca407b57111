"""Physical animation (ABA tracking) and secondary motion (cape, rope) on the humanoid."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.body.segments import BODY_SEGMENTS, default_skeleton
from mocap.skeleton import Motion
from dynamics.secondary import CAPE_BACK, TRUNK_RADIUS, simulate_secondary
from dynamics.humanoid.tracking import simulate_tracking


@pytest.fixture(scope="module")
def skeleton():
    return default_skeleton(1.75)


def test_standing_body_keeps_its_pose_under_physics(skeleton):
    result = simulate_tracking(Motion.still(skeleton, 40, 100.0), body_mass=75.0)
    assert result.joint_error_deg.max() < 0.5
    assert result.root_error_m.max() < 0.005                        # sinks ~2 mm into the floor
    # The floor and the (weak) root assist carry the weight together.
    support = result.contact_force[-1, 1] + result.assist_force[-1]
    assert support == pytest.approx(75.0 * 9.81, rel=0.1)
    assert result.contact_force[-1, 1] > 0.5 * 75.0 * 9.81


def test_unsupported_body_falls_to_the_floor(skeleton):
    held = Motion.still(skeleton, 50, 100.0, root_translation=[0.0, 0.3, 0.0])
    result = simulate_tracking(held, root_assist=0.0)
    height = result.motion.root_translation[:, 1]
    # Free fall for 0.3 m takes about 0.25 s; then the feet meet the floor.
    assert height[20] == pytest.approx(0.3 - 0.5 * 9.81 * 0.2 ** 2, abs=0.01)
    assert height.min() < 0.02
    assert result.contact_force[:, 1].max() > 75.0 * 9.81


def test_cape_hangs_behind_the_back_and_follows_the_shoulders(skeleton):
    motion = Motion.still(skeleton, 30, 100.0)
    motion.root_translation[:, 2] = 0.6 * motion.times               # walks forward
    result = simulate_secondary(motion, cape=True, rope=True, settle=0.3)
    assert np.isfinite(result.cape).all() and np.isfinite(result.rope).all()
    rows, columns = result.cape_shape
    world = motion.forward_kinematics()[1]
    left = world[:, BODY_SEGMENTS.index("l_upperarm")]
    top = result.cape[:, :columns]
    # The pinned row sits on the line between the shoulders (moved back, and up 3 cm).
    np.testing.assert_allclose(top[:, 0], left + [0.0, 0.03, -CAPE_BACK], atol=1e-9)
    bottom = result.cape[-1, -columns:]
    assert bottom[:, 1].mean() < top[-1, :, 1].mean() - 0.5        # it hangs down
    assert (result.cape[:, :, 1] > 0.0).all()                       # above the floor
    # Not inside the trunk: distance to the pelvis–neck axis at least the radius (- slack).
    pelvis, neck = world[-1, 0], world[-1, BODY_SEGMENTS.index("head")]
    axis = (neck - pelvis) / np.linalg.norm(neck - pelvis)
    offsets = result.cape[-1, columns:] - pelvis                    # free particles
    radial = offsets - np.outer(offsets @ axis, axis)
    along = offsets @ axis
    inside = (along > 0) & (along < np.linalg.norm(neck - pelvis))
    assert np.linalg.norm(radial[inside], axis=1).min() > TRUNK_RADIUS - 0.02
    # The rope keeps roughly its length (stiff links) and hangs from the head.
    length = np.linalg.norm(np.diff(result.rope[-1], axis=0), axis=1).sum()
    assert length == pytest.approx(0.45, rel=0.15)
