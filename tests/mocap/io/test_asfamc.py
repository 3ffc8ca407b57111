"""ASF/AMC values a skeleton or motion cannot have (found by the hostile re-run of issue 11):
each was read without a word — ``:units length 0`` (taken as 1), a bone of negative length or
with direction 0 0 0, an AMC angle of 1e300 degrees — and AMC frame numbers that do not count
up by one were ignored silently."""
from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from mocap.errors import MocapError, MocapWarning
from mocap.io.asfamc import read_asf_amc

DATA = Path(__file__).resolve().parents[2] / "data"
ASF = (DATA / "cmu_lambada.asf").read_text()
AMC = (DATA / "cmu_lambada.amc").read_text()


def _pair(tmp_path: Path, asf: str = ASF, amc: str = AMC) -> tuple[Path, Path]:
    (tmp_path / "s.asf").write_text(asf)
    (tmp_path / "s_01.amc").write_text(amc)
    return tmp_path / "s.asf", tmp_path / "s_01.amc"


@pytest.mark.parametrize("old, new, file, words", [
    ("  length 0.45\n", "  length 0\n", "s.asf", ":units length must be > 0"),
    ("  length 0.45\n", "  length -0.45\n", "s.asf", ":units length must be > 0"),
    ("     length 2.58915 \n", "     length -2.58915 \n", "s.asf",
     "bone 'lhipjoint': length must be >= 0, found -2.58915"),
    ("     direction 0.643272 -0.706573 0.294883 \n", "     direction 0 0 0\n", "s.asf",
     "bone 'lhipjoint': direction 0 0 0 points nowhere"),
    ("lowerback 3.85054 1.07078 4.92185", "lowerback 3.85054 1e300 4.92185", "s_01.amc",
     "bone 'lowerback' has a value that is not a finite number within ±1e+06"),
])
def test_impossible_skeleton_or_motion_values_are_refused_naming_the_file(
        old, new, file, words, tmp_path):
    asf, amc = ASF, AMC
    if file == "s.asf":
        assert old in asf
        asf = asf.replace(old, new, 1)
    else:
        assert old in amc
        amc = amc.replace(old, new, 1)
    with pytest.raises(MocapError) as caught:
        read_asf_amc(*_pair(tmp_path, asf, amc))
    assert file in str(caught.value) and words in str(caught.value)


def test_amc_frame_numbers_that_jump_warn_once_and_frames_keep_file_order(tmp_path):
    reference = read_asf_amc(*_pair(tmp_path))
    lines = AMC.splitlines()
    numbers = [i for i, line in enumerate(lines) if line.strip().isdigit()]
    assert len(numbers) == 4
    lines[numbers[2]], lines[numbers[3]] = "1000000000", "7"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        motion = read_asf_amc(*_pair(tmp_path, amc="\n".join(lines) + "\n"))
    notes = [str(w.message) for w in caught if issubclass(w.category, MocapWarning)]
    assert len(notes) == 1 and "frame 1000000000 after 2" in notes[0], notes
    assert motion.frames == reference.frames == 4
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        read_asf_amc(*_pair(tmp_path))
    assert not [w for w in caught if issubclass(w.category, MocapWarning)]
