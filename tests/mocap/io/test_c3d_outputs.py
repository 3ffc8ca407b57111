"""write_c3d(outputs=, groups=): model outputs as points after the markers, round trip."""
from __future__ import annotations

import numpy as np
import pytest

from mocap.errors import MocapError
from mocap.io import read
from mocap.io.c3d.write import write_c3d
from mocap.trial import Trial


def test_outputs_beyond_255_labels_and_a_group_round_trip(tmp_path):
    import ezc3d

    rng = np.random.default_rng(0)
    frames, markers = 12, 250
    trial = Trial([f"M{i}" for i in range(markers)], rng.random((frames, markers, 3)), 100.0)
    angles = rng.random((frames, 3)) * 90
    moment = rng.random((frames, 3)) * 1000
    moment[3] = np.nan                                   # an invalid frame
    outputs = [(f"X{i}Angles", "ANGLES", angles + i) for i in range(20)]
    outputs.append(("LHipMoment", "MOMENTS", moment))
    path = tmp_path / "out.c3d"
    write_c3d(trial, path, outputs=outputs,
              groups={"ANALYSIS": {"NAMES": ["Cadence"], "VALUES": np.array([112.5])}})
    c3d = ezc3d.c3d(str(path))
    point = c3d["parameters"]["POINT"]
    assert len(point["LABELS"]["value"]) + len(point["LABELS2"]["value"]) == markers + 21
    assert point["MOMENTS"]["value"] == ["LHipMoment"] and point["MOMENT_UNITS"]["value"] == ["Nmm"]
    assert point["ANGLE_UNITS"]["value"] == ["deg"]
    assert c3d["parameters"]["ANALYSIS"]["VALUES"]["value"][0] == pytest.approx(112.5)
    back = read(path)
    assert back.labels == trial.labels                    # the outputs are not markers
    np.testing.assert_allclose(back.points, trial.points, atol=1e-6)
    values = back.modelled["values"]
    np.testing.assert_allclose(values[:, back.modelled["labels"].index("X19Angles")],
                               angles + 19, atol=1e-4)
    got = values[:, back.modelled["labels"].index("LHipMoment")]
    assert np.isnan(got[3]).all()
    np.testing.assert_allclose(np.delete(got, 3, 0), np.delete(moment, 3, 0), rtol=1e-6)


def test_an_output_of_the_wrong_shape_or_kind_is_refused(tmp_path):
    trial = Trial(["A"], np.zeros((5, 1, 3)), 100.0)
    for bad in [("B", "ANGLES", np.zeros((4, 3))), ("B", "SPEEDS", np.zeros((5, 3)))]:
        with pytest.raises(MocapError, match="output"):
            write_c3d(trial, tmp_path / "x.c3d", outputs=[bad])
    assert not (tmp_path / "x.c3d").exists()
