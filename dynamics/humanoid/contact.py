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

from mocap.body.anthropometry import foot_points, leg_length

from dynamics.humanoid.model import Humanoid


#: A stance normal tilted more than this from the foot's Y axis is not taken as its sole.
MAX_PITCH_DEG = 30.0
#: Stances whose sole normal differs more than this from the longest stance's are not
#: flat (a foot still on its toes) and do not set the sole's pitch.
STANCE_AGREEMENT_DEG = 10.0
#: How far a rig's sole may lie below the lowest of its foot's points (ankle, toe), in
#: leg lengths, by what that point is: the most a foot's anatomy and a shoe put between
#: them, so that a trial whose feet stand further above the floor than this floats. A toe
#: joint (the metatarsophalangeal joint centre) stands about 2-2.5 cm above the sole
#: barefoot, and a running shoe's forefoot adds up to 4.5 cm: 7 cm, 0.085 of a 0.82 m
#: leg (Bandai's stand 4.0-5.8 cm above the floor in stance); a toe-tip end site lies
#: on the toe, 0-2 cm above the sole, and the shoe's 3 cm at the toe: 0.06; an ankle
#: joint centre the lateral malleolus height 0.039 of the stature (Winter 2009,
#: Fig. 4.1) over the hip-to-ankle 0.491, 6.8 cm, and a shoe's heel 3 cm: 0.115.
#: Held out: the shoe's forefoot went from 3.5 cm (0.07) to 4.5 cm after one take of
#: bandai2's design half (styles active, exhausted, masculine, youthful: 14 of 72 takes
#: stand above 0.07, the highest 0.0735); on the report half (elderly, feminine,
#: normal), not looked at for it, 0 of 54 stand above 0.085 (9 above 0.07; the highest
#: 0.0733). ``python benchmarks/check_validation.py`` prints both.
SOLE_BELOW_LOWEST = {"toe joint": 0.085, "end site": 0.06, "ankle": 0.115}
#: The toes (phalanges) beyond a rig's toe joint, in leg lengths: 0.27 of the foot length
#: (the metatarsal heads at 0.73 of it from the heel), the foot 0.152 of the stature
#: (Winter 2009), i.e. 0.041 of the stature over the hip-to-ankle 0.491.
TOE_LENGTH = 0.084


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
        (default the foot's Y; :func:`joint_soles` gives a rig's feet theirs).
    sole_lowest : dict, optional
        Foot segment index → the least offset ``d`` of its sole (:func:`joint_soles`: the
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


def _flat_foot_normal(rotations: np.ndarray, origins: np.ndarray, toe: np.ndarray,
                      within: float = 0.01) -> np.ndarray:
    """The floor's normal in a foot's frame while the foot is flat (unit, shape (3,)).

    Flat: ankle and toe point both at their lowest together — the frames whose summed
    heights above their minima are within ``within`` (m) of the least sum. No speed test,
    so a runner's short stances count as well as a walker's; heights are only compared
    with themselves, so the floor's level plays no part.
    """
    ankle = origins[:, 1]
    tip = origins[:, 1] + rotations[:, 1, :] @ toe
    raised = (ankle - ankle.min()) + (tip - tip.min())
    seen = np.swapaxes(rotations, 1, 2)[:, :, 1]                       # Rᵀ e_y, (F, 3)
    normal = np.median(seen[raised <= raised.min() + within], axis=0)
    return normal / np.linalg.norm(normal)


def _stance_runs(world: np.ndarray, rate: float, still_speed: float) -> list[tuple[int, int]]:
    """Runs of at least 50 ms (2 frames) where every point of ``world`` (frames, points, 3)
    of one foot is slower than ``still_speed``."""
    speed = np.linalg.norm(np.gradient(world, 1.0 / rate, axis=0), axis=2)
    return _runs((speed < still_speed).all(axis=1), max(int(round(0.05 * rate)), 2))


def joint_soles(humanoid: Humanoid, feet: dict[str, str], world_r: np.ndarray,
                world_p: np.ndarray, rate: float, floor: float = 0.0,
                still_speed: float = 0.2) -> tuple[np.ndarray, dict, dict]:
    """Contact points under the feet of a rig whose foot ends at a joint (module docstring).

    A skeleton's ankle and toe are points of the rig on the foot's bones: joint centres
    inside the foot (a captured skeleton: Bandai's toe joint 42 mm above its floor), or
    points on the sole itself (game and tool rigs whose ankle and toe joints touch the
    floor). Which one is found from the trial, with no constant of any dataset: where the
    foot stands still, its lowest rig point stands ``h`` above ``floor`` (median over
    those frames); the sole lies ``h`` below that point when ``0 ≤ h ≤``
    :data:`SOLE_BELOW_LOWEST` (what a foot's anatomy and a shoe can put between them), and
    at the point itself otherwise: a trial standing higher floats, one standing lower
    penetrates, by what the rig's own points show (nothing is invented below them). The
    sole's normal in the foot frame is the floor's normal seen from the foot when it is
    flat (:func:`_flat_foot_normal`; Bandai's foot X runs along the bone, pitched 40°
    down); the contact points are laid out across and along it
    (:func:`mocap.body.anthropometry.foot_points` with that ``up``).
    :func:`calibrate_contacts` then fits the sole's height to the stances, never above
    the rig's lowest point (``sole_lowest``).

    Parameters
    ----------
    humanoid : Humanoid
    feet : dict
        The feet to lay out (``"l_foot"``, ``"r_foot"``) → what their toe point is,
        ``"toe joint"`` (the toes, :data:`TOE_LENGTH`, are added beyond it) or
        ``"end site"`` (the rig's toe tip); the others keep their points.
    world_r, world_p : segment poses, (frames, segments, 3, 3) and (frames, segments, 3)
    rate : float, Hz
    floor : float, m
        The floor's height (Y up).
    still_speed : float, m/s
        A foot whose rig points are all slower stands still.

    Returns
    -------
    points : ndarray, shape (points, 3)
        Contact points in their foot's frame (``humanoid.contact_points`` order).
    normals : dict
        Foot segment index → sole normal in its frame (the ``sole_up`` of
        :func:`calibrate_contacts`).
    lowest : dict
        Foot segment index → the sole's offset ``d`` (``n·x = −d``) through the rig's
        lowest point: the least the sole lies below the foot's origin.
    """
    skeleton = humanoid.skeleton
    segments = np.asarray(humanoid.contact_segments)
    points = np.array(humanoid.contact_points, dtype=float)
    normals, lowest = {}, {}
    leg = leg_length(skeleton)
    for name, kind in feet.items():
        foot = skeleton.index(name)
        mine = np.flatnonzero(segments == foot)
        toe = skeleton.end_sites[foot]
        normal = _flat_foot_normal(world_r[:, foot], world_p[:, foot], toe)
        h = still_foot_height(world_r[:, foot], world_p[:, foot], toe, rate, still_speed) \
            - floor
        low = min(0.0, float(toe @ normal))
        bound = SOLE_BELOW_LOWEST[kind if toe @ normal < 0.0 else "ankle"] * leg
        level = low - (h if 0.0 <= h <= bound else 0.0)
        laid = foot_points(toe, up=normal)
        if kind == "toe joint":
            # The toes beyond the toe joint (phalanges), which push off after the heel
            # rises; the ball (metatarsal heads) stays under the joint.
            ahead = toe - (toe @ normal) * normal
            tip = toe + TOE_LENGTH * leg * ahead / max(np.linalg.norm(ahead), 1e-9)
            longer = foot_points(tip, up=normal)
            ball = longer["heel"] + 0.8 * (tip - longer["heel"])
            laid = {k: v + (toe - ball if k.startswith("toe_") else 0.0)
                    for k, v in longer.items()}
        laid = np.array(list(laid.values()))
        points[mine] = laid - np.outer(laid @ normal - level, normal)
        normals[int(foot)] = normal
        lowest[int(foot)] = -low
    return points, normals, lowest


def still_foot_height(rotations: np.ndarray, origins: np.ndarray, toe: np.ndarray,
                      rate: float, still_speed: float = 0.2) -> float:
    """How high (m, Y up) a rig's foot stands when still: the median over the frames
    where its ankle (the foot's origin) and toe point are both slower than
    ``still_speed`` of the lower of the two; NaN when the foot never stands still.

    Parameters
    ----------
    rotations, origins : ndarray, shapes (frames, 3, 3) and (frames, 3)
        The foot segment's world poses.
    toe : ndarray, shape (3,)
        The toe point in the foot frame (its end site).
    rate : float, Hz
    """
    rig = np.stack([origins, origins + rotations @ toe], axis=1)           # (F, 2, 3)
    speed = np.linalg.norm(np.gradient(rig, 1.0 / rate, axis=0), axis=2) \
        if rig.shape[0] > 1 else np.zeros(rig.shape[:2])
    still = (speed < still_speed).all(axis=1)
    return float(np.median(rig[still, :, 1].min(axis=1))) if still.any() else np.nan


def rig_soles(body: Motion, humanoid: Humanoid, floor: float = 0.0
              ) -> tuple[np.ndarray, dict, dict]:
    """The contact points of a body: the humanoid's, with :func:`joint_soles` under the
    feet its rig ends at joints (``body.metadata["feet_at_joints"]``, set by
    :func:`mocap.body.retarget.reduce_to_segments`). The check and the physics replay
    both stand on these.

    Parameters
    ----------
    body : Motion
        The reduced body motion the soles are seen in.
    humanoid : Humanoid
    floor : float, m
        The floor's height in the motion (Y up).

    Returns
    -------
    points : ndarray, shape (points, 3)
        Contact points in their foot's frame (``humanoid.contact_points`` order).
    normals : dict
        Foot segment index → sole normal in its frame (empty without rig feet).
    lowest : dict
        Foot segment index → the sole offset through the rig's lowest point
        (:func:`joint_soles`; empty without rig feet).
    """
    feet = {n: kind for n, kind in body.metadata.get("feet_at_joints", {}).items()
            if n in body.skeleton.names}
    if not feet:
        return humanoid.contact_points, {}, {}
    return joint_soles(humanoid, feet, *body.forward_kinematics(), body.rate, floor)


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
    humanoid's contact points (a rig's soles, :func:`joint_soles`)."""
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


def foot_skate(contacts: np.ndarray, height: float, speed: float, rate: float
                ) -> tuple[float, float]:
    """Foot skating of contact points, (mean mm per frame, skating ratio).

    A pair of consecutive frames counts when the point is below ``height`` in both and its
    horizontal speed is below ``speed`` (the contact definition of the force solve): a
    swinging foot passes within a centimetre or two of the floor in normal walking (toe
    clearance) but far faster. The skating ratio is the fraction of those pairs faster than
    0.5 m/s (captured walking scores about 0.03–0.07).
    """
    if contacts.shape[0] < 2:
        return 0.0, 0.0
    near = contacts[:, :, 1] < height
    step = np.linalg.norm((contacts[1:] - contacts[:-1])[..., [0, 2]], axis=2)
    both = near[1:] & near[:-1] & (step * rate < speed)
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
