"""The frame rate of a corpus, for the clips synthesised from its model.

``mocap decompose`` records the rate its trials were captured at (the median over the
files, read from their headers where they state it) in the model; ``mocap synthesize``
writes its clips at that rate unless ``--fps`` asks for another, so a model of a 30 fps
corpus gives 30 fps clips instead of the model's own time-normalised sampling (samples
over the cycle's predicted duration: 109.72 fps for a bandai2 walk).
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from mocap.errors import MocapError

#: Key of the capture rate (Hz) in a model's ``cleaning`` record (what it knows of how its
#: trials were read: saved with the model).
RATE_KEY = "capture_rate_hz"
#: ASF/AMC files store no rate; the readers take CMU's and HDM05's 120 Hz.
AMC_RATE_HZ = 120.0


def _bvh_rate(path: Path) -> float | None:
    """1 / 'Frame Time:' of a BVH header, without reading its frames."""
    from mocap.skeleton import frame_rate

    with open(path, encoding="utf-8", errors="replace") as handle:
        for line in handle:
            if line.strip().lower().startswith("frame time:"):
                try:
                    seconds = float(line.split(":", 1)[1])
                except ValueError:
                    return None
                return frame_rate(seconds) if seconds > 0 else None
    return None


def file_rate_hz(path: str | os.PathLike) -> float | None:
    """Frames per second of one trial file (None when it holds no usable rate).

    BVH and C3D give the rate their header states (the frames are not read), AMC the
    120 Hz the reader assumes, a joint-angle CSV the median step of its time column and a
    marker CSV or TRC the rate its reader finds.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    try:
        if suffix == ".bvh":
            return _bvh_rate(path)
        if suffix == ".amc":
            return AMC_RATE_HZ
        if suffix == ".c3d":
            from mocap.io.c3d.layout import inspect_c3d
            rate = float(inspect_c3d(path).rate)
        else:
            from mocap.io import file_kind, read
            if file_kind(path) == "angles":
                from mocap.io.angles_csv import read_angles_csv
                steps = np.diff(read_angles_csv(path).times)
                steps = steps[steps > 0]
                rate = 1.0 / float(np.median(steps)) if steps.size else 0.0
            else:
                rate = float(read(path).rate)
    except (MocapError, OSError):
        return None
    return rate if np.isfinite(rate) and rate > 0 else None


def corpus_rate_hz(paths) -> float | None:
    """Median frame rate (Hz) over trial files; None when none states a rate.

    Parameters
    ----------
    paths : iterable of str or PathLike
        The corpus' trial files (``MotionCorpus.sources`` values).
    """
    rates = [rate for rate in (file_rate_hz(p) for p in paths) if rate is not None]
    return float(np.median(rates)) if rates else None
