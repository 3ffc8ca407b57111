"""Measured force plates beside the dynamics check: estimated vs measured ground reaction,
and bottom-up inverse dynamics from the plates.

The plates (:mod:`mocap.io.c3d.forceplates`) are resampled to the marker frames, turned into
the check's Y-up frame (the same turn as the markers) and shifted by the check's floor.

Which foot is on which plate: for every run of loaded frames of a plate (vertical force
above 20 N) the foot whose contact points lie nearest the centre of pressure, horizontally.
A stance is *clean* when only that foot stands on the plate (no point of another foot
that the check puts in contact — low and slow — within 2 cm of the plate's outline), the
foot stands wholly on it (none of its points in contact more than 3 cm outside the outline
during the run and three frames either side), the run
does not touch the trial's first or last frame, and it lasts at least 0.1 s. Comparisons
use clean stances only; the total is compared in the frames where the plates carry the
whole body: at least one plate is loaded and every foot the check puts in contact is on
a clean stance's plate.

Figures (vertical and antero-posterior components): Pearson r and RMS difference in % of
body weight. Antero-posterior is the horizontal direction of the centre of mass's mean
velocity over the stance (over the compared frames for the total). With ``lowpass``
(Hz), the measured forces are filtered with the same zero-lag Butterworth filter as the
markers — and :func:`dynamics.humanoid.check.check_motion` filters its estimated contact
forces alike — so the two sides are compared at the same bandwidth (Kristianslund et al.
2012 on filtering markers and forces alike).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocap.body.retarget import Z_UP_TO_Y_UP
from mocap.errors import MocapError
from mocap.clean.filtering import butterworth_lowpass
from mocap.io.c3d.forceplates import plate_forces
from mocap.trial import runs

#: Vertical force (N) above which a plate is loaded.
LOADED_N = 20.0
#: Shortest stance compared, s.
MIN_STANCE_S = 0.1


@dataclass
class MeasuredPlates:
    """Plate reactions in the check's frame, at the marker rate.

    Attributes
    ----------
    force, cop, free_moment : ndarray, shape (plates, frames, 3)
        N, m (NaN while unloaded), N·m; Y up, floor at 0.
    moment : ndarray, shape (plates, frames, 3)
        N·m, each plate's whole wrench moment about the origin of this frame (the COP's
        moment of the force plus the free moment; defined in every frame, unlike the COP).
        Inverse dynamics moves it to a joint as ``moment − p × force``.
    outlines : ndarray, shape (plates, 4, 3)
        Plate corners in the same frame.
    names : list of str
        ``plate1`` …
    """

    force: np.ndarray
    cop: np.ndarray
    free_moment: np.ndarray
    outlines: np.ndarray
    names: list[str]
    moment: np.ndarray | None = None

    @property
    def vertical(self) -> np.ndarray:
        """Vertical force of each plate, (plates, frames), N."""
        return self.force[..., 1]


def measured_plates(trial, floor: float = 0.0, up: str = "z",
                    lowpass: float | None = None) -> MeasuredPlates:
    """The plates of a C3D trial in the check's frame (see the module docstring).

    Raises
    ------
    MocapError
        No plates, plates that cannot be computed (:func:`mocap.io.c3d.forceplates.force_plates`)
        or without believable corners.
    """
    turn = Z_UP_TO_Y_UP if up == "z" else np.eye(3)
    parts = plate_forces(trial, rate="marker", baseline=True, threshold=LOADED_N)
    if not parts:
        raise MocapError("--forces plates: the trial has no force plates "
                         "(FORCE_PLATFORM:USED is 0 or absent)", trial.path)
    parts = [p for p in parts if not p.plate.problem]
    if not parts:
        raise MocapError("--forces plates: no force plate has believable corners", trial.path)
    if parts[0].samples != trial.frames:
        raise MocapError("--forces plates: the plates' analog samples do not cover the "
                         "marker frames", trial.path)
    shift = np.array([0.0, floor, 0.0])
    force = np.stack([p.force @ turn.T for p in parts])
    free = np.stack([p.free_moment @ turn.T for p in parts])
    cop = np.stack([p.cop @ turn.T for p in parts]) - shift
    outlines = np.stack([p.plate.corners @ turn.T for p in parts]) - shift
    # The moment about the origin (the floor-shifted one): COP × force + free moment where
    # the COP is defined (it carries a plate's COP correction), the plate's own moment
    # elsewhere (an unloaded plate's small offsets), so it is finite in every frame.
    raw = np.stack([p.moment @ turn.T for p in parts]) - np.cross(shift, force)
    defined = np.isfinite(cop).all(axis=2, keepdims=True)
    moment = np.where(defined, np.cross(np.nan_to_num(cop), force) + free, raw)
    if lowpass:
        # Force and moment about a fixed point are linear in the plate's channels, so
        # filtering them is filtering the plate; the COP (a ratio) is left as measured.
        if 0 < lowpass < trial.rate / 2:          # as the check's motion (a 2nd order)
            force, free, moment = (butterworth_lowpass(x, lowpass, trial.rate, axis=1)
                                   for x in (force, free, moment))
    return MeasuredPlates(force, cop, free, outlines,
                          [f"plate{p.plate.index + 1}" for p in parts], moment)


def _inside(points: np.ndarray, outline: np.ndarray, margin: float) -> np.ndarray:
    """Whether horizontal positions (…, 3) lie within a plate's outline grown by margin."""
    low = outline[:, [0, 2]].min(axis=0) - margin
    high = outline[:, [0, 2]].max(axis=0) + margin
    xz = points[..., [0, 2]]
    return ((xz >= low) & (xz <= high)).all(axis=-1)


