"""``mocap angles`` of a long marker trial loads neither scipy nor numba (issue 11, speed).

scipy.spatial.transform costs about 0.4 s of CPU to import and numba 0.5 s to import and
load its cache: together more than the whole angle computation of 100 000 frames × 15
segments. Euler angles come from closed forms (:mod:`mocap.rotations.euler`) and large CSV tables are
written by numpy (:func:`mocap.io.text_format._format_block`). A structural test, not a
timed one.
"""
from __future__ import annotations

import warnings

import numpy as np

from mocap.rotations.angles import GimbalLockWarning, joint_angles
from mocap.io import read, write
from mocap.io.angles_csv import read_angles_csv
from mocap.markersets import load_markerset
from mocap.trial import Trial
from tests.cli.test_check_startup import _probe
from tests.conftest import realdata_path


def test_angles_of_a_long_real_walk_import_no_scipy_or_numba(tmp_path):
    walk = read(realdata_path("biomechzoo_sample_study/HC002D/Straight/HC002D06.c3d"))
    long = Trial(walk.labels, np.concatenate([walk.points] * 25), walk.rate)  # 5550 frames
    write(long, tmp_path / "long.c3d")
    out = tmp_path / "long.csv"
    probe = _probe("angles", str(tmp_path / "long.c3d"), "-m", "plugingait-lower",
                   "--no-clinical", "-o", str(out))
    assert probe["status"] == 0
    loaded = {name.split(".")[0] for name in probe["modules"]}
    assert "mocap" in loaded                     # the probe does see the real imports
    assert not loaded & {"scipy", "numba", "matplotlib"}, \
        sorted(loaded & {"scipy", "numba", "matplotlib"})
    # the large-table writer was used (more than COMPILED_ABOVE cells) and wrote the angles
    back = read_angles_csv(out)
    assert back.values.size + back.frames > 100_000
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        expected = joint_angles(read(tmp_path / "long.c3d"),
                                load_markerset("plugingait-lower"), "ZXY")
    np.testing.assert_array_equal(np.isnan(back.values), np.isnan(expected.values))
    np.testing.assert_allclose(back.values, expected.values, atol=5.0000001e-7, rtol=0)
