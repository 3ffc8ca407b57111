"""mocap.pipeline: the recipes keep everything a trial carries (analogs, events, plates)."""
from __future__ import annotations

import numpy as np

from mocap.io import read
from mocap.markersets import load_markerset
from mocap.pipeline import Cleaning, clinical_angles, marker_file_angles
from tests.conftest import realdata_path

WALK = ("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")


def test_the_recipes_keep_the_analog_channels_and_metadata():
    """Selecting the markers a model reads used to rebuild the Trial positionally and drop
    the force-plate analogs; both recipes now keep them (Trial.select)."""
    walk = read(realdata_path(*WALK))
    assert walk.analogs is not None and walk.analogs.size
    segments = marker_file_angles(walk, load_markerset("plugingait-lower"), "ZXY",
                                  Cleaning(lowpass_hz=6.0))
    clinical = clinical_angles(walk)
    for result in (segments, clinical):
        assert result.trial.labels != walk.labels                  # a selection
        np.testing.assert_array_equal(result.trial.analogs, walk.analogs)
        assert result.trial.analog_labels == walk.analog_labels
        assert result.trial.analog_rate == walk.analog_rate
        assert result.trial.parameters is walk.parameters


def test_the_everyday_calls_are_at_the_top_of_mocap():
    """``mocap.read``, ``mocap.clinical_angles`` … are the library's own functions (one
    home each), reachable without knowing the sub-packages."""
    import mocap
    from mocap import io, pipeline
    from mocap.rotations import angles

    assert sorted(mocap.__all__) == sorted(mocap._HOMES)
    assert mocap.read is io.read and mocap.write is io.write
    assert mocap.clinical_angles is pipeline.clinical_angles
    assert mocap.joint_angles is angles.joint_angles
    walk = mocap.read(realdata_path(*WALK))
    assert isinstance(walk, mocap.Trial) and walk.rate == 100.0
    with np.testing.assert_raises(AttributeError):
        mocap.no_such_thing  # noqa: B018
