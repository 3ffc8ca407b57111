"""Cleaning marker trajectories: gap filling and zero-lag low-pass, under one name.

The two jobs live in their own modules: :mod:`mocap.gapfill` (gaps filled from
donor markers or a spline, inside the gap only; the donor methods in
:mod:`mocap.donorfill`) and :mod:`mocap.filtering` (the Butterworth low-pass,
per run of valid samples, and the other filters).  This module keeps the names
``mocap.clean`` has always offered.
"""
from __future__ import annotations

from mocap.filtering import butterworth_sos, lowpass
from mocap.gapfill import Gap, GapReport, fill_gaps, filled_masks, recorded_frames

__all__ = ["Gap", "GapReport", "butterworth_sos", "fill_gaps", "filled_masks", "lowpass",
           "recorded_frames"]
