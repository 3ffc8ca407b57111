"""Cleaning marker trajectories: gap filling and zero-lag low-pass filtering.

Modules
-------
gapfill
    Gaps filled from donor markers or a spline, inside the gap only (:func:`fill_gaps`,
    :class:`GapReport`).
donorfill
    The donor methods behind :func:`fill_gaps` (rigid-body and ridge-model donors).
filtering
    The one Butterworth low-pass (:func:`lowpass`, per run of valid samples, zero lag) and
    the other filters.

The names below are importable from ``mocap.clean`` itself; they load on first use, so
importing one module of the package does not load the others.

Examples
--------
>>> from mocap.clean import lowpass
>>> lowpass.__module__
'mocap.clean.filtering'
"""
from __future__ import annotations

__all__ = ["Gap", "GapReport", "butterworth_sos", "fill_gaps", "filled_masks", "lowpass",
           "recorded_frames"]

_HOMES = {"butterworth_sos": "filtering", "lowpass": "filtering", "Gap": "gapfill",
          "GapReport": "gapfill", "fill_gaps": "gapfill", "filled_masks": "gapfill",
          "recorded_frames": "gapfill"}


def __getattr__(name: str):
    if name in _HOMES:
        import importlib
        return getattr(importlib.import_module(f"mocap.clean.{_HOMES[name]}"), name)
    raise AttributeError(f"module 'mocap.clean' has no attribute {name!r}")
