"""The physical-plausibility check of a motion on the humanoid (``docs/check.md``, ``docs/formats/check-json.md``).

For a motion on the floor y = 0 (world Y up):

1. q, v, a on the configuration manifold (:func:`dynamics.humanoid.kinematics.motion_kinematics`),
   optionally low-passed.
2. RNEA for all frames at once (:func:`dynamics.humanoid.inverse.rnea_batch`): ``tau[:6]`` is
   the wrench a fictitious actuator at the root would need.
3. Contact points calibrated onto the soles seen in the stance phases, with the floor level
   under each foot (:func:`dynamics.humanoid.contact.calibrate_contacts`).
4. Ground reaction forces at the foot points in contact, each inside a friction pyramid
   (:func:`dynamics.humanoid.contact_forces.solve_contact_forces`), fitting the root wrench moved to
   the centre of mass in the norm ``‖ΔF‖² + ‖ΔM / L‖²`` (L = :data:`TORQUE_LENGTH`): what
   they cannot supply is the residual — the non-physical "hand of God". Where each foot
   bears its load is then refined by a heel-to-toe roll-over prior
   (:func:`dynamics.humanoid.contact.rollover_centres`): the same total force, kept
   (:data:`HELD_FORCE_WEIGHT`), and its moment shared between the dynamics' torque and
   the prior's centre of pressure under each foot in contact (weighted 1 : 1 /
   :data:`ROLLOVER_LENGTH`). A single stance's centre of pressure from the dynamics alone
   is off by the errors of the whole body's angular momentum, and in double support the
   wrench leaves it free (heel of the leading foot or its forefoot); the prior pulls it
   towards where feet bear load in walking. The force is kept because the knee's and
   hip's moments are far more sensitive to a horizontal force error (lever ~0.5-0.9 m)
   than to a centre-of-pressure one; the residual, hence the verdict, is that of the
   dynamics alone. On the 30 clean stances of the real walks with plates, against
   bottom-up inverse dynamics: median r knee 0.86 -> 0.91, ankle 0.95 -> 0.96,
   hip 0.961 -> 0.964, RMS knee 0.12 -> 0.11 N·m/kg (README). The prior's weight is one
   constant for all motions, the value of a sweep (0.5-5) where no joint worsened (knee
   0.90-0.91 over 1-2).
5. Joint torques with those contact forces taken off, foot skating, penetration, floating
   (no foot point in contact, flight phases whose captured centre of mass falls freely
   excepted; a flight's residual force is its captured parabola's), and a verdict with
   reasons against each trial's own limits (:mod:`dynamics.humanoid.limits`: what its
   noise, filter, inertial parameters and the contact model can leave) and
   :class:`Thresholds` for the geometry.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mocap.body.retarget import reduce_to_segments
from mocap.errors import MocapError
from mocap.clean.filtering import butterworth_lowpass
from mocap.rotations.quaternions import quaternions_to_matrices
from mocap.skeleton import Motion
from mocap.trial import runs as runs_of_true

from dynamics.humanoid.contact import (ballistic_runs, calibrate_contacts, estimate_floor,
                                       flight_accelerations, foot_skate, points_in_world,
                                       rollover_centres)
from dynamics.humanoid.contact_forces import (contact_columns, preference_weights,
                                              solve_contact_forces)
from dynamics.humanoid.inverse import contact_joint_torques, rnea_batch
from dynamics.humanoid.kinematics import _window, centre_of_mass, motion_kinematics
from dynamics.humanoid.limits import (COVERAGE, LUMPED_SPREAD, MASS_SPREAD, expected_residual,
                                      filter_change, inertial_spread, measured_noise,
                                      noise_gain)
from mocap.body.anthropometry import leg_length
from dynamics.humanoid.model import GRAVITY, Humanoid, build_humanoid
from dynamics.humanoid.soles import rig_soles

#: Low-pass (Hz) of the motion before the inverse dynamics when none is given: Winter's
#: customary cutoff for walking kinematics, the one the real Plug-in Gait walks and their
#: force plates were compared at. Motions sampled at twice this or less are not filtered.
DEFAULT_LOWPASS = 6.0
#: A residual force limit (RMS, % body weight) at or above which the residual is not
#: judged: a limit of the body weight cannot tell a body held up from one on its feet
#: (at 30 Hz with the 6 Hz low-pass, a run's impacts). The verdict is then "not judged",
#: never "plausible" for want of a residual the check could see.
UNJUDGED_PCT_BW = 100.0
#: Fewest frames of a flight (no foot point in contact) whose
#: captured parabola can tell a free fall from a body held up: a parabola has three
#: parameters, five frames leave two to test it (:func:`ballistic_runs`). A shorter
#: flight (a run's at 30 Hz: 1-4 frames) is not judged, and the verdict says so.
SHORTEST_JUDGED_FLIGHT = 5
#: Floor tolerance (m) for penetration and floating, as in the motion-synthesis literature.
FLOOR_TOLERANCE = 0.005
#: Length (m) between newtons and newton-metres in the contact solve's misfit
#: ``‖ΔF‖² + ‖ΔM / L‖²`` (torque about the centre of mass): a torque error counts as the
#: horizontal floor force that makes it at about the centre of mass's height.
TORQUE_LENGTH = 1.0
#: How much more the roll-over solve (step 4) weighs the force it keeps than the torque.
HELD_FORCE_WEIGHT = 100.0
#: The roll-over prior's length (step 4), relative to :data:`TORQUE_LENGTH`: a centre of
#: pressure off the prior by Δ under a load F costs as a torque misfit of F·Δ / 2.
ROLLOVER_LENGTH = 2.0


@dataclass
class Thresholds:
    """Limits above which the check calls a motion implausible.

    The residual's limits are not fixed numbers: left at None, each trial gets its own,
    :data:`dynamics.humanoid.limits.COVERAGE` times what its measurement noise (through
    the filter and the double derivative at its rate), its segments' inertial parameters
    (within their published spread) and the contact model's resolution can leave
    (:mod:`dynamics.humanoid.limits`); a number given here replaces the trial's own.

    Attributes
    ----------
    residual_rms_pct_bw : float, optional
        RMS residual force, % body weight. A static 20° lean gives ~7.
    residual_peak_pct_bw : float, optional
        Peak residual force, % body weight.
    residual_torque_rms_nm : float, optional
        RMS residual torque about the centre of mass, N·m.
    penetration_mm : float
        Deepest point below the floor beyond the 5 mm tolerance: the heel pad and a
        shoe's sole compress by up to about 1 cm each under the body's weight, and a
        joint centre or marker sits a few millimetres off.
    skate_speed : float, m/s
        Mean horizontal speed of foot points in contact (real walks 0.07–0.12).
    floating_fraction : float
        Fraction of frames off the floor while needing support (residual above
        ``floating_residual_pct_bw``) that counts as floating (real walks: at most 0.005).
    """

    residual_rms_pct_bw: float | None = None
    residual_peak_pct_bw: float | None = None
    residual_torque_rms_nm: float | None = None
    penetration_mm: float = 25.0
    skate_speed: float = 0.2
    floating_fraction: float = 0.1
    floating_residual_pct_bw: float = 10.0


@dataclass
class CheckReport:
    """Result of :func:`check_motion` (per-frame series and summary figures).

    Per-frame arrays have ``frames`` rows; forces in N, torques in N·m, lengths in mm.
    """

    mass_kg: float
    frames: int
    rate: float
    times: np.ndarray
    residual_force: np.ndarray           # (F, 3) world
    residual_torque: np.ndarray          # (F, 3) world, about the centre of mass
    contact_forces: np.ndarray           # (F, P, 3) world
    contact_active: np.ndarray           # (F, P) bool
    contact_names: list[str]
    joint_torques: np.ndarray            # (F, J-1, 3) in each joint's frame
    joint_names: list[str]               # the segment each joint moves (l_thigh = left hip)
    lowest_point_mm: np.ndarray          # (F,) height of the lowest body point
    foot_skate_mm: float
    skating_ratio: float
    penetration_mm: float
    floating_mm: float
    floating_frames: int
    verdict: str
    reasons: list[str]
    not_judged: list[str] = field(default_factory=list)
    thresholds: Thresholds = field(default_factory=Thresholds)
    lumped_segments: list[str] = field(default_factory=list)
    floor_m: float = 0.0
    contact_positions: np.ndarray | None = None     # (F, P, 3) world, m (smoothed motion)
    contact_segments: list[int] = field(default_factory=list)   # segment of each point
    centre_of_mass: np.ndarray | None = None        # (F, 3) world, m
    segment_poses: tuple | None = None              # (world_r, world_p) of the smoothed motion
    contact_torques: np.ndarray | None = None       # (F, J-1, 3) the contacts' share, N·m
    calibration: object = None                      # humanoid_contact.ContactCalibration
    lowpass_hz: float | None = None                 # the low-pass the motion was given
    limits: dict = field(default_factory=dict)      # each judged figure: value, limit, margin

    @property
    def weight(self) -> float:
        return self.mass_kg * GRAVITY

    @property
    def penetration_series_mm(self) -> np.ndarray:
        """Depth below the floor beyond the floor tolerance per frame, mm, shape (frames,):
        0 where the lowest body point is above ``-FLOOR_TOLERANCE``; its maximum is
        ``penetration_mm``, the figure the verdict judges."""
        return np.clip(-self.lowest_point_mm - 1000.0 * FLOOR_TOLERANCE, 0.0, None)

    def to_dataframe(self):
        """The per-frame series as a pandas DataFrame: index ``time`` (s), the residual
        force (N) and torque (N·m) on the root in world axes (Y up), the total contact force
        (N), the lowest body point's height (mm) and each joint's torque (N·m, in the
        joint's frame) as ``<segment>_torque_x`` …. Needs pandas (the ``tables`` extra)."""
        from mocap.errors import import_pandas

        pandas = import_pandas()
        columns = {}
        for name, values in (("residual_force", self.residual_force),
                             ("residual_torque", self.residual_torque),
                             ("contact_force", self.contact_forces.sum(axis=1))):
            columns.update({f"{name}_{axis}": values[:, i] for i, axis in enumerate("xyz")})
        columns["lowest_point_mm"] = self.lowest_point_mm
        for j, joint in enumerate(self.joint_names):
            columns.update({f"{joint}_torque_{axis}": self.joint_torques[:, j, i]
                            for i, axis in enumerate("xyz")})
        return pandas.DataFrame(columns, index=pandas.Index(self.times, name="time"))

    def summary(self) -> dict:
        """The ``docs/formats/check-json.md`` JSON object (plain Python types)."""
        force = np.linalg.norm(self.residual_force, axis=1)
        torque = np.linalg.norm(self.residual_torque, axis=1)
        peaks = np.linalg.norm(self.joint_torques, axis=2).max(axis=0) if self.frames else []
        return {
            "mass_kg": round(self.mass_kg, 3),
            "frames": self.frames,
            "rate_hz": self.rate,
            "residual_force_rms_N": _r(_rms(force)),
            "residual_force_peak_N": _r(force.max()),
            "residual_force_rms_pct_bw": _r(100.0 * _rms(force) / self.weight),
            "residual_force_peak_pct_bw": _r(100.0 * force.max() / self.weight),
            "residual_torque_rms_Nm": _r(_rms(torque)),
            "residual_torque_peak_Nm": _r(torque.max()),
            "foot_skate_mm": _r(self.foot_skate_mm),
            "skating_ratio": _r(self.skating_ratio),
            "penetration_mm": _r(self.penetration_mm),
            "floating_mm": _r(self.floating_mm),
            "floating_frames": self.floating_frames,
            "peak_joint_torque_Nm": {n: _r(p) for n, p in zip(self.joint_names, peaks)},
            "verdict": self.verdict,
            "reasons": list(self.reasons),
            "not_judged": list(self.not_judged),
            "lumped_segments": list(self.lumped_segments),
            "floor_m": _r(self.floor_m),
            "limits": self.limits,
        }


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x.size else 0.0


def _r(x: float) -> float:
    return round(float(x), 3)


def check_motion(motion: Motion, body_mass: float = 75.0, sex: str = "male",
                 mu: float = 0.8, contact_height: float = 0.03,
                 contact_speed: float = 1.0, smoothing: float = 0.1,
                 thresholds: Thresholds | None = None, threads: int = 1,
                 humanoid: Humanoid | None = None, floor: float | str = 0.0,
                 lowpass: float | None = DEFAULT_LOWPASS, torque_length: float = TORQUE_LENGTH,
                 prefer_com: bool = True, rollover: bool = True) -> CheckReport:
    """Check a motion for physical plausibility (``docs/check.md``).

    Parameters
    ----------
    motion : Motion
        Any skeleton with recognisable joint names (reduced to the 15-segment body with
        ``reduce_to_segments``; pelvis and legs are enough, the rest is then lumped into the
        pelvis); floor y = 0, Y up, metres.
    body_mass : float, kg
    sex : {"male", "female"}
    mu : float
        Friction coefficient of the floor.
    contact_height : float, m
        A foot point lower than this, and slower than ``contact_speed`` (m/s), may push on
        the floor.
    smoothing : float, s
        Savitzky–Golay window for velocities and accelerations.
    thresholds : Thresholds, optional
    threads : int
        Threads of ``pin.rneaInParallel``.
    humanoid : Humanoid, optional
        A model built before (its skeleton must be the motion's reduced skeleton).
    floor : float or "auto"
        Height of the floor in the motion (m, Y up); "auto" takes the median height of the
        lowest foot point over the frames where a foot stands still (for files whose floor
        is not at y = 0). The check then works with the floor at 0.
    lowpass : float, Hz, optional
        Low-pass the motion before differentiating (:func:`motion_kinematics`), and the
        estimated contact forces (hence the joint torques) after the solve; default
        :data:`DEFAULT_LOWPASS` (as ``mocap check``), which a motion sampled at twice
        that or less does not get; None or 0: off. ``CheckReport.lowpass_hz`` says what was used.
    rollover : bool
        Share the torque with the heel-to-toe roll-over prior (module docstring, step 4);
        False keeps the forces the dynamics alone choose.

    Returns
    -------
    CheckReport
    """
    thresholds = thresholds or Thresholds()
    body = reduce_to_segments(motion, partial=True)
    if body.frames < 3:
        raise MocapError(f"the dynamics check needs at least 3 frames, the motion has "
                         f"{body.frames}")
    if humanoid is None:
        humanoid = build_humanoid(body.skeleton, body_mass, sex)
    # A rig's feet end at joints: their soles lie below, under the stance normal, as far
    # as the trial shows the feet standing above the floor (rig_soles).
    floor_height = estimate_floor(body, humanoid, points=rig_soles(body, humanoid)[0]) \
        if floor == "auto" else float(floor)
    if floor_height:
        body = Motion(body.skeleton, body.root_translation - [0.0, floor_height, 0.0],
                      body.rotations, body.rate, dict(body.metadata))
    points, sole_up, sole_lowest = rig_soles(body, humanoid)
    frames, rate = body.frames, body.rate
    # The same band for every motion, whatever its frame rate: differentiated twice, an
    # unfiltered 30 Hz capture keeps everything up to 15 Hz, a 100 Hz one ~11 Hz.
    if lowpass == DEFAULT_LOWPASS and rate <= 2.0 * DEFAULT_LOWPASS:
        lowpass = None
    lowpass = float(lowpass) if lowpass else None
    kin = motion_kinematics(body, smoothing, lowpass)
    tau = rnea_batch(humanoid, kin.q, kin.v, kin.a, threads)

    # Root wrench in world axes, moved to the centre of mass.
    root_r = quaternions_to_matrices(kin.q[:, 3:7])
    force_w = np.einsum("fij,fj->fi", root_r, tau[:, :3])
    torque_w = np.einsum("fij,fj->fi", root_r, tau[:, 3:6])
    smoothed = Motion(body.skeleton, kin.root - body.skeleton.offsets[0], kin.rotations, rate)
    world_r, world_p = smoothed.forward_kinematics()
    com = centre_of_mass(humanoid, world_r, world_p)
    wrench = np.concatenate([force_w, torque_w - np.cross(com - kin.root, force_w)], axis=1)

    segments = list(humanoid.contact_segments)
    names = body.skeleton.names
    prior = {names.index(name): shift
             for name, shift in body.metadata.get("sole_calibration_m", {}).items()
             if name in names}
    calibration = calibrate_contacts(points, segments, world_r, world_p, rate,
                                     prior_shift=prior, sole_up=sole_up,
                                     sole_lowest=sole_lowest)
    contact_world = points_in_world(calibration.points, segments, world_r, world_p)
    heights = contact_world[:, :, 1] - calibration.floors
    speed = np.linalg.norm(np.gradient(contact_world, 1.0 / rate, axis=0), axis=2)
    active = (heights < contact_height) & (speed < contact_speed)
    levers = contact_world - com[:, None, :]
    weights = preference_weights(heights, speed)
    preferred = _sagittal_towards(com, contact_world, world_r[:, 0]) if prefer_com else None
    columns = contact_columns(levers, active, mu, weights=weights, preferred=preferred)
    forces, residual = solve_contact_forces(
        wrench, levers, active, mu, torque_length=torque_length, weights=weights,
        preferred=preferred, columns=columns)
    if rollover:
        # The same total force, its moment shared with the roll-over prior (module
        # docstring, step 4): only where each foot bears it changes, and the residual
        # (hence the verdict) stays that of the dynamics alone.
        centres = rollover_centres(calibration, humanoid.contact_names, segments, active,
                                   world_r, world_p)
        held = np.concatenate([wrench[:, :3] - residual[:, :3], wrench[:, 3:]], axis=1)
        forces, _ = solve_contact_forces(
            held, levers, active, mu, torque_length=torque_length * HELD_FORCE_WEIGHT,
            weights=weights, preferred=preferred, centres=centres - com[:, None, :],
            groups=np.asarray(segments),
            centre_length=ROLLOVER_LENGTH * torque_length * HELD_FORCE_WEIGHT, columns=columns)
    residual_torque = residual[:, 3:]                      # about the centre of mass
    if lowpass:
        # The contact forces band-limited like the motion they come from: the on/off
        # switching of contact points would otherwise put steps into them (and into the
        # joint torques) that the filtered motion cannot know of. The residual stays the
        # misfit of the unfiltered solve.
        forces = butterworth_lowpass(forces, lowpass, rate, ends="fitted")

    contact_torques = contact_joint_torques(humanoid, world_r, world_p, contact_world, forces)
    joint_torques = tau[:, 6:].reshape(frames, -1, 3) - contact_torques

    # Geometry of the raw (unsmoothed) motion: floor contact, skating.
    raw_r, raw_p = body.forward_kinematics()
    raw_contacts = points_in_world(calibration.points, segments, raw_r, raw_p)
    index, ends = body.end_site_positions((raw_r, raw_p))
    feet = set(segments)
    others = np.concatenate([raw_p[:, [i for i in range(raw_p.shape[1]) if i not in feet]],
                             ends[:, [k for k, i in enumerate(index) if i not in feet]]],
                            axis=1)
    # The toe tip is left out of the floor test: real toes bend at push-off, where a rigid
    # foot's tip would dip below the floor by toe length × sin(heel-rise angle).
    solid = [k for k, name in enumerate(humanoid.contact_names) if not name.endswith(".toe")]
    lowest = np.minimum((raw_contacts[:, solid, 1] - calibration.floors[:, solid]).min(axis=1),
                        others[:, :, 1].min(axis=1) if others.shape[1] else np.inf)
    # Skating on the smoothed motion: marker noise, differentiated, would read as sliding.
    skate_mm, skating_ratio = foot_skate(contact_world - np.stack(
        [np.zeros_like(calibration.floors), calibration.floors,
         np.zeros_like(calibration.floors)], axis=2), contact_height, contact_speed, rate,
        segments, FLOOR_TOLERANCE)
    below = np.clip(-lowest - FLOOR_TOLERANCE, 0.0, None)
    penetration_mm = 1000.0 * float(below.max()) if frames else 0.0
    # Off the floor: the toe tip counts here — a body on its toes stands on the floor.
    resting = np.minimum(lowest, (raw_contacts[..., 1] - calibration.floors).min(axis=1))
    above = resting > FLOOR_TOLERANCE
    residual_pct = 100.0 * np.linalg.norm(residual[:, :3], axis=1) / humanoid.weight
    # Free fall judged on the captured (unfiltered) centre of mass: a low-pass spreads the
    # landing's deceleration over the flight before it (at 6 Hz, a 0.15 s running flight
    # falls at well under g in the filtered motion though the capture falls at g).
    airborne = ~active.any(axis=1)
    raw_com = centre_of_mass(humanoid, raw_r, raw_p)
    ballistic = ballistic_runs(raw_com, airborne, rate, shortest=SHORTEST_JUDGED_FLIGHT)
    # A judged flight that does not fall freely (a body held in the air, whether or not
    # it hangs above the floor: held at take-off height, its toes stay at the floor).
    held_flights = [(int(a), int(n)) for a, n in zip(*runs_of_true(airborne & ~ballistic))]
    # Flights (no foot point in contact) too short for their parabola to tell a free
    # fall from a body held up: counted as ballistic, so not judged.
    short = [int(n) for n in runs_of_true(airborne)[1] if n < SHORTEST_JUDGED_FLIGHT]
    if lowpass:
        # In flight nothing but gravity may move the body, and the capture shows whether
        # it does: the residual force of a flight is that of its captured parabola, not
        # the filter's spread of the take-off and landing into it.
        aloft = above & ~(heights < contact_height).any(axis=1)
        flight = flight_accelerations(raw_com, aloft, rate, shortest=3)
        known = np.isfinite(flight[:, 0])
        residual[known, :3] = humanoid.mass * (flight[known] - [0.0, -GRAVITY, 0.0])
        residual_pct = 100.0 * np.linalg.norm(residual[:, :3], axis=1) / humanoid.weight
    # Floating: off the floor with no contact point in reach, needing support that no
    # free fall explains (a frame whose feet are in contact but cannot supply the wrench
    # counts in the residual).
    unsupported = above & airborne & (residual_pct > thresholds.floating_residual_pct_bw) \
        & ~ballistic
    # Floating: how high the unsupported frames hang (a jump's free flight is not
    # floating, whatever its height).
    floating_mm = 1000.0 * float(resting[unsupported].mean()) if unsupported.any() else 0.0

    limits = trial_limits(humanoid, world_r, world_p, raw_p, com, raw_com, rate, lowpass,
                          smoothing, residual_pct, np.linalg.norm(residual_torque, axis=1),
                          thresholds)
    reasons = _reasons(limits, residual_pct, penetration_mm, skate_mm * rate / 1000.0,
                       unsupported, floating_mm, thresholds)
    if held_flights:
        fall = flight_accelerations(raw_com, airborne, rate, SHORTEST_JUDGED_FLIGHT)[
            [a for a, _ in held_flights], 1]
        reasons.append(f"{len(held_flights)} flight{'s' if len(held_flights) > 1 else ''} "
                       f"of {SHORTEST_JUDGED_FLIGHT} frames or more not in free fall: the "
                       f"centre of mass's vertical acceleration up to {fall.max():+.1f} m/s² "
                       f"(free fall {-GRAVITY:.2f})")
    not_judged = _not_judged(limits, short, unsupported, thresholds, rate)
    names = body.skeleton.names
    return CheckReport(
        mass_kg=float(humanoid.mass), frames=frames, rate=rate, times=body.times,
        residual_force=residual[:, :3], residual_torque=residual_torque,
        contact_forces=forces, contact_active=active, contact_names=humanoid.contact_names,
        joint_torques=joint_torques, joint_names=names[1:],
        lowest_point_mm=1000.0 * lowest, foot_skate_mm=skate_mm, skating_ratio=skating_ratio,
        penetration_mm=penetration_mm, floating_mm=floating_mm,
        floating_frames=int(unsupported.sum()),
        verdict="implausible" if reasons else "not judged" if not_judged else "plausible",
        reasons=reasons, not_judged=not_judged,
        thresholds=thresholds, lumped_segments=[name for name, _, _ in humanoid.lumped],
        floor_m=floor_height, contact_positions=contact_world, contact_segments=segments,
        centre_of_mass=com, segment_poses=(world_r, world_p),
        contact_torques=contact_torques, calibration=calibration, lowpass_hz=lowpass,
        limits=limits)


def _sagittal_towards(com: np.ndarray, points: np.ndarray, pelvis: np.ndarray) -> np.ndarray:
    """Directions (frames, points, 3) from contact points towards the centre of mass, in
    the pelvis's sagittal plane (its left axis, X, taken out): in walking each foot's
    reaction points near the centre of mass fore and aft (it carries the braking and
    propulsion), while side to side a standing foot pushes straight up."""
    towards = com[:, None, :] - points
    left = pelvis[:, :, 0]                                              # (F, 3)
    left = left - left[:, 1:2] * np.array([0.0, 1.0, 0.0])             # horizontal
    left /= np.maximum(np.linalg.norm(left, axis=1, keepdims=True), 1e-12)
    return towards - np.einsum("fpk,fk->fp", towards, left)[..., None] * left[:, None, :]


def _reasons(limits: dict, residual_pct: np.ndarray, penetration_mm: float,
             skate_speed: float, unsupported: np.ndarray, floating_mm: float,
             thresholds: Thresholds) -> list[str]:
    reasons: list[str] = []
    unjudged = limits["residual_force_rms_pct_bw"]["limit"] >= UNJUDGED_PCT_BW
    # The peak is reported with its limit but not judged: one frame's residual rests on
    # one frame's contact switching and, at a trial's edge, on what the filter knows of
    # the motion beyond it; the RMS figures judge the trial.
    for key, text, unit in () if unjudged else (
            ("residual_force_rms_pct_bw", "residual force RMS", "% body weight"),
            ("residual_torque_rms_Nm", "residual torque RMS", "N·m")):
        judged = limits[key]
        if judged["value"] > judged["limit"]:
            digits = 0 if unit == "N·m" else 1
            short = "N·m" if unit == "N·m" else "%"
            reasons.append(f"{text} {judged['value']:.{digits}f} {unit} (limit "
                           f"{judged['limit']:.{digits}f} {short})")
    if penetration_mm > thresholds.penetration_mm:
        reasons.append(f"penetrates the floor by {penetration_mm:.0f} mm")
    if skate_speed > thresholds.skate_speed:
        reasons.append(f"feet skate: {skate_speed:.2f} m/s while in contact "
                       f"(limit {thresholds.skate_speed:g} m/s)")
    if unsupported.size and unsupported.mean() > thresholds.floating_fraction:
        reasons.append(f"floating: {floating_mm:.0f} mm above the floor without support in "
                       f"{100 * unsupported.mean():.0f} % of frames")
    return reasons


def _not_judged(limits: dict, short_flights: list[int], unsupported: np.ndarray,
                thresholds: Thresholds, rate: float) -> list[str]:
    """What the check could not judge in this trial (the verdict is then "not judged"
    unless a judged figure failed): a residual whose limit reaches the body weight, and
    flights shorter than :data:`SHORTEST_JUDGED_FLIGHT` frames when they could decide
    the floating test (held up, with the unsupported frames they would exceed
    ``thresholds.floating_fraction`` of the trial, which those frames alone do not)."""
    out = []
    frames = max(unsupported.size, 1)
    could_float = unsupported.sum() / frames <= thresholds.floating_fraction \
        < (unsupported.sum() + sum(short_flights)) / frames
    force = limits["residual_force_rms_pct_bw"]
    if force["limit"] >= UNJUDGED_PCT_BW:
        filtered = limits["expected"]["force_N"]["filter"]
        out.append(f"residual: its limit is {force['limit']:.0f} % body weight at {rate:g} Hz "
                   f"(the low-pass takes {100 * filtered / limits['weight_N']:.0f} % BW of the "
                   f"motion's own acceleration out): it cannot tell a body on its feet from "
                   f"one held up")
    if could_float:
        low, high = min(short_flights), max(short_flights)
        out.append(f"{len(short_flights)} flight{'s' if len(short_flights) > 1 else ''} of "
                   f"{low if low == high else f'{low}-{high}'} frame{'s' if high > 1 else ''}"
                   f" at {rate:g} Hz: shorter "
                   f"than {SHORTEST_JUDGED_FLIGHT} frames ({SHORTEST_JUDGED_FLIGHT / rate:.2f} s), "
                   f"too short to tell a free fall from a body held up "
                   f"({100 * sum(short_flights) / frames:.0f} % of the frames)")
    return out


def trial_limits(humanoid: Humanoid, world_r: np.ndarray, world_p: np.ndarray,
                 raw_p: np.ndarray, com: np.ndarray, raw_com: np.ndarray, rate: float,
                 lowpass: float | None,
                 smoothing: float, residual_pct: np.ndarray, residual_torque: np.ndarray,
                 thresholds: Thresholds) -> dict:
    """The residual's limits of this trial (:mod:`dynamics.humanoid.limits`) and how each
    judged figure stands against its own: ``{figure: {value, limit, margin, ratio,
    source}}`` plus ``noise_mm`` (the position noise measured on the trial), the parts
    of the expected residual and ``coverage``.

    ``world_r``, ``world_p`` are the smoothed segment poses, ``raw_p`` the captured
    segment origins (frames, segments, 3), ``com`` the smoothed centre of mass and
    ``raw_com`` the captured one (frames, 3); ``residual_pct`` (% BW) and ``residual_torque`` (N·m) the per-frame norms.
    """
    frames = com.shape[0]
    parts = [(i, s, MASS_SPREAD) for i, s in enumerate(humanoid.inertias)]
    parts += [(host, s, LUMPED_SPREAD) for _, host, s in humanoid.lumped]
    owners = [i for i, _, _ in parts]
    masses = np.array([s.mass for _, s, _ in parts])
    spreads = np.array([spread for _, _, spread in parts])
    centres = world_p[:, owners] + np.einsum("fsij,sj->fsi", world_r[:, owners],
                                             np.stack([s.com for _, s, _ in parts]))
    dt = 1.0 / rate
    accelerations = np.gradient(np.gradient(centres, dt, axis=0), dt, axis=0)
    com_acceleration = np.einsum("s,fsi->fi", masses, accelerations) / masses.sum()
    inertial_force, inertial_torque = inertial_spread(
        masses, spreads, centres, accelerations, com, com_acceleration,
        np.array([0.0, -GRAVITY, 0.0]))
    feet = sorted(set(humanoid.contact_segments))
    sigma = measured_noise(raw_p[:, feet], rate)
    window, order = _window(frames, rate, smoothing)
    noise_force = humanoid.mass * sigma * noise_gain(rate, lowpass, window, order) \
        * np.sqrt(3.0)
    filtered = humanoid.mass * filter_change(raw_com, rate, lowpass, window, order)
    expected = expected_residual(humanoid.weight, noise_force, leg_length(humanoid.skeleton),
                                 inertial_force, inertial_torque, filtered)
    peak_factor = COVERAGE + np.sqrt(2.0 * np.log(max(frames, 2)))
    force_pct = 100.0 * expected["force_N"] / humanoid.weight
    worst = int(np.argmax(residual_pct)) if frames else 0

    def judged(value, derived, given):
        limit = float(derived if given is None else given)
        return {"value": _r(value), "limit": _r(limit), "margin": _r(limit - value),
                "ratio": _r(value / limit) if limit > 0 else None,
                "source": "trial" if given is None else "given"}

    return {
        "residual_force_rms_pct_bw": judged(_rms(residual_pct), COVERAGE * _rms(force_pct),
                                            thresholds.residual_rms_pct_bw),
        "residual_force_peak_pct_bw": judged(
            float(residual_pct[worst]) if frames else 0.0, peak_factor * _rms(force_pct),
            thresholds.residual_peak_pct_bw),
        "residual_torque_rms_Nm": judged(_rms(residual_torque),
                                         COVERAGE * _rms(expected["torque_Nm"]),
                                         thresholds.residual_torque_rms_nm),
        "noise_mm": _r(1000.0 * sigma),
        "expected": {kind: {k: _r(v) for k, v in part.items()}
                     for kind, part in expected["parts"].items()},
        "coverage": COVERAGE,
        "weight_N": _r(humanoid.weight),
        "rate_hz": rate,
    }
