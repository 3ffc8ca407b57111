"""Subject measurements a walk lacks, estimated from its own markers (with a warning each).

Plug-in Gait needs the inter-ASIS distance, leg lengths, knee widths and ankle widths
(:class:`~mocap.plugingait.model.Subject`).  When neither the walk's nor the static's C3D
PROCESSING group gives one (and no medial marker of a static measures a width),
:func:`estimate_missing` stands in a value from the walk's markers and says so with one
:class:`EstimatedMeasurementWarning` per value, naming the measurement and the value used:

* inter-ASIS distance: the median LASI–RASI distance;
* leg length: the 95th percentile ASIS–lateral malleolus distance plus the marker radius
  (the leg extended);
* knee width: :data:`KNEE_WIDTH_PER_ASIS` × the median LASI–RASI marker distance;
* ankle width: :data:`ANKLE_WIDTH_PER_FOOT` × the median HEE–TOE marker distance of that
  side (without those markers, :data:`ANKLE_WIDTH_PER_LEG` × the leg length).

The ratios are medians over the 12 legs of 6 "design" subjects of the corpus (alternate
subjects; benchmarks/plugingait_estimates.py); no published ratio of these marker
distances was found to cite.  Held out (10 legs of 5 other subjects) the knee width is
off by 8.7 mm on average (24 mm at most) and the ankle width by 3.2 mm (8 mm at most); a
knee width off by 10 mm moves the knee centre 5 mm along the flexion axis, about 1° of hip
and knee adduction (held-out median adduction RMS against Vicon's 0.9° at the hip and 1.2°
at the knee, against 0.3° with the measured widths; docs/plugingait.md).
"""
from __future__ import annotations

import warnings
from collections.abc import Collection
from dataclasses import replace

import numpy as np

from mocap.errors import MocapError, MocapWarning
from mocap.plugingait.model import SIDES, Subject

#: Knee width per metre of LASI–RASI marker distance (median of the design legs; held
#: out: mean absolute error 8.7 mm).  Chosen over leg length (13.9 mm held out), a
#: constant (7.7 mm held out but 13.2 mm on design, 44 mm on the largest knee), the foot
#: (13.0 mm) and the lateral knee marker's offset from the hip–ankle line (27 mm).
KNEE_WIDTH_PER_ASIS = 0.445
#: Ankle width per metre of HEE–TOE marker distance (design 3.1 mm, held out 3.2 mm mean
#: absolute error; leg length gives 5.3 / 4.3 mm).
ANKLE_WIDTH_PER_FOOT = 0.368
#: Ankle width per metre of leg length, when the foot's markers are missing.
ANKLE_WIDTH_PER_LEG = 0.079
#: The provenance (``Subject.sources``) of a value estimated here.
ESTIMATED = "estimated from the walk"


class EstimatedMeasurementWarning(MocapWarning):
    """A subject measurement was not given and has been estimated from the markers."""


def _say(path: str | None, what: str, value_m: float, how: str) -> None:
    warnings.warn(f"{path or 'trial'}: {what} not measured: estimated {value_m * 1000:.0f} mm "
                  f"({how})", EstimatedMeasurementWarning, stacklevel=4)


