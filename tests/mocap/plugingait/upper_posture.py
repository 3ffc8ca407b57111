"""An exact synthetic upper-body posture for the known-answer tests of test_upper.py.

The markers are placed by inverting Plug-in Gait's constructions
(:mod:`mocap.plugingait.upper`): from chosen joint centres and segment frames, each
marker goes where the model's chord or offset puts the centre back, so the centres
and frames the model recovers from the markers are known exactly.

Lab and pelvis: x forward (the progression), y left, z up.  The neutral posture
stands upright, head level, upper arms hanging with the forearms pointing forward
(elbows flexed 90°), hands in line with the forearms.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.plugingait.upper import UpperSubject

#: Upper-body measurements of the posture, metres.
SUBJECT = UpperSubject(shoulder_offset={"l": 0.040, "r": 0.045},
                       elbow_width={"l": 0.070, "r": 0.072},
                       wrist_width={"l": 0.050, "r": 0.052},
                       hand_thickness={"l": 0.025, "r": 0.030})
RADIUS = 0.007
#: The trunk's reference point (lab, metres), about which the trunk turns.
TRUNK = np.array([0.0, 0.0, 1.35])
#: Vicon's thorax upright: x anterior, y right, z down.
THORAX_UPRIGHT = np.diag([1.0, -1.0, -1.0])


def rot(axis: str, degrees: float) -> np.ndarray:
    """Rotation matrix (3, 3) about a lab / frame axis."""
    return Rotation.from_euler(axis, degrees, degrees=True).as_matrix()


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _perpendicular_in_plane(axis: np.ndarray, towards: np.ndarray) -> np.ndarray:
    """Unit vector orthogonal to ``axis`` in the plane of ``axis`` and ``towards``."""
    axis = _unit(axis)
    return _unit(towards - (towards @ axis) * axis)


def _elbow_marker(sjc: np.ndarray, ejc: np.ndarray, wri: np.ndarray, humerus: np.ndarray,
                  side: str, delta: float) -> np.ndarray:
    """ELB at ``delta`` from the elbow centre, orthogonal to the humerus, turned about
    it (from lateral) until the centre lies in the plane of the shoulder centre and the
    normal of the arm plane (SJC, ELB, WRI), as the elbow's chord requires."""
    lateral = -humerus[:, 1] if side == "l" else humerus[:, 1]
    other = humerus[:, 0]

    def marker(beta: float) -> np.ndarray:
        return ejc + delta * (np.cos(beta) * lateral + np.sin(beta) * other)

    def off_plane(beta: float) -> float:
        elb = marker(beta)
        normal = np.cross(sjc - elb, wri - elb)
        return float((ejc - elb) @ _unit(np.cross(sjc - elb, normal)))

    a, b = -0.5, 0.5                     # a root lies within ±0.5 rad of lateral
    for _ in range(80):                  # bisection to rounding
        middle = (a + b) / 2
        if np.sign(off_plane(middle)) == np.sign(off_plane(a)):
            a = middle
        else:
            b = middle
    return marker((a + b) / 2)


def posture(trunk: np.ndarray = np.eye(3), head: np.ndarray = np.eye(3),
            shoulder: dict | None = None, elbow_deg: dict | None = None,
            wrist: dict | None = None) -> tuple[dict, dict]:
    """Markers (name -> (1, 3) metres) and the true centres / frames of a posture.

    Parameters
    ----------
    trunk : (3, 3)
        Rotation of the thorax (and everything on it) about :data:`TRUNK`, lab axes.
    head : (3, 3)
        Rotation of the head relative to the thorax, about the neck, in lab axes
        of the upright posture.
    shoulder : dict side -> (3, 3)
        Rotation of the upper arm in the thorax's upright lab axes, after the
        neutral (hanging) one, about the shoulder centre.
    elbow_deg : dict side -> float
        Elbow flexion, degrees (90 in the neutral posture).
    wrist : dict side -> (3, 3)
        Rotation of the hand in the forearm's own axes (post-multiplied).
    """
    shoulder = shoulder or {}
    elbow_deg = elbow_deg or {}
    wrist = wrist or {}
    markers: dict = {}
    truth: dict = {}

    def place(name: str, local: np.ndarray) -> None:
        markers[name] = (TRUNK + trunk @ local)[None]

    for name, local in (("CLAV", (0.08, 0.0, 0.10)), ("C7", (-0.08, 0.0, 0.10)),
                        ("STRN", (0.10, 0.0, -0.05)), ("T10", (-0.10, 0.0, -0.05))):
        place(name, np.array(local))
    neck = np.array([0.0, 0.0, 0.17])
    for name, local in (("LFHD", (0.09, 0.07, 0.10)), ("RFHD", (0.09, -0.07, 0.10)),
                        ("LBHD", (-0.09, 0.07, 0.10)), ("RBHD", (-0.09, -0.07, 0.10))):
        place(name, neck + head @ np.array(local))
    thorax = trunk @ THORAX_UPRIGHT
    origin = markers["CLAV"][0] - RADIUS * thorax[:, 0]
    truth["thorax"], truth["head"] = thorax, trunk @ head
    for side, sign in (("l", 1.0), ("r", -1.0)):
        S = side.upper()
        # shoulder centre in the thorax's frontal plane through its origin
        sjc = origin + trunk @ np.array([0.0, sign * 0.17, -0.05])
        out = sjc - origin
        up = _perpendicular_in_plane(out, trunk @ np.array([0.0, 0.0, 1.0]))
        markers[f"{S}SHO"] = (sjc + (SUBJECT.shoulder_offset[side] + RADIUS) * up)[None]
        humerus = trunk @ shoulder.get(side, np.eye(3)) @ THORAX_UPRIGHT @ rot("y", 180)
        ejc = sjc - 0.28 * humerus[:, 2]
        flexion = elbow_deg.get(side, 90.0)
        radius_frame = humerus @ rot("y", flexion)
        wjc = ejc - 0.25 * radius_frame[:, 2]
        hand = radius_frame @ wrist.get(side, np.eye(3))
        bar = -hand[:, 1] if side == "l" else hand[:, 1]      # WRA - WRB direction
        delta = SUBJECT.wrist_width[side] / 2 + RADIUS
        wri = wjc.copy()
        for _ in range(60):       # WJC = WRI -/+ delta * unit((EJC - WRI) x bar)
            offset = _unit(np.cross(_unit(ejc - wri), bar))
            wri = wjc + (delta if side == "l" else -delta) * offset
        markers[f"{S}WRA"] = (wri + 0.03 * bar)[None]
        markers[f"{S}WRB"] = (wri - 0.03 * bar)[None]
        markers[f"{S}ELB"] = _elbow_marker(sjc, ejc, wri, humerus, side,
                                           SUBJECT.elbow_width[side] / 2 + RADIUS)[None]
        centre = wjc - 0.07 * hand[:, 2]
        towards = _perpendicular_in_plane(hand[:, 2], wri - wjc)
        markers[f"{S}FIN"] = (centre + (SUBJECT.hand_thickness[side] / 2 + RADIUS)
                              * towards)[None]
        truth.update({f"{side}_shoulder": sjc, f"{side}_elbow": ejc, f"{side}_wrist": wjc,
                      f"{side}_hand": centre, f"{side}_humerus": humerus,
                      f"{side}_radius": radius_frame, f"{side}_hand_frame": hand})
    return markers, truth
