"""What a physical motion's data can leave as residual: the check's limits from the
measurement noise, the filter and the body's inertial parameters, per trial, instead of
percentiles of the walks the team could see.

The residual is the part of the root wrench that ground reactions inside friction cones
cannot supply. A physical motion, captured and modelled, still leaves some, from sources
each trial's own numbers bound:

* **measurement noise** through the double derivative at the trial's rate and filter
  (:func:`noise_gain`, :func:`measured_noise`): position noise of standard deviation
  ``sigma`` (metres, white at the trial's rate) comes out of the low-pass and the
  Savitzky–Golay second derivative with standard deviation ``sigma * noise_gain``
  (m/s²): the gain is that of the check's own pipeline, computed on an impulse.
  ``sigma`` is measured on the trial where its feet stand still (:func:`measured_noise`:
  the robust spread of the fourth difference, which the motion does not reach at rest).
* **segment inertial parameters** within their published spread (:func:`inertial_spread`):
  a segment whose mass is off by ``δm`` (:data:`MASS_SPREAD` of it, one standard
  deviation) needs ``δm (a_i − a_c)`` more force and ``δm (r_i − r_c) × (a_i − g)`` more
  torque about the centre of mass; segments the marker set does not see (lumped into
  the pelvis) are off by their whole mass (:data:`LUMPED_SPREAD`): their motion is not
  measured.
* **the filter** (:func:`filter_change`): the low-pass takes out of the motion what lies
  above its cut-off (a heel strike's transient, a contact's switching), and the contacts
  are asked for the filtered force; by how much the filter changes the captured centre
  of mass's acceleration, the needed force may differ from what the floor gave.
* **the resolution of the contact model** (:data:`RESOLUTION_PCT_BW`,
  :data:`RESOLUTION_LENGTH`): three points per sole, not a continuous pressure
  distribution, and a floor known to a few millimetres.

Their standard deviations add in quadrature into the expected residual; the limit is
:data:`COVERAGE` times it (the normal quantile that calls one physical trial in a
thousand implausible on these sources alone), for a peak ``COVERAGE + sqrt(2 ln N)``
times its RMS (the largest of N normal samples), reported but not judged. The JSON reports
each limit, what it is made of and the margin (``limits``).
"""
from __future__ import annotations

import numpy as np

from mocap.clean.filtering import butterworth_lowpass, savgol

#: Relative standard deviation of segment masses about the de Leva (1996) means: his
#: source sample (Zatsiorsky-Seluyanov, 100 men) spreads 10-20 % per segment (the trunk
#: least, hands and feet most); 15 % for every segment.
MASS_SPREAD = 0.15
#: The relative spread of a segment with no markers, carried rigidly by the pelvis: its
#: motion is a guess, so its whole inertial effect is unknown.
LUMPED_SPREAD = 1.0
#: Standard normal quantile of one physical trial in a thousand called implausible.
COVERAGE = 3.1
#: The contact model's resolution, % body weight (one standard deviation): three points
#: per sole carry what a continuous sole would, within about one percent of the load.
RESOLUTION_PCT_BW = 1.0
#: ... and in torque, a centre of pressure known to about 1 cm (the sole's points and the
#: floor's height to a few millimetres), metres: weight × this.
RESOLUTION_LENGTH = 0.01


def noise_gain(rate: float, lowpass: float | None, window: int, order: int) -> float:
    """Standard deviation (per unit of white position noise, 1/s²) of the check's second
    derivative: the zero-lag low-pass (when given) then Savitzky–Golay of ``window`` and
    ``order``, on an impulse far from the ends."""
    half = max(4 * int(np.ceil(rate / lowpass)) if lowpass else 0, window) + window
    impulse = np.zeros(2 * half + 1)
    impulse[half] = 1.0
    if lowpass:
        impulse = butterworth_lowpass(impulse, lowpass, rate)
    response = savgol(impulse, window, order, deriv=2, delta=1.0 / rate)
    return float(np.sqrt(np.sum(response[window:-window] ** 2)))