@dataclass
class Stance:
    """One foot's clean stance on one plate: frames [start, stop)."""

    plate: int
    foot: int               # segment index of the foot
    start: int
    stop: int


def plate_stances(report, plates: MeasuredPlates) -> tuple[list[Stance], np.ndarray]:
    """Clean single-foot stances on the plates and, per frame and plate, the foot
    (segment index) that loads it (-1 when unloaded or unclear)."""
    positions = report.contact_positions
    segments = np.asarray(report.contact_segments)
    feet = sorted(set(segments.tolist()))
    frames = positions.shape[0]
    owner = np.full((len(plates.names), frames), -1)
    stances = []
    minimum = max(int(round(MIN_STANCE_S * report.rate)), 2)
    for k in range(len(plates.names)):
        loaded = plates.vertical[k] > LOADED_N
        for start, length in zip(*runs(loaded)):
            stop = start + length
            cop = plates.cop[k, start:stop]
            distance = []
            for foot in feet:
                centre = positions[start:stop, segments == foot].mean(axis=1)
                gap = np.linalg.norm((centre - cop)[:, [0, 2]], axis=1)
                distance.append(np.nanmedian(gap) if np.isfinite(gap).any() else np.inf)
            foot = feet[int(np.argmin(distance))]
            owner[k, start:stop] = foot
            others = positions[start:stop, segments != foot]
            resting = report.contact_active[start:stop][:, segments != foot]
            intruder = (_inside(others, plates.outlines[k], 0.02) & resting).any()
            # The foot itself wholly on the plate: none of its points in contact outside it
            # during the stance, nor in the frames around it (a foot that stays on the floor
            # after the plate unloads stood across its edge).
            a, b = max(start - 3, 0), min(stop + 3, frames)
            own = positions[a:b, segments == foot]
            touching = report.contact_active[a:b][:, segments == foot]
            astride = (touching & ~_inside(own, plates.outlines[k], 0.03)).any()
            if (not intruder and not astride and start > 0 and stop < frames and stop - start >= minimum
                    and min(distance) < 0.15):
                stances.append(Stance(k, foot, start, stop))
    return stances, owner


def carried_frames(report, stances: list[Stance], lag: bool = True) -> np.ndarray:
    """Frames (bool) where the plates carry the whole body: some foot is on a clean
    stance's plate and every foot the check puts in contact is, nor does any foot touch
    off the plates within :func:`contact_lag` of the frame (the check finds a contact
    from the low-passed motion, which lags a heel strike or a toe-off off the plates by
    about that: the floor then carries some of the weight the plates do not see);
    ``lag=False`` leaves that guard out."""
    segments = np.asarray(report.contact_segments)
    feet = sorted(set(segments.tolist()))
    clean = np.zeros((len(feet), report.frames), bool)
    for stance in stances:
        clean[feet.index(stance.foot), stance.start:stance.stop] = True
    touching = np.stack([report.contact_active[:, segments == f].any(axis=1) for f in feet])
    guard = contact_lag(report.rate, report.lowpass_hz) if lag else 0
    off = (touching & ~clean).any(axis=0).astype(float)
    near = np.convolve(off, np.ones(2 * guard + 1), mode="same") > 0 if guard else off > 0
    return (touching <= clean).all(axis=0) & clean.any(axis=0) & ~near


def contact_lag(rate: float, lowpass: float | None) -> int:
    """Frames by which the check's contacts may lag the floor's: a quarter period of the
    motion's low-pass (42 ms at 6 Hz, 4 frames at 100 Hz), the time its zero-lag filter
    spreads a foot's landing or lift-off over; 0 without one. Chosen on the design half of
    the visible walks (alternate subjects; 0-15 frames tried at 100 Hz: 4 gave the best
    median r of ground_reaction against the raw plates there, 0.964, and 0.968 on the
    report half, against 0.942 and 0.921 without it)."""
    return int(round(rate / (4.0 * lowpass))) if lowpass else 0


