"""Trial: what every reader produces is a typed field, and it travels with the trial."""
from __future__ import annotations

import numpy as np

from mocap.io import read
from mocap.io.lab import rotate_trial
from tests.conftest import realdata_path

WALK = ("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")


def test_a_c3d_walk_fills_the_typed_fields_and_they_travel():
    walk = read(realdata_path(*WALK))
    assert walk.first_frame >= 1 and walk.first_frame == walk.time_base()[0][0]
    assert {e["label"] for e in walk.events} >= {"Foot Strike", "Foot Off"}
    assert "FORCE_PLATFORM" in walk.parameters and "PROCESSING" in walk.parameters
    assert "LKneeAngles" in walk.modelled["labels"]
    assert walk.modelled["values"].shape[0] == walk.frames
    for key in ("first_frame", "events", "parameters", "modelled", "rotations"):
        assert key not in walk.metadata                      # one home: the field
    picked = walk.select(["LASI", "RASI"])
    assert picked.first_frame == walk.first_frame and picked.events == walk.events
    assert picked.parameters is walk.parameters and picked.modelled is walk.modelled
    turned = rotate_trial(walk, "y")
    assert turned.events == walk.events and turned.modelled is None
    corners = walk.parameters["FORCE_PLATFORM"]["CORNERS"]
    assert not np.allclose(turned.parameters["FORCE_PLATFORM"]["CORNERS"], corners)
    assert np.array_equal(walk.parameters["FORCE_PLATFORM"]["CORNERS"], corners)


def test_a_trc_keeps_its_frame_numbers_and_times(tmp_path):
    walk = read(realdata_path(*WALK)).select(["LASI", "RASI", "SACR"])
    path = tmp_path / "walk.trc"
    from mocap.io import write
    write(walk, path)
    back = read(path)
    numbers, times = walk.time_base()
    np.testing.assert_array_equal(back.frame_numbers, numbers)
    np.testing.assert_allclose(back.frame_times, times, atol=1e-9)
    assert back.first_frame == walk.first_frame and back.start_time == times[0]
