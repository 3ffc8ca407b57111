"""Ground contact of the humanoid: contact points calibrated on the soles, the floor under
each foot, flight phases, foot skating. The forces at those points, inside friction
pyramids, are :mod:`dynamics.humanoid.contact_forces`.

Sole calibration (per foot). Markers do not show where the sole is, and the heel–toe
marker line is not parallel to it (Plug-in Gait's toe marker sits on the forefoot's
dorsum, the heel marker on the back of the calcaneus: the line is pitched about 5° in
stance). In the frames where every contact point of the foot is slower than
``still_speed`` (foot flat), the floor's normal seen from the foot, ``u = Rᵀ e_y``, and
the ankle's height are nearly constant. Per stance (a run of such frames) their medians
give one sole plane in the foot frame, ``u·x = −d``; the foot's sole normal is the mean
of its stances' normals (its pitch and roll against the segment frame) and the contact
points (heel, ball, toe from :func:`mocap.body.anthropometry.foot_points`) are moved along
it onto the plane. Its offset ``d`` (ankle above sole) is the median ankle height of the
stances on the reference floor (``floor``, 0 by default): those whose ankle height is
within ``step`` of what the uncalibrated sole predicts for that floor.

Floors that are not flat. A stance whose sole (with the calibrated offset) is more than
``step`` off the reference floor stands on its own level (a stair, a step, a platform):
its floor height is where its lowest sole point stands (median over the stance; for a
flat foot the ankle height minus ``d``, but also right for a foot still on its toes).
Each frame's floor under a foot is that of the foot's stance during a stance, and the
lower of the two stances around a swing (of the first or last stance and the reference
floor before or after them). A stance below the floor counts as a level only where the
stances, of one foot or of both, lie on several levels (stairs down; in a one-cycle stair
trial each foot may stand on one step only); the skeleton's flat-floor sole calibration,
which takes the median over a foot's stances, is then undone (``prior_shift``). On
several levels, before a foot's first and after its last stance the floor follows the
foot (:func:`_open_ends`): where its lowest point is nearly still it stands there (a
foot rolling off its toe as the trial starts or ends), where it moves the floor is a
``step`` below it (reaching for a step the trial does not show), so a stair trial's
first and last steps neither penetrate nor carry weight they could not.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mocap.skeleton import Motion
from mocap.trial import runs as runs_of_true

from dynamics.humanoid.model import Humanoid


#: A stance normal tilted more than this from the foot's Y axis is not taken as its sole.
MAX_PITCH_DEG = 30.0
#: Stances whose sole normal differs more than this from the longest stance's are not
#: flat (a foot still on its toes) and do not set the sole's pitch.
STANCE_AGREEMENT_DEG = 10.0


@dataclass
class ContactCalibration:
    """Calibrated contact points and the floor under them.

    Attributes
    ----------
    points : ndarray, shape (points, 3), metres
        Contact points in their foot's frame, on the calibrated sole.
    floors : ndarray, shape (frames, points), metres
        Floor height under each point in each frame (Y up).
    pitch_deg : dict
        Per foot, the angle between the calibrated sole normal and the uncalibrated one.
    shift_mm : dict
        Per foot, how far the sole moved along its normal (positive: down).
    levels : list of float
        Distinct floor heights found (m), the reference floor first.
    """

    points: np.ndarray
    floors: np.ndarray
    pitch_deg: dict = field(default_factory=dict)
    shift_mm: dict = field(default_factory=dict)
    levels: list = field(default_factory=list)


def points_in_world(points: np.ndarray, segments: list[int], world_r: np.ndarray,
                    world_p: np.ndarray) -> np.ndarray:
    """World positions (frames, points, 3) of contact points given in segment frames."""
    return world_p[:, segments] + np.einsum("fpij,pj->fpi", world_r[:, segments], points)


def _runs(mask: np.ndarray, shortest: int) -> list[tuple[int, int]]:
    """(start, stop) of the runs of True in a 1-D mask at least ``shortest`` long."""
    starts, lengths = runs_of_true(mask)
    return [(a, a + n) for a, n in zip(starts, lengths) if n >= shortest]


def calibrate_contacts(points: np.ndarray, segments: list[int], world_r: np.ndarray,
                       world_p: np.ndarray, rate: float, floor: float = 0.0,
                       still_speed: float = 0.2, step: float = 0.03,
                       prior_shift: dict | None = None, sole_up: dict | None = None,
                       sole_lowest: dict | None = None) -> ContactCalibration:
    """Calibrate soles and find the floor under each foot (module docstring).

    Parameters
    ----------
    points : ndarray, shape (points, 3)
        Uncalibrated contact points in their segment's frame.
    segments : list of int
        Segment (foot) of each point.
    world_r, world_p : segment poses, (frames, segments, 3, 3) and (frames, segments, 3)
    rate : float, Hz
    floor : float, m
        The reference floor height.
    still_speed : float, m/s
    step : float, m
        How far a stance's sole may be off the reference floor and still stand on it.
    prior_shift : dict, optional
        Foot segment index → how far (m, along the foot's Y) a flat-floor sole calibration
        before this one lowered the sole (``mocap.skeleton``'s ``sole_calibration_m``).
        Where the foot's stances lie on several levels, that calibration mixed them: it is
        undone and the foot's lowest stances are taken as standing on the floor.
    sole_up : dict, optional
        Foot segment index → the direction (foot frame) the sole normal is kept near
        (default the foot's Y; :func:`dynamics.humanoid.soles.joint_soles` gives a rig's feet theirs).
    sole_lowest : dict, optional
        Foot segment index → the least offset ``d`` of its sole (:func:`dynamics.humanoid.soles.joint_soles`: the
        sole no higher than the rig's lowest point, whatever the stances).
    """
    frames = world_p.shape[0]
    segments = np.asarray(segments)
    points = np.array(points, dtype=float)
    calibrated = points.copy()
    floors = np.full((frames, len(segments)), float(floor))
    result = ContactCalibration(calibrated, floors, levels=[float(floor)])
    if frames < 3:
        return result
    world = points_in_world(points, list(segments), world_r, world_p)
    stances = {}
    for foot in sorted(set(segments.tolist())):
        mine = np.flatnonzero(segments == foot)
        runs = _stance_runs(world[:, mine], rate, still_speed)
        if runs:
            stances[foot] = (mine, runs, np.array([float(np.median(world_p[a:b, foot, 1]))
                                                   for a, b in runs]))
    # Several levels when the stances, of one foot or of both, lie more than two steps
    # apart (stairs: in a one-cycle trial each foot may stand on one step only), judged
    # at each stance's lowest sole point: a still foot on its toes (heel up) lifts the
    # ankle, not the sole. The sole as the geometry gives it (a flat-floor calibration
    # before this one, which would put every foot's stances at one level, undone).
    geometric = points.copy()
    for foot, shift in (prior_shift or {}).items():
        geometric[segments == foot, 1] += shift
    lowest = points_in_world(geometric, list(segments), world_r, world_p)[..., 1]
    seen = np.concatenate([[np.median(lowest[a:b][:, mine].min(axis=1)) for a, b in runs]
                           for mine, runs, _ in stances.values()]) \
        if stances else np.zeros(1)
    several = bool(seen.max() - seen.min() > 2 * step)
    found = []
    for foot, (mine, runs, heights) in stances.items():
        normal = _stance_normal(world_r[:, foot], runs,
                                up=(sole_up or {}).get(int(foot), np.array([0.0, 1.0, 0.0])))
        prior = (prior_shift or {}).get(int(foot), 0.0)
        if prior and several:
            # Several levels: an earlier flat-floor calibration took their median; undo it
            # and keep the sole the geometry gives (markers or the skeleton).
            points[mine, 1] += prior
        # The uncalibrated sole's offset along the calibrated normal: d0 = −median(n·x).
        d0 = -float(np.median(points[mine] @ normal))
        ground = np.abs(heights - d0 - floor) < step
        d = float(np.median(heights[ground] - floor)) if ground.any() else d0
        d = max(d, (sole_lowest or {}).get(int(foot), -np.inf))
        found.append((foot, mine, runs, heights, normal, d0, d, ground))
    # Stances on other levels, only when a foot stands on the floor in the trial (a body
    # that never touches it is held up, not on a stage): above the floor (a step, stairs, a
    # platform); below it only among several levels (stairs down from the floor), so feet
    # sunk into a flat floor still penetrate it.
    grounded = any(entry[7].any() for entry in found)
    default = np.array([0.0, 1.0, 0.0])
    for foot, mine, runs, heights, normal, d0, d, ground in found:
        calibrated[mine] = points[mine] - np.outer(points[mine] @ normal + d, normal)
        sole = points_in_world(calibrated[mine], [foot] * mine.size, world_r, world_p)
        # A stance's level: where its lowest sole point stands (the ankle's height less d
        # would put a foot still on its toes, heel up, above its step).
        level = np.array([float(np.median(sole[a:b, :, 1].min(axis=1))) for a, b in runs])
        off = level - floor
        # A level is stood on longer than a body in free flight stays still: its speed is
        # below still_speed for 2·still_speed/g around a jump's apex (and a frame more).
        lasting = np.array([b - a for a, b in runs]) / rate > 2.0 * still_speed / 9.81 \
            + 1.0 / rate
        other = ((off >= step) | (several & (off <= -step))) & grounded & lasting
        run_floor = np.where(other, level, floor)
        ends = _open_ends(sole, runs, run_floor, rate, still_speed, step) \
            if several and grounded else None
        floors[:, mine] = _floor_under(runs, run_floor, frames, floor, ends)[:, None]
        reference = (sole_up or {}).get(int(foot), default)
        result.pitch_deg[int(foot)] = float(np.degrees(np.arccos(np.clip(normal @ reference,
                                                                          -1, 1))))
        result.shift_mm[int(foot)] = 1000.0 * (d - d0)
        for level in run_floor:
            if all(abs(level - seen) > 0.01 for seen in result.levels):
                result.levels.append(float(level))
    return result


def _stance_normal(rotations: np.ndarray, runs: list[tuple[int, int]],
                   up: np.ndarray | None = None) -> np.ndarray:
    """The floor's normal seen from a foot in its stances, ``Rᵀ e_y`` (median per stance,
    mean over the stances within :data:`STANCE_AGREEMENT_DEG` of the longest one's: a
    foot resting on its toes with the heel up, as it lowers the body down a stair, is
    still but not flat), unit, in the foot frame; with ``up`` (a direction in the foot
    frame) kept within :data:`MAX_PITCH_DEG` of it."""
    seen = np.swapaxes(rotations, 1, 2)[:, :, 1]                       # Rᵀ e_y, (F, 3)
    normals = np.array([np.median(seen[a:b], axis=0) for a, b in runs])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    longest = normals[int(np.argmax([b - a for a, b in runs]))]
    flat = normals @ longest >= np.cos(np.radians(STANCE_AGREEMENT_DEG))
    normal = normals[flat].mean(axis=0)
    normal /= np.linalg.norm(normal)
    if up is None:
        return normal
    up = np.asarray(up, float)
    tilt = np.degrees(np.arccos(np.clip(normal @ up, -1.0, 1.0)))
    if tilt > MAX_PITCH_DEG:
        axis = np.cross(up, normal)
        axis /= np.linalg.norm(axis)
        angle = np.radians(MAX_PITCH_DEG)
        normal = up * np.cos(angle) + np.cross(axis, up) * np.sin(angle)
    return normal


def _stance_runs(world: np.ndarray, rate: float, still_speed: float) -> list[tuple[int, int]]:
    """Runs of at least 50 ms (2 frames) where every point of ``world`` (frames, points, 3)
    of one foot is slower than ``still_speed``."""
    speed = np.linalg.norm(np.gradient(world, 1.0 / rate, axis=0), axis=2)
    return _runs((speed < still_speed).all(axis=1), max(int(round(0.05 * rate)), 2))


def _floor_under(runs: list[tuple[int, int]], levels: np.ndarray, frames: int,
                 floor: float, ends: tuple[np.ndarray, np.ndarray] | None = None
                 ) -> np.ndarray:
    """Per frame, the floor under a foot: its stance's level during a stance; between
    two stances the lower of the two (a swinging foot is above both); before the first
    and after the last, the lower of that stance's and the reference floor, or ``ends``
    (the floor over the frames before the first and after the last, :func:`_open_ends`)."""
    out = np.empty(frames)
    starts = np.array([a for a, _ in runs])
    stops = np.array([b for _, b in runs])
    index = np.arange(frames)
    before = np.searchsorted(stops, index, side="right") - 1       # last run ended ≤ f
    after = np.searchsorted(starts, index, side="right") - 1       # last run started ≤ f
    inside = (after >= 0) & (index < stops[np.clip(after, 0, None)])
    previous = levels[np.clip(before, 0, None)]
    following = levels[np.clip(before + 1, 0, len(runs) - 1)]
    out[:] = np.where(before < 0, min(levels[0], floor),
                      np.where(before + 1 >= len(runs), min(levels[-1], floor),
                               np.minimum(previous, following)))
    out[inside] = levels[after[inside]]
    if ends is not None:
        out[:starts[0]] = ends[0]
        out[stops[-1]:] = ends[1]
    return out


def _open_ends(world: np.ndarray, runs: list[tuple[int, int]], levels: np.ndarray,
               rate: float, still_speed: float, step: float) -> tuple[np.ndarray, np.ndarray]:
    """The floor under a foot before its first and after its last stance on a floor of
    several levels, where the reference floor says nothing (stairs: the step a foot
    pushes off from as the trial starts, the one it reaches for as it ends).

    ``world`` (frames, points, 3) are the foot's calibrated contact points. Going away
    from the stance (back in time before the first, forward after the last), where the
    foot's lowest point is slower than twice ``still_speed`` it stands there (rolling off
    the toe, a stance the trial's edge cut short): that is the floor; where it moves but is
    not below where it last stood (a toe rolling off at toe-off speed, or a foot lifting
    towards a step above) the floor stays there; where it has gone more than half a
    ``step`` below it (past the step's edge, on its way to a step further down: not in
    contact, not in it) the floor is a ``step`` below the lowest it has been since.
    Starts from the stance's level.

    Returns
    -------
    before, after : ndarray
        The floor over the frames before the first stance and after the last, metres.
    """
    speed = np.linalg.norm(np.gradient(world, 1.0 / rate, axis=0), axis=2)
    lowest = world[:, :, 1].argmin(axis=1)
    index = np.arange(world.shape[0])
    height = world[index, lowest, 1]
    slow = speed[index, lowest] < 2.0 * still_speed        # a toe rolls off at up to ~0.3 m/s

    def away(h: np.ndarray, standing: np.ndarray, level: float) -> np.ndarray:
        out = np.empty(h.size)
        group = np.cumsum(standing)                  # frames since the last standing one
        start = np.r_[level, h[standing]][group]     # where the foot last stood
        for g in np.unique(group):
            mine = group == g
            # A moving foot not below where it last stood is still over that step (a toe
            # rolling off it, or lifting towards one above): the floor stays there. Only
            # below it has the foot passed the step's edge, on its way further down.
            past = ~standing[mine] & (h[mine] < start[mine] - step / 2)
            out[mine] = np.minimum(start[mine], np.minimum.accumulate(
                np.where(past, h[mine] - step, np.inf)))
        return out

    first, last = runs[0][0], runs[-1][1]
    before = away(height[:first][::-1], slow[:first][::-1], float(levels[0]))[::-1]
    after = away(height[last:], slow[last:], float(levels[-1]))
    return before, after


def flight_accelerations(com: np.ndarray, airborne: np.ndarray, rate: float,
                         shortest: int = 5) -> np.ndarray:
    """The captured centre of mass's acceleration over each flight phase (frames, 3).

    For each run of airborne frames (no contact point active) of at least ``shortest``
    frames, a parabola per axis fitted to the centre of mass's position over the whole
    run: its (constant) second derivative, m/s². The fit uses positions, so it is not
    spoiled by a low-pass that spreads the landing's deceleration over the flight before
    it; NaN outside such runs.
    """
    out = np.full((airborne.shape[0], 3), np.nan)
    for a, b in _runs(airborne, shortest):
        t = np.arange(b - a) / rate
        out[a:b] = 2.0 * np.polyfit(t, com[a:b], 2)[0]
    return out


def ballistic_runs(com: np.ndarray, airborne: np.ndarray, rate: float,
                   gravity: float = 9.81, shortest: int = 5) -> np.ndarray:
    """Frames of flight phases whose centre of mass falls freely (bool, frames).

    A run of airborne frames of at least ``shortest`` frames is ballistic when the
    vertical acceleration of its parabola (:func:`flight_accelerations`) is within half of
    g of −g (a body held up has 0). Shorter runs are too short to tell and count as
    ballistic (the check reports them as not judged).
    """
    result = airborne.copy()
    fitted = flight_accelerations(com, airborne, rate, shortest)[:, 1]
    known = np.isfinite(fitted)
    result[known] = np.abs(fitted[known] + gravity) < 0.5 * gravity
    return result


def estimate_floor(body: Motion, humanoid: Humanoid, still_speed: float = 0.15,
                   points: np.ndarray | None = None) -> float:
    """Floor height (m) of a motion: the median height of each foot's lowest contact point
    over the frames where that foot stands still (all its points slower than
    ``still_speed`` m/s); 0 when a foot never stands still. ``points`` replaces the
    humanoid's contact points (a rig's soles, :func:`dynamics.humanoid.soles.joint_soles`)."""
    world_r, world_p = body.forward_kinematics()
    contacts = points_in_world(humanoid.contact_points if points is None else points,
                               humanoid.contact_segments, world_r, world_p)
    speed = np.linalg.norm(np.gradient(contacts, 1.0 / body.rate, axis=0), axis=2)
    heights = []
    for foot in sorted(set(humanoid.contact_segments)):
        points = [k for k, s in enumerate(humanoid.contact_segments) if s == foot]
        still = (speed[:, points] < still_speed).all(axis=1)
        heights.append(contacts[still][:, points, 1].min(axis=1))
    found = np.concatenate(heights) if heights else np.zeros(0)
    return float(np.median(found)) if found.size else 0.0


def foot_skate(contacts: np.ndarray, height: float, speed: float, rate: float,
               segments: list[int] | None = None, flat: float = 0.005
               ) -> tuple[float, float]:
    """Foot skating of contact points, (mean mm per frame, skating ratio).

    A pair of consecutive frames counts when the point is below ``height`` in both and its
    horizontal speed is below ``speed`` (the contact definition of the force solve): a
    swinging foot passes within a centimetre or two of the floor in normal walking (toe
    clearance) but far faster. With ``segments`` (the foot of each point), a point also
    counts, however fast, while every point of its foot is within ``flat`` (m) of the
    floor in both frames: a sole flat on the floor that moves slides (a swinging or
    landing foot is not flat on it). The skating ratio is the fraction of those pairs faster than 0.5 m/s
    (captured walking scores about 0.03–0.07).
    """
    if contacts.shape[0] < 2:
        return 0.0, 0.0
    near = contacts[:, :, 1] < height
    step = np.linalg.norm((contacts[1:] - contacts[:-1])[..., [0, 2]], axis=2)
    slow = step * rate < speed
    if segments is not None:
        segments = np.asarray(segments)
        down = contacts[:, :, 1] < flat
        sole = np.zeros_like(near)
        for foot in set(segments.tolist()):
            sole[:, segments == foot] = down[:, segments == foot].all(axis=1, keepdims=True)
        slow |= sole[1:] & sole[:-1]
    both = near[1:] & near[:-1] & slow
    if not both.any():
        return 0.0, 0.0
    moved = step[both]
    return 1000.0 * float(moved.mean()), float(np.mean(moved * rate > 0.5))


def rollover_centres(calibration: ContactCalibration, names: list[str], segments: list[int],
                     active: np.ndarray, world_r: np.ndarray, world_p: np.ndarray
                     ) -> np.ndarray:
    """A prior centre of pressure under each foot: heel-to-toe roll-over in time.

    Over each of a foot's contacts (a run of frames with any of its points in contact,
    at least 3 frames, not cut by the trial's first or last frame) the centre of pressure
    moves along the sole from the heel point to the toe point in proportion to the time
    since the contact began: at the heel when it lands, at the toe when it leaves. The
    contact points' own in-contact test starts a contact a little before the heel
    strikes and ends it a little after the toe leaves, so the prior spans the whole of
    what a plate sees. On the floor under the foot; NaN outside such contacts.

    Parameters
    ----------
    calibration : ContactCalibration
        Calibrated contact points (``points``, foot frames) and the floor under them.
    names : list of str
        ``<foot>.<point>`` of each contact point (each foot has a ``.heel`` and a ``.toe``).
    segments : list of int
        Foot segment of each point.
    active : ndarray, shape (frames, points), bool
        Points in contact.
    world_r, world_p : segment poses, (frames, segments, 3, 3) and (frames, segments, 3)

    Returns
    -------
    ndarray, shape (frames, points, 3), metres
        Per frame and point, the prior centre of pressure of the point's foot (world).
    """
    frames = active.shape[0]
    segments = np.asarray(segments)
    out = np.full((frames, segments.size, 3), np.nan)
    for foot in sorted(set(segments.tolist())):
        mine = np.flatnonzero(segments == foot)
        ends = {names[k].rsplit(".", 1)[-1]: calibration.points[k] for k in mine}
        if "heel" not in ends or "toe" not in ends:
            continue
        fraction = np.full(frames, np.nan)
        for a, b in _runs(active[:, mine].any(axis=1), 3):
            if a > 0 and b < frames:
                fraction[a:b] = np.arange(b - a) / (b - 1 - a)
        known = np.isfinite(fraction)
        local = ends["heel"] + fraction[known, None] * (ends["toe"] - ends["heel"])
        centre = world_p[known, foot] + np.einsum("fij,fj->fi", world_r[known, foot], local)
        centre[:, 1] = calibration.floors[known, mine[0]]
        out[np.flatnonzero(known)[:, None], mine[None, :]] = centre[:, None, :]
    return out
