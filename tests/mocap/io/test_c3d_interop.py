"""C3D → C3D keeps what the data still match, checked with ezc3d and the ``c3d`` package.

- ezc3d's force-platform extraction (forces, moments, centre of pressure, free moment)
  of the toolkit's copy equals that of the original, for one file of every folder of
  the corpus with force plates that ezc3d reads;
- every parameter group survives, FORCE_PLATFORM and the ANALOG scales, offsets and
  units unchanged, the first frame and the EVENT times kept;
- analog values equal the ``c3d`` package's (which applies ANALOG:FORMAT "UNSIGNED" to
  the offsets, as the C3D User Guide says) on every real file it reads, before and
  after the rewrite.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from mocap.errors import MocapError
from mocap.io import read, write
from mocap.io.c3d.read import ezc3d_refusal
from mocap.io.c3d.parameters import analog_offsets
from mocap.io.c3d.layout import inspect_c3d
from tests.conftest import REALDATA, realdata_path


def _real_c3d():
    return sorted(p for p in REALDATA.rglob("*") if p.suffix.lower() == ".c3d") \
        if REALDATA.exists() else []


def _layout(path):
    try:
        return inspect_c3d(path)
    except MocapError:
        return None


def _plate_files() -> list[Path]:
    """One C3D file with force plates per folder (one for the whole Plug-in Gait study
    of 8 subjects), among those ezc3d reads."""
    chosen: dict[Path, Path] = {}
    for path in _real_c3d():
        parts = path.relative_to(REALDATA).parts
        key = Path(parts[0]) if parts[0].startswith("biomechzoo") else path.parent
        layout = _layout(path)
        if layout is None or key in chosen or ezc3d_refusal(layout):
            continue
        used = layout.get("FORCE_PLATFORM", "USED")
        if isinstance(used, np.ndarray) and used.size and int(used.reshape(-1)[0]) > 0:
            chosen[key] = path
    return list(chosen.values())


@pytest.mark.filterwarnings("ignore::mocap.errors.MocapWarning")
def test_rewritten_c3d_gives_ezc3d_the_same_force_platforms(tmp_path):
    import ezc3d

    realdata_path()
    files = _plate_files()
    assert len(files) >= 10
    for path in files:
        trial = read(path)
        copy = tmp_path / "copy.c3d"
        notes = write(trial, copy)
        assert not any("FORCE_PLATFORM" in note for note in notes), (path, notes)
        original = ezc3d.c3d(str(path), extract_forceplat_data=True)["data"]["platform"]
        rewritten = ezc3d.c3d(str(copy), extract_forceplat_data=True)["data"]["platform"]
        assert len(rewritten) == len(original) > 0, path
        for before, after in zip(original, rewritten):
            for key in ("force", "moment", "center_of_pressure", "Tz"):
                expected = np.asarray(before[key], float)
                actual = np.asarray(after[key], float)
                # with no load the centre of pressure is ±M/0: either infinity
                np.testing.assert_array_equal(np.isfinite(actual), np.isfinite(expected),
                                              err_msg=f"{path} {key}")
                expected = np.where(np.isfinite(expected), expected, np.nan)
                actual = np.where(np.isfinite(actual), actual, np.nan)
                scale = np.nanmax(np.abs(expected), initial=1.0)
                # the copy stores 32-bit floats of the scaled values: 1e-6 relative
                np.testing.assert_allclose(actual, expected, rtol=1e-5,
                                           atol=2e-6 * scale, equal_nan=True,
                                           err_msg=f"{path} {key}")
            np.testing.assert_allclose(after["corners"], before["corners"], rtol=1e-6)
            np.testing.assert_allclose(after["cal_matrix"], before["cal_matrix"], rtol=1e-6)


@pytest.mark.filterwarnings("ignore::mocap.errors.MocapWarning")
def test_rewritten_c3d_keeps_groups_plates_analog_parameters_first_frame_and_events(
        tmp_path):
    realdata_path()
    for path in _plate_files():
        trial = read(path)
        copy = tmp_path / "copy.c3d"
        write(trial, copy)
        back = read(copy)
        before, after = trial.parameters, back.parameters
        assert set(before) <= set(after), (path, set(before) - set(after))
        for name, value in before["FORCE_PLATFORM"].items():
            np.testing.assert_array_equal(np.asarray(after["FORCE_PLATFORM"][name]),
                                          np.asarray(value), err_msg=f"{path} {name}")
        channels = len(trial.analog_labels)
        for name in ("SCALE", "UNITS", "DESCRIPTIONS"):
            # per channel: files often list more entries than channels (32 for 16)
            if name in before["ANALOG"] and len(before["ANALOG"][name]):
                assert np.array_equal(_strings(after["ANALOG"][name])[:channels],
                                      _strings(before["ANALOG"][name])[:channels]), \
                    (path, name)
        np.testing.assert_array_equal(after["ANALOG"]["GEN_SCALE"],
                                      before["ANALOG"].get("GEN_SCALE", [1.0]))
        np.testing.assert_array_equal(analog_offsets(after["ANALOG"], channels),
                                      analog_offsets(before["ANALOG"], channels))
        for group in ("MANUFACTURER", "SUBJECTS"):
            for name, value in before.get(group, {}).items():
                # ezc3d writes a list of one string as a plain string, [] as '': the same text
                assert np.array_equal(_strings(after[group][name]), _strings(value)), \
                    (path, group, name)
        assert back.first_frame == trial.first_frame, path
        assert back.analog_labels == trial.analog_labels
        np.testing.assert_allclose(back.analogs, trial.analogs, rtol=1e-6, atol=1e-6)
        if "EVENT" in before:
            np.testing.assert_allclose(after["EVENT"]["TIMES"], before["EVENT"]["TIMES"],
                                       rtol=1e-6)
            assert back.events == trial.events or \
                [e["frame"] for e in back.events] == \
                [e["frame"] for e in trial.events]


def _strings(value):
    """Text of a character parameter: one string or a list of them, blanks dropped."""
    if isinstance(value, np.ndarray):
        return value.reshape(-1)
    return np.asarray([v for v in ([value] if isinstance(value, str) else value) if v])


def _c3d_package_analogs(path: Path, frames: int) -> np.ndarray:
    """Scaled analog values of the first ``frames`` frames, (samples, channels)."""
    import c3d

    with open(path, "rb") as handle, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reader = c3d.Reader(handle)
        blocks = []
        for index, (_, _, analog) in enumerate(reader.read_frames()):
            blocks.append(np.asarray(analog, float).T)
            if index + 1 == frames:
                break
    return np.concatenate(blocks, axis=0)


@pytest.mark.filterwarnings("ignore::mocap.errors.MocapWarning")
def test_analogs_equal_the_c3d_package_before_and_after_a_rewrite(tmp_path):
    """The c3d package reads OFFSET as unsigned under ANALOG:FORMAT "UNSIGNED"."""
    realdata_path()
    compared = 0
    for path in _real_c3d():
        layout = _layout(path)
        if layout is None or not layout.analog_channels or layout.warnings:
            continue
        trial = read(path)
        if trial.analogs is None:
            continue
        try:
            reference = _c3d_package_analogs(path, 20)
        except Exception:               # the package refuses some valid files
            continue
        rows = reference.shape[0]
        if reference.shape[1] != trial.analogs.shape[1]:
            continue
        np.testing.assert_allclose(trial.analogs[:rows], reference, rtol=1e-6, atol=1e-6,
                                   err_msg=str(path))
        copy = tmp_path / "copy.c3d"
        write(trial, copy)
        np.testing.assert_allclose(_c3d_package_analogs(copy, 20), reference, rtol=1e-5,
                                   atol=1e-5 * max(1.0, np.abs(reference).max()),
                                   err_msg=f"{path} (rewritten)")
        compared += 1
    assert compared >= 30


@pytest.mark.filterwarnings("ignore::mocap.errors.MocapWarning")
def test_unsigned_format_makes_the_offset_unsigned():
    """ANALOG:FORMAT "UNSIGNED": the word 0x8000 is the offset 32768, not -32768 (hand
    calculation: raw 32778 - 32768 = 10, times SCALE 0.5 = 5)."""
    import dataclasses

    from mocap.io.c3d.read import _analog_transform

    layout = _layout(realdata_path("c3dorg_via_c3dio", "sample_02", "pc_int.c3d"))
    channels = layout.analog_channels
    signed = dict(layout.parameters["ANALOG"])
    signed.update(OFFSET=np.full(channels, -32768, dtype=np.int64),
                  SCALE=np.full(channels, 0.5), GEN_SCALE=np.array([1.0]))
    unsigned = dict(signed, FORMAT="UNSIGNED")
    raw = np.full((3, channels), 32778 - 65536, dtype=float)     # the stored word 0x800A
    for group, expected in ((unsigned, 5.0), (signed, (-32758 + 32768) * 0.5)):
        patched = dataclasses.replace(layout, parameters=dict(layout.parameters,
                                                               ANALOG=group))
        np.testing.assert_allclose(_analog_transform(patched, raw), expected)
    unsigned_list = dict(unsigned, FORMAT=["UNSIGNED"])          # 2-D character parameter
    patched = dataclasses.replace(layout, parameters=dict(layout.parameters,
                                                           ANALOG=unsigned_list))
    np.testing.assert_allclose(_analog_transform(patched, raw), 5.0)