def measured_noise(points: np.ndarray, rate: float, still_speed: float = 0.2) -> float:
    """Position noise (m, one standard deviation) of points (frames, points, 3) measured
    where they stand still: the median absolute fourth difference over every run of 5
    frames in which the point is slower than ``still_speed`` (a planted foot), over
    points and axes, / (0.6745 √70) (white noise: ``Var Δ⁴x = 70 σ²``). At rest the
    motion adds nothing to it, at any rate (a walk's own fourth difference at 30 Hz is
    millimetres, and would read as noise); all frames when no point is ever still; 0 for
    fewer than 5 frames."""
    if points.shape[0] < 5:
        return 0.0
    fourth = np.diff(points, 4, axis=0)                                # (F-4, P, 3)
    speed = np.linalg.norm(np.gradient(points, 1.0 / rate, axis=0), axis=2)   # (F, P)
    slow = np.lib.stride_tricks.sliding_window_view(speed < still_speed, 5, axis=0)
    still = slow.all(axis=-1)                                          # (F-4, P)
    chosen = fourth[still] if still.any() else fourth.reshape(-1, 3)
    chosen = np.abs(chosen[np.isfinite(chosen)])
    return float(np.median(chosen) / (0.6745 * np.sqrt(70.0))) if chosen.size else 0.0


def inertial_spread(masses: np.ndarray, spreads: np.ndarray, centres: np.ndarray,
                    accelerations: np.ndarray, com: np.ndarray, com_acceleration: np.ndarray,
                    gravity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per frame, the standard deviation of the root force (N) and of the torque about the
    centre of mass (N·m) from segment masses off by ``spreads`` (relative) of ``masses``.

    Parameters
    ----------
    masses, spreads : ndarray, shape (segments,)
    centres, accelerations : ndarray, shape (frames, segments, 3)
        World position (m) and acceleration (m/s²) of each segment's centre of mass.
    com, com_acceleration : ndarray, shape (frames, 3)
    gravity : ndarray, shape (3,), m/s²
    """
    sigma = (masses * spreads)[None, :, None]
    force = sigma * (accelerations - com_acceleration[:, None, :])
    torque = sigma * np.cross(centres - com[:, None, :], accelerations - gravity)
    return (np.sqrt(np.sum(force ** 2, axis=(1, 2))),
            np.sqrt(np.sum(torque ** 2, axis=(1, 2))))


def filter_change(com: np.ndarray, rate: float, lowpass: float | None, window: int,
                  order: int) -> np.ndarray:
    """Per frame, by how much (m/s²) the low-pass changes the acceleration of the captured
    centre of mass ``com`` (frames, 3): Savitzky–Golay second derivatives of it with and
    without the check's low-pass; zeros without one."""
    if not lowpass:
        return np.zeros(com.shape[0])
    dt = 1.0 / rate
    raw = savgol(com, window, order, deriv=2, delta=dt)
    smooth = savgol(butterworth_lowpass(com, lowpass, rate, ends="fitted"), window, order,
                    deriv=2, delta=dt)
    return np.linalg.norm(smooth - raw, axis=1)


def expected_residual(weight: float, noise_force: float, leg: float,
                      inertial_force: np.ndarray, inertial_torque: np.ndarray,
                      filter_force: np.ndarray) -> dict:
    """The expected residual (one standard deviation) of a physical trial, per frame and
    RMS: ``force_N`` and ``torque_Nm`` (frames,), and the parts of each RMS. Forces in N,
    torques in N·m; ``leg`` (m) turns a force error into a torque one (a floor force's
    error acting at the hip's height)."""
    resolution_force = RESOLUTION_PCT_BW / 100.0 * weight
    resolution_torque = RESOLUTION_LENGTH * weight
    noise_torque = noise_force * leg
    filter_torque = filter_force * leg
    force = np.sqrt(noise_force ** 2 + inertial_force ** 2 + filter_force ** 2
                    + resolution_force ** 2)
    torque = np.sqrt(noise_torque ** 2 + inertial_torque ** 2 + filter_torque ** 2
                     + resolution_torque ** 2)

    def rms(x):
        return float(np.sqrt(np.mean(np.square(x)))) if np.size(x) else 0.0

    return {"force_N": force, "torque_Nm": torque,
            "parts": {"force_N": {"noise": noise_force, "inertial": rms(inertial_force),
                                  "filter": rms(filter_force), "resolution": resolution_force},
                      "torque_Nm": {"noise": noise_torque, "inertial": rms(inertial_torque),
                                    "filter": rms(filter_torque),
                                    "resolution": resolution_torque}}}
