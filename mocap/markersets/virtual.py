"""Virtual markers: midpoints, fixed offsets in a marker frame, hip joint centre regressions,
Plug-in Gait's knee and ankle joint centres.

The ``[[virtual]]`` tables of a marker set (``docs/formats/markerset-toml.md``) become
:class:`~mocap.markersets.model.VirtualMarker` objects; :func:`virtual_positions` computes
one of them over all frames, :meth:`~mocap.markersets.model.MarkerSet.apply_virtual` all of
them for a trial.

Hip joint centre regressions
----------------------------
All three work in the Plug-in Gait pelvis frame: origin ``O`` = midpoint of the
ASIS markers, ``y = unit(LASI - RASI)`` (left), ``x`` = the component of
``O - SACR`` orthogonal to ``y``, normalised (anterior), ``z = x × y`` (up).
Pelvis width ``PW = |LASI - RASI|`` and depth ``PD = |O - SACR|`` are the
medians over the trial (the pelvis is rigid; per-frame values would add noise).
The hip joint centre is ``O + x·X + y·Y + z·Z`` with ``Y`` positive for the left
hip and negated for the right one.

``davis`` (Davis, Ounpuu, Tyburski & Gage 1991, *Hum Mov Sci* 10:575-587; the
Vicon Plug-in Gait reference guide, section "Hip joint centre"), with leg length
``L`` and marker radius ``r``, lengths in millimetres::

    C  = 0.115 L - 15.3            (ASIS-trochanter distance to HJC, Davis)
    AT = 0.1288 L - 48.56          (ASIS-trochanter distance, Plug-in Gait)
    theta = 0.5 rad, beta = 0.314 rad
    X = C cos(theta) sin(beta) - (AT + r) cos(beta)
    Y = -(C sin(theta) - PW / 2)
    Z = -C cos(theta) cos(beta) - (AT + r) sin(beta)

``L`` is ``leg_length`` when given, else estimated per trial as the 95th
percentile of the distance from the hip's ASIS to the ``ankle`` marker of the
same side (on the eight Plug-in Gait walking trials of the biomechzoo study and
pyCGM's sample, within 1-6 % of the measured leg length; an error of 20 mm in
``L`` moves the centre by about 3 mm).

``bell`` (Bell, Pedersen & Brand 1990, *J Biomech* 23:617-621)::

    X = -0.19 PW,  Y = 0.36 PW,  Z = -0.30 PW

``harrington`` (Harrington, Zavatsky, Lawson, Yuan & Theologis 2007,
*J Biomech* 40:595-602, the width-and-depth regression), in millimetres::

    X = -0.24 PD - 9.9,  Y = 0.33 PW + 7.3,  Z = -0.30 PW - 10.9

Knee and ankle joint centres
----------------------------
``joint_centre`` is Plug-in Gait's chord (:func:`mocap.markersets.chord.chord`): from the wand
(plane) marker, the proximal joint centre and the marker on the joint (THI, HJC, KNE for
the knee; TIB, KJC, ANK for the ankle), the centre lies at half the joint's width plus the
marker radius from the marker, at a right angle to the proximal joint centre, in the wand's
plane turned about the segment axis by the subject's thigh (knee) or shank (ankle)
rotation offset. Width, rotation offset and marker diameter are the subject values Vicon
stores in the trial's PROCESSING group (``LKneeWidth``, ``LThighRotation``,
``MarkerDiameter``, …). On the biomechzoo Plug-in Gait walks this gives Vicon's own knee
joint centre (the femur origin ``LFEO``/``RFEO`` stored in the files) to a median 2 mm;
the lateral knee marker is 50-70 mm away. A trial without the width keeps the marker on
the joint (a width of 0): the centre then sits on the flexion axis's lateral end.
"""
from __future__ import annotations

import numpy as np

from mocap.markersets.axes import frame_from_markers
from mocap.markersets.chord import chord, processing_number
from mocap.trial import Trial

#: Kinds of virtual markers.
VIRTUAL_TYPES = ("midpoint", "offset", "hip_joint_centre", "joint_centre")
#: Joints whose centre ``joint_centre`` finds: the PROCESSING names of the subject's width
#: (mm) and rotation offset (radians), ``{S}`` the side's letter.
JOINT_CENTRES = {"knee": ("{S}KneeWidth", "{S}ThighRotation"),
                 "ankle": ("{S}AnkleWidth", "{S}ShankRotation")}
