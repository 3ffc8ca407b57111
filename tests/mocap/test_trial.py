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


def test_slicing_frames_keeps_analogs_events_and_clock_in_step(tmp_path):
    """Frames 40..149 of a walk: every analog sample of those frames, the events inside
    them, and the old frame numbers and times; ezc3d reads the written slice back on the
    same clock."""
    import ezc3d

    from mocap.io import write
    walk = read(realdata_path(*WALK))
    part = walk.slice(40, 150)
    ratio = walk.analogs.shape[0] // walk.frames
    assert part.frames == 110 and part.analogs.shape == (110 * ratio, walk.analogs.shape[1])
    np.testing.assert_array_equal(part.analogs, walk.analogs[40 * ratio:150 * ratio])
    np.testing.assert_array_equal(part.modelled["values"], walk.modelled["values"][40:150])
    numbers, times = walk.time_base()
    np.testing.assert_array_equal(part.time_base()[0], numbers[40:150])
    np.testing.assert_allclose(part.time_base()[1], times[40:150], atol=1e-12)
    inside = [e for e in walk.events if 40 <= e["frame"] < 150]
    assert [e["frame"] for e in part.events] == [e["frame"] - 40 for e in inside]
    np.testing.assert_allclose([e["time"] for e in part.events],
                               [e["time"] - 0.4 for e in inside], atol=1e-12)
    for event in part.events:       # time counts from the first frame, as the reader's
        assert abs(event["frame"] / part.rate - event["time"]) < 1e-9
    path = tmp_path / "part.c3d"
    write(part, path)
    c3d = ezc3d.c3d(str(path))
    assert c3d["header"]["points"]["first_frame"] + 1 == walk.first_frame + 40
    assert c3d["data"]["analogs"].shape[-1] == 110 * ratio
    assert walk.frames > 150 and walk.slice(5, 5).frames == 0