def _figures(estimated: np.ndarray, measured: np.ndarray, weight: float) -> dict:
    ok = np.isfinite(estimated) & np.isfinite(measured)
    e, m = estimated[ok], measured[ok]
    r = float(np.corrcoef(e, m)[0, 1]) if e.size > 2 and e.std() > 0 and m.std() > 0 \
        else float("nan")
    rms = float(np.sqrt(np.mean((e - m) ** 2)) / weight * 100.0) if e.size else float("nan")
    return {"r": round(r, 3), "rms_pct_bw": round(rms, 2)}


def _forward(report, frames: np.ndarray) -> np.ndarray:
    """Unit horizontal direction of the centre of mass's mean velocity over ``frames``."""
    com = report.centre_of_mass
    velocity = np.gradient(com, 1.0 / report.rate, axis=0)[frames].mean(axis=0)
    velocity[1] = 0.0
    norm = np.linalg.norm(velocity)
    return velocity / norm if norm > 0 else np.array([0.0, 0.0, 1.0])


def compare_with_plates(report, plates: MeasuredPlates) -> dict:
    """Estimated (the check's contact forces) vs measured ground reaction.

    Returns
    -------
    dict
        ``stances``: one entry per clean stance (plate, foot, frames, ``vertical`` and
        ``antero_posterior`` {r, rms_pct_bw}); ``total``: the same over the frames where the
        plates carry the whole body (``frames`` 0 when there are none).
    """
    weight = report.weight
    segments = np.asarray(report.contact_segments)
    names = report.joint_names
    stances, owner = plate_stances(report, plates)
    forces = report.contact_forces
    result = {"stances": [], "total": {"frames": 0}}
    for s in stances:
        span = np.arange(s.start, s.stop)
        estimated = forces[span][:, segments == s.foot].sum(axis=1)
        measured = plates.force[s.plate, span]
        ahead = _forward(report, span)
        result["stances"].append({
            "plate": plates.names[s.plate], "foot": names[s.foot - 1],
            "start_s": round(float(report.times[s.start]), 3), "frames": int(span.size),
            "vertical": _figures(estimated[:, 1], measured[:, 1], weight),
            "antero_posterior": _figures(estimated @ ahead, measured @ ahead, weight)})
    carried = carried_frames(report, stances)
    if carried.sum() > 2:
        span = np.flatnonzero(carried)
        estimated = forces[span].sum(axis=1)
        measured = plates.force[:, span].sum(axis=0)
        ahead = _forward(report, span)
        result["total"] = {"frames": int(span.size),
                           "vertical": _figures(estimated[:, 1], measured[:, 1], weight),
                           "antero_posterior": _figures(estimated @ ahead, measured @ ahead,
                                                        weight)}
    return result


def plate_joint_torques(report, humanoid, plates: MeasuredPlates
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bottom-up inverse dynamics: joint torques with the measured plate wrenches applied
    to the feet that load them.

    Each loaded plate's wrench acts on its foot (the owner of :func:`plate_stances`): its
    force, and its moment about the origin moved to the joint (``moment − p × force``,
    the force at the centre of pressure plus the free moment, without dividing by a
    vertical force that vanishes at heel strike and toe off, and filtered like the force
    — :attr:`MeasuredPlates.moment`); a joint's torque is the RNEA torque of the motion
    minus the moments of the external wrenches on its subtree — the same numbers as a
    recursion from the foot upwards.

    Returns
    -------
    torques : ndarray, shape (frames, joints, 3), N·m, each joint's frame
    valid : ndarray, shape (frames, joints), bool
        Joints whose subtree's external load is fully measured in that frame: no foot of
        the subtree touches the floor (per the check) off a plate.
    loaded : ndarray, shape (frames, joints), bool
        Valid joints whose subtree stands on a plate in that frame (stance on a plate).
    """
    world_r, world_p = report.segment_poses
    sk = humanoid.skeleton
    frames = report.frames
    _, owner = plate_stances(report, plates)
    free_torques = report.joint_torques + report.contact_torques
    segments = np.asarray(report.contact_segments)
    external = np.zeros((frames, sk.count - 1, 3))
    valid = np.ones((frames, sk.count - 1), bool)
    loaded = np.zeros((frames, sk.count - 1), bool)
    feet = sorted(set(segments.tolist()))
    for foot in feet:
        on_plate = (owner == foot)
        force = np.where(on_plate[..., None], plates.force, 0.0).sum(axis=0)       # (F, 3)
        about_origin = np.where(on_plate[..., None], plates.moment, 0.0).sum(axis=0)
        touching = report.contact_active[:, segments == foot].any(axis=1)
        unmeasured = touching & ~on_plate.any(axis=0)
        for j in range(1, sk.count):
            if foot not in sk.subtree(j):
                continue
            moment = about_origin - np.cross(world_p[:, j], force)
            external[:, j - 1] += np.einsum("fji,fj->fi", world_r[:, j], moment)
            valid[:, j - 1] &= ~unmeasured
            loaded[:, j - 1] |= on_plate.any(axis=0)
    return free_torques - external, valid, loaded & valid
