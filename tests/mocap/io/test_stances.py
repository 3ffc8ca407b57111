"""Plates assigned to feet: clean single-foot contacts only (known geometric answers)."""
from __future__ import annotations

import numpy as np

from mocap.io.c3d.forceplates import ForcePlate, PlateForces
from mocap.io.c3d.stances import FOOT_MARKER_HEIGHT, assign_plates

RATE, FRAMES = 100.0, 60


def _plate(centre=(0.0, 0.0, 0.0), loaded=slice(10, 50)) -> PlateForces:
    """A 0.6 × 0.4 m plate (Z down, as Vicon's), loaded by 700 N at its centre."""
    cx, cy, cz = centre
    corners = np.array([[cx + 0.3, cy + 0.2, cz], [cx - 0.3, cy + 0.2, cz],
                        [cx - 0.3, cy - 0.2, cz], [cx + 0.3, cy - 0.2, cz]])
    axes = np.array([[1.0, 0, 0], [0, -1.0, 0], [0, 0, -1.0]]).T
    plate = ForcePlate(0, 2, corners, np.zeros(3), list(range(6)), ["F"] * 6, None, axes)
    force = np.zeros((FRAMES, 3))
    force[loaded, 2] = 700.0
    cop = np.full((FRAMES, 3), np.nan)
    cop[loaded] = [cx, cy, cz]
    return PlateForces(RATE, force, np.zeros((FRAMES, 3)), cop, np.zeros((FRAMES, 3)), plate)


def _still(heel, toe):
    return np.tile(heel, (FRAMES, 1)).astype(float), np.tile(toe, (FRAMES, 1)).astype(float)


def _swinging(y: float, z: float = 0.1):
    """A foot moving at 1.5 m/s along x, passing over the plate."""
    x = -0.6 + 1.5 * np.arange(FRAMES) / RATE
    heel = np.stack([x, np.full(FRAMES, y), np.full(FRAMES, z)], axis=1)
    return heel, heel + [0.2, 0.0, 0.0]


def test_a_foot_wholly_on_the_plate_with_the_other_swinging_over_is_clean():
    feet = {"l": _still([-0.1, 0.0, 0.05], [0.1, 0.0, 0.03]), "r": _swinging(-0.05)}
    (stance,) = assign_plates([_plate()], feet)
    assert (stance.side, stance.start, stance.stop, stance.clean) == ("l", 10, 50, True)


def test_a_toe_off_the_plate_is_refused():
    feet = {"l": _still([0.15, 0.0, 0.05], [0.35, 0.0, 0.03]), "r": _swinging(-0.3)}
    (stance,) = assign_plates([_plate()], feet)
    assert stance.side == "l" and not stance.clean and stance.reason == "partly off the plate"


def test_two_feet_standing_on_one_plate_are_refused():
    feet = {"l": _still([-0.1, 0.1, 0.05], [0.1, 0.1, 0.03]),
            "r": _still([-0.25, -0.1, 0.05], [-0.05, -0.1, 0.03])}
    (stance,) = assign_plates([_plate()], feet)
    assert not stance.clean and stance.reason == "both feet on the plate"


def test_a_foot_on_the_next_stair_step_is_not_on_the_plate():
    step = FOOT_MARKER_HEIGHT + 0.05           # the other foot stands one step up
    feet = {"l": _still([-0.1, 0.1, 0.05], [0.1, 0.1, 0.03]),
            "r": _still([-0.25, -0.1, step + 0.05], [-0.05, -0.1, step + 0.03])}
    (stance,) = assign_plates([_plate()], feet)
    assert stance.side == "l" and stance.clean


def test_a_short_blip_is_no_stance():
    feet = {"l": _still([-0.1, 0.0, 0.05], [0.1, 0.0, 0.03]), "r": _swinging(-0.3)}
    assert assign_plates([_plate(loaded=slice(20, 22))], feet) == []