#: Hip joint centre regressions.
HJC_METHODS = ("davis", "bell", "harrington")
#: Davis et al. (1991) hip regression angles theta and beta, radians: 0.5 and 0.314 as
#: Plug-in Gait stores them (single precision).
DAVIS_THETA = 0.500000178813934
DAVIS_BETA = 0.314000427722931


def _median_distance(a: np.ndarray, b: np.ndarray) -> float:
    d = np.linalg.norm(a - b, axis=-1)
    d = d[np.isfinite(d)]
    return float(np.median(d)) if d.size else float("nan")


def virtual_positions(v, get, trial: Trial, keep: list[np.ndarray] | None = None
                      ) -> np.ndarray:
    """Positions of one virtual marker over all frames.

    Parameters
    ----------
    v : mocap.markersets.model.VirtualMarker
    get : callable
        ``get(name)`` → positions of an input marker, ndarray (frames, 3), metres.
    trial : Trial
        The trial the inputs come from.
    keep : list of ndarray of bool (frames,), optional
        Per input of ``v.inputs``, the frames no gap fill wrote: a hip joint
        centre's whole-trial estimates (pelvis width and depth, leg length) use
        only those, so they equal the estimates of the unfilled trial.

    Returns
    -------
    ndarray, shape (frames, 3), metres
        NaN where an input is missing.
    """
    inputs = [get(name) for name in v.markers]
    if v.type == "midpoint":
        return np.mean(np.stack(inputs), axis=0)
    if v.type == "offset":
        rotation = frame_from_markers(*inputs)
        return inputs[0] + np.einsum("fij,j->fi", rotation, np.asarray(v.offset))
    if v.type == "joint_centre":
        return _chord_joint_centre(v, *inputs, trial=trial)
    return _hip_joint_centre(v, *inputs, ankle=get(v.ankle) if v.ankle else None,
                             trial=trial, keep=keep)


