"""Force plates of real C3D files against ezc3d's force-platform extraction, plus the
hand-checkable physics of the plate arithmetic."""
from __future__ import annotations

import json

import numpy as np
import pytest

from mocap.errors import MocapError
from mocap.io.c3d.forceplates import force_plates, plate_forces, total_forces
from mocap.io.c3d.read import read_c3d
from mocap.trial import Trial
from tests.conftest import realdata_path


def _plate_files() -> list[str]:
    catalogue = json.loads(realdata_path("catalogue.json").read_text())
    return sorted(e["local"] for e in catalogue if e.get("fp_used") and e["kind"] == "c3d")


def test_every_real_plate_equals_ezc3d():
    ezc3d = pytest.importorskip("ezc3d")
    files = _plate_files()
    assert len(files) >= 50
    compared = 0
    for local in files:
        path = realdata_path(local)
        reference = ezc3d.c3d(str(path), extract_forceplat_data=True)["data"]["platform"]
        ours = plate_forces(read_c3d(path))
        assert len(ours) == len(reference), local
        for mine, theirs in zip(ours, reference):
            if theirs["force"].size == 0 or mine.plate.problem:
                continue            # no analog samples; or corners that are not a plate
            # ezc3d labels lengths by POINT:UNITS ("m" when absent) but uses the file's
            # numbers; compare in the file's unit (Kistler.c3d has no POINT:UNITS).
            unit = mine.plate.unit
            force = theirs["force"].T
            moment = theirs["moment"].T * unit
            cop = theirs["center_of_pressure"].T * unit
            free = theirs["Tz"].T * unit
            about_centre = mine.moment - np.cross(mine.plate.centre, mine.force)
            scale = max(np.abs(force).max(), 1.0)
            np.testing.assert_allclose(mine.force, force, atol=1e-9 * scale, err_msg=local)
            np.testing.assert_allclose(about_centre, moment, atol=1e-9 * scale, err_msg=local)
            both = np.isfinite(mine.cop).all(axis=1)
            assert both.any() or np.abs(force[:, 2]).max() < 20.0, local
            np.testing.assert_allclose(mine.cop[both], cop[both], atol=1e-9, err_msg=local)
            np.testing.assert_allclose(mine.free_moment[both], free[both],
                                       atol=1e-9 * scale, err_msg=local)
            compared += 1
    assert compared >= 100


def test_plates_at_marker_rate_and_total():
    trial = read_c3d(realdata_path("biomechzoo_sample_study/HC030A/Turn/HC030A22.c3d"))
    analog = plate_forces(trial)
    frames = plate_forces(trial, rate="marker")
    assert frames[0].samples == trial.frames and frames[0].rate == trial.rate
    per = int(trial.analog_rate / trial.rate)
    for a, f in zip(analog, frames):
        # A frame's value is the mean of the analog samples around it (one frame wide).
        k = np.arange(5, trial.frames - 5)
        centred = np.stack([a.force[i * per - per // 2:i * per - per // 2 + per].mean(axis=0)
                            for i in k])
        np.testing.assert_allclose(f.force[k], centred, atol=1e-9)
    total = total_forces(frames)
    np.testing.assert_allclose(total.force, frames[0].force + frames[1].force)
    # While only one plate is loaded, the combined COP is that plate's.
    one = np.isfinite(frames[0].cop).all(axis=1) & (np.abs(frames[1].force[:, 2]) < 1.0)
    assert one.sum() > 10
    np.testing.assert_allclose(total.cop[one], frames[0].cop[one], atol=1e-6)
    # The stance reaction points up and carries about body weight (a 10-75 kg person).
    assert 100 < frames[0].force[:, 2].max() < 1500


def _synthetic_plate(kind: int, channels: np.ndarray, origin=(0.0, 0.0, -40.0),
                     cal=None) -> Trial:
    corners = np.array([[500.0, 0, 0], [0, 0, 0], [0, 400.0, 0], [500.0, 400.0, 0]]).T
    params = {"FORCE_PLATFORM": {
        "USED": np.array([1]), "TYPE": np.array([kind]),
        "CORNERS": corners.reshape(3, 4, 1), "ORIGIN": np.array(origin).reshape(3, 1),
        "CHANNEL": np.arange(1, channels.shape[1] + 1).reshape(-1, 1)}}
    if cal is not None:
        params["FORCE_PLATFORM"]["CAL_MATRIX"] = cal.reshape(6, 6, 1)
    return Trial(["a"], np.zeros((len(channels) // 10, 1, 3)), 100.0, "mm",
                 analogs=channels, analog_labels=[f"c{i}" for i in range(channels.shape[1])],
                 analog_rate=1000.0, parameters=params)


def test_type2_hand_calculation():
    # 700 N straight down through a point 100 mm along plate X, 50 mm along plate Y, from
    # the surface centre; the transducer 40 mm under the surface.
    f = np.array([0.0, 0.0, 700.0])                    # plate axes (Z into the plate here)
    r = np.array([100.0, 50.0, 40.0])                  # from the transducer, mm
    m = np.cross(r, f)                                 # N·mm about the transducer
    data = np.tile(np.r_[f, m], (20, 1))
    result = plate_forces(_synthetic_plate(2, data))[0]
    plate = result.plate
    # Plate axes: X = c1 - c2 = +x lab, Y = c1 - c4 = -y lab, Z = X × Y = -z lab.
    np.testing.assert_allclose(plate.axes, np.diag([1.0, -1.0, -1.0]), atol=1e-12)
    np.testing.assert_allclose(result.force[0], [0, 0, -700.0])
    np.testing.assert_allclose(result.cop[0], plate.centre + [0.1, -0.05, 0.0], atol=1e-12)
    np.testing.assert_allclose(result.free_moment[0], 0.0, atol=1e-9)
    # Type 4 with a calibration that doubles the channels: doubled force, same COP.
    cal = 2.0 * np.eye(6)
    doubled = plate_forces(_synthetic_plate(4, data / 2.0, cal=cal))[0]
    np.testing.assert_allclose(doubled.force, result.force)
    np.testing.assert_allclose(doubled.cop, result.cop, atol=1e-12)


def test_bad_plates_one_clear_error():
    data = np.zeros((20, 6))
    with pytest.raises(MocapError, match="CAL_MATRIX"):
        plate_forces(_synthetic_plate(4, data))
    with pytest.raises(MocapError, match="type 7"):
        plate_forces(_synthetic_plate(7, data))
    trial = _synthetic_plate(2, data[:, :4])
    with pytest.raises(MocapError, match="fewer than 6"):
        force_plates(trial)
    assert force_plates(Trial(["a"], np.zeros((3, 1, 3)), 100.0)) == []