def estimate_missing(subject: Subject, markers: dict, path: str | None = None,
                     keep: dict | None = None, *, warn: bool = True, lengths: bool = True,
                     widths: bool | Collection[tuple[str, str]] = True) -> Subject:
    """Fill the measurements a subject lacks from a walk's markers.

    Parameters
    ----------
    subject : Subject
        None marks a value to estimate; given values are kept.
    markers : dict of str to ndarray (frames, 3)
        The walk's Plug-in Gait markers, metres (bare names: LASI …).
    path : str, optional
        Named in warnings and errors.
    keep : dict of str to bool ndarray (frames,), optional
        Frames no gap fill wrote (:func:`mocap.clean.gapfill.recorded_frames`): only
        those count, so a fill cannot change an estimate.
    warn : bool
        One :class:`EstimatedMeasurementWarning` per estimated value.
    lengths : bool
        The inter-ASIS distance and leg lengths (False leaves them as they are, for a
        static to give).
    widths : bool or collection of (str, str)
        The knee and ankle widths: all missing ones (True), none, or only these
        (``("knee_width", "l")`` …; the others are left for a static's medial markers).

    Returns
    -------
    Subject
        A copy with every missing length filled, metres.

    Raises
    ------
    MocapError
        The markers an estimate needs (LASI, RASI, an ankle marker) are missing.
    """
    sub = replace(subject, sources=dict(subject.sources),
                  leg_length=dict(subject.leg_length),
                  knee_width=dict(subject.knee_width), ankle_width=dict(subject.ankle_width))
    keep = keep or {}

    def distance(a: str, b: str) -> np.ndarray:
        absent = [name for name in (a, b) if name not in markers]
        if absent:
            raise MocapError(f"no {' or '.join(absent)} marker to estimate the subject's "
                             "measurements from", path)
        d = np.linalg.norm(markers[a] - markers[b], axis=1)
        for name in (a, b):
            if name in keep:
                d = np.where(keep[name], d, np.nan)
        return d

    wanted = {(key, side) for key in ("knee_width", "ankle_width") for side in SIDES
              if getattr(sub, key)[side] is None
              and (widths is True or (widths and (key, side) in widths))}
    asis = None
    if (lengths and sub.inter_asis is None) or any(k == "knee_width" for k, _ in wanted):
        asis = float(np.nanmedian(distance("LASI", "RASI")))
    if lengths and sub.inter_asis is None:
        sub.inter_asis = asis
        sub.sources[("inter_asis", None)] = ESTIMATED
        if warn:
            _say(path, "inter-ASIS distance", asis, "median LASI-RASI marker distance")
    legs = dict(sub.leg_length)
    for side in SIDES:
        S = side.upper()
        if legs[side] is None and f"{S}ANK" in markers and (lengths or wanted):
            d = distance(f"{S}ASI", f"{S}ANK")
            d = d[np.isfinite(d)]
            if d.size:
                legs[side] = float(np.percentile(d, 95)) + sub.radius
    known = [legs[s] for s in SIDES if legs[s] is not None]
    if lengths and not known:
        raise MocapError("Plug-in Gait needs the leg length (the file's PROCESSING group "
                         "has none and no ankle marker gives an estimate)", path)
    for side in SIDES:
        if legs[side] is None and known:
            legs[side] = known[0]
    if lengths:
        for side in SIDES:
            if sub.leg_length[side] is None:
                sub.leg_length[side] = legs[side]
                sub.sources[("leg_length", side)] = ESTIMATED
                if warn:
                    _say(path, f"{side.upper()} leg length", legs[side],
                         "95th percentile ASIS-ankle marker distance plus the marker radius")
    for side in SIDES:
        S = side.upper()
        if ("knee_width", side) in wanted:
            sub.knee_width[side] = KNEE_WIDTH_PER_ASIS * asis
            sub.sources[("knee_width", side)] = ESTIMATED
            if warn:
                _say(path, f"{S} knee width", sub.knee_width[side],
                     f"{KNEE_WIDTH_PER_ASIS} x LASI-RASI marker distance {asis * 1000:.0f} mm")
        if ("ankle_width", side) in wanted:
            foot = np.nan
            if f"{S}HEE" in markers and f"{S}TOE" in markers:
                d = distance(f"{S}HEE", f"{S}TOE")
                foot = float(np.nanmedian(d)) if np.isfinite(d).any() else np.nan
            if not np.isfinite(foot) and legs[side] is None:
                raise MocapError(f"no {S}HEE/{S}TOE or leg length to estimate the {S} "
                                 f"ankle width from", path)
            if np.isfinite(foot):
                sub.ankle_width[side] = ANKLE_WIDTH_PER_FOOT * foot
                how = f"{ANKLE_WIDTH_PER_FOOT} x {S}HEE-{S}TOE distance {foot * 1000:.0f} mm"
            else:
                sub.ankle_width[side] = ANKLE_WIDTH_PER_LEG * legs[side]
                how = (f"{ANKLE_WIDTH_PER_LEG} x leg length "
                       f"{legs[side] * 1000:.0f} mm; no {S}HEE/{S}TOE")
            sub.sources[("ankle_width", side)] = ESTIMATED
            if warn:
                _say(path, f"{S} ankle width", sub.ankle_width[side], how)
    return sub