def pelvis_frame(rasi: np.ndarray, lasi: np.ndarray, sacr: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Plug-in Gait pelvis frame, vectorised over frames.

    Parameters
    ----------
    rasi, lasi, sacr : ndarray, shape (frames, 3), metres
        Right and left ASIS and the sacrum (or the PSIS midpoint).

    Returns
    -------
    rotation : ndarray, shape (frames, 3, 3)
        Columns x (anterior), y (left), z (up).
    origin : ndarray, shape (frames, 3)
        Midpoint of the ASIS markers.
    """
    origin = 0.5 * (rasi + lasi)
    with np.errstate(invalid="ignore", divide="ignore"):
        y = lasi - rasi
        y = y / np.linalg.norm(y, axis=-1, keepdims=True)
        back = origin - sacr
        x = back - np.sum(back * y, axis=-1, keepdims=True) * y
        x = x / np.linalg.norm(x, axis=-1, keepdims=True)
        z = np.cross(x, y)
    return np.stack([x, y, z], axis=-1), origin


def davis_asis_trochanter(leg_length: float) -> float:
    """ASIS-trochanter distance regressed from the leg length, metres.

    Plug-in Gait's ``0.1288 L - 48.56`` mm (Davis et al. 1991), with ``L`` and the
    result in metres.

    Examples
    --------
    >>> round(davis_asis_trochanter(0.9), 5)
    0.06736
    """
    return 0.1288 * leg_length - 0.04856


def hip_joint_centre_offset(method: str, side: str, pelvis_width: float,
                            pelvis_depth: float | None = None,
                            leg_length: float | None = None,
                            marker_diameter: float = 0.014,
                            asis_trochanter: float | None = None) -> np.ndarray:
    """Hip joint centre in the Plug-in Gait pelvis frame, metres, shape (3,).

    Parameters
    ----------
    method : {"davis", "bell", "harrington"}
        Regression (formulas and sources in the module docstring).
    side : {"left", "right"}
    pelvis_width : float
        Inter-ASIS distance, metres.
    pelvis_depth : float, optional
        Mid-ASIS to sacrum (or PSIS midpoint) distance, metres (harrington).
    leg_length : float, optional
        Metres (davis): the mean of both legs in Plug-in Gait.
    marker_diameter : float
        Metres (davis).
    asis_trochanter : float, optional
        Measured ASIS-trochanter distance of this side, metres (davis); default the
        regression :func:`davis_asis_trochanter` of ``leg_length``.

    Examples
    --------
    >>> hip_joint_centre_offset("bell", "left", 0.25).round(4)
    array([-0.0475,  0.09  , -0.075 ])
    """
    sign = 1.0 if side == "left" else -1.0
    if method == "bell":
        x, y, z = -0.19 * pelvis_width, 0.36 * pelvis_width, -0.30 * pelvis_width
    elif method == "harrington":
        pw, pd = pelvis_width * 1000.0, pelvis_depth * 1000.0
        x, y, z = (-0.24 * pd - 9.9) / 1000, (0.33 * pw + 7.3) / 1000, \
            (-0.30 * pw - 10.9) / 1000
    elif method == "davis":
        radius = marker_diameter / 2.0
        c = 0.115 * leg_length - 0.0153          # Davis et al. 1991: 0.115 L - 15.3 mm
        at = davis_asis_trochanter(leg_length) if asis_trochanter is None else asis_trochanter
        theta, beta = DAVIS_THETA, DAVIS_BETA
        x = c * np.cos(theta) * np.sin(beta) - (at + radius) * np.cos(beta)
        y = -(c * np.sin(theta) - pelvis_width / 2.0)
        z = -c * np.cos(theta) * np.cos(beta) - (at + radius) * np.sin(beta)
    else:
        raise ValueError(f"unknown hip joint centre method {method!r}")
    return np.array([x, sign * y, z])


def _chord_joint_centre(v, plane: np.ndarray, joint: np.ndarray, marker: np.ndarray,
                        trial: Trial) -> np.ndarray:
    """Plug-in Gait's knee or ankle joint centre (module docstring), metres."""
    letter = v.side[0].upper()
    width_name, rotation_name = (n.format(S=letter) for n in JOINT_CENTRES[v.joint])
    width = processing_number(trial, width_name)
    if width is None:
        return np.array(marker, float)
    diameter = processing_number(trial, "MarkerDiameter")
    radius = diameter / 2000.0 if diameter and diameter > 0 else v.marker_diameter / 2.0
    # Vicon's rotation offsets turn the wand's plane the other way round from
    # mocap.markersets.chord.rotate_about's sense on the left side (measured against the
    # femur origins Vicon stores: 2 mm this way, 5-40 mm the other).
    sign = -1.0 if letter == "L" else 1.0
    return chord(plane, joint, marker, width / 2000.0 + radius,
                 sign * (processing_number(trial, rotation_name) or 0.0))


def _hip_joint_centre(v, rasi, lasi, sacr, ankle, trial: Trial,
                      keep: list[np.ndarray] | None = None) -> np.ndarray:
    rotation, origin = pelvis_frame(rasi, lasi, sacr)
    whole_origin = origin
    if keep is not None:       # whole-trial values from recorded samples only
        rasi, lasi, sacr = (np.where(k[:, None], p, np.nan)
                            for p, k in zip((rasi, lasi, sacr), keep))
        if ankle is not None and len(keep) > 3:
            ankle = np.where(keep[3][:, None], ankle, np.nan)
        origin = 0.5 * (rasi + lasi)
    width = _median_distance(lasi, rasi)
    depth = _median_distance(origin, sacr)
    origin = whole_origin
    leg_length = v.leg_length
    if v.method == "davis" and leg_length is None:
        asis = lasi if v.side == "left" else rasi
        d = np.linalg.norm(asis - ankle, axis=-1)
        d = d[np.isfinite(d)]
        leg_length = float(np.percentile(d, 95)) if d.size else float("nan")
    if not np.isfinite(width) or (v.method == "harrington" and not np.isfinite(depth)):
        return np.full_like(rasi, np.nan)
    if v.method == "davis" and not np.isfinite(leg_length):
        return np.full_like(rasi, np.nan)
    local = hip_joint_centre_offset(v.method, v.side, width, depth, leg_length,
                                    v.marker_diameter)
    return origin + np.einsum("fij,j->fi", rotation, local)

