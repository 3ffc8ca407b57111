"""Synthetic marker data: people × actions with ground-truth joint angles.

Each person has a *motion signature*: body size and proportions, cadence, a few
latent style factors that scale and offset every joint-angle curve (and interact
with the action: a long-striding walker is not a long-striding stair climber in
the same proportion), a stance/swing timing warp and a left/right asymmetry.
Each action (walk, run, ascend and descend stairs) has its own template curves,
written as sums of periodic bumps over the gait cycle (0 = right heel strike).

Forward kinematics puts three markers on each of the 15 segments of the
``synthetic15`` marker set (origin at the proximal joint centre, one marker
0.10 m anterior, one 0.10 m to the left), in a Z-up lab facing +X.  The root is
translated so that the stance foot's lowest contact point stays planted on the
floor (no foot skating by construction; running has no flight phase in this
simplified model; stair trials rise or fall by two steps per cycle).

Examples
--------
>>> from mocap.synthetic import synthesize_trial
>>> trial, truth = synthesize_trial(0, "walk")
>>> trial.points.shape[1], truth.rotations.shape[1]
(45, 15)
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.errors import MocapError
from mocap.planting import planted_translation
from mocap.trial import Trial

#: Actions the generator knows, with their nominal cycle duration in seconds.
ACTION_CYCLE_SECONDS = {"walk": 1.10, "run": 0.72, "ascend": 1.35, "descend": 1.15}
ACTIONS = tuple(ACTION_CYCLE_SECONDS)

#: Default person names (any count beyond this list is named p13, p14 …).
PERSON_NAMES = ("ana", "ben", "chen", "dara", "emil", "fay",
                "gus", "hana", "ivo", "jade", "kofi", "lena")

#: Segments in marker-set order: (name, parent, marker prefix).
SEGMENTS = (
    ("pelvis", None, "PEL"), ("thorax", "pelvis", "THX"), ("head", "thorax", "HED"),
    ("l_upperarm", "thorax", "LUA"), ("l_forearm", "l_upperarm", "LFA"),
    ("l_hand", "l_forearm", "LHA"),
    ("r_upperarm", "thorax", "RUA"), ("r_forearm", "r_upperarm", "RFA"),
    ("r_hand", "r_forearm", "RHA"),
    ("l_thigh", "pelvis", "LTH"), ("l_shank", "l_thigh", "LSH"), ("l_foot", "l_shank", "LFT"),
    ("r_thigh", "pelvis", "RTH"), ("r_shank", "r_thigh", "RSH"), ("r_foot", "r_shank", "RFT"),
)
SEGMENT_NAMES = tuple(name for name, _, _ in SEGMENTS)
PARENT_INDEX = tuple(-1 if parent is None else SEGMENT_NAMES.index(parent)
                     for _, parent, _ in SEGMENTS)
MARKER_LABELS = tuple(prefix + suffix for _, _, prefix in SEGMENTS for suffix in "OAL")
#: Distance of the anterior and left markers from the segment origin, metres.
MARKER_SPACING = 0.10
#: Height of one stair step, metres (two steps per cycle on stairs).
STEP_RISE = 0.17

# Body proportions for a 1.75 m person, metres.
_NOMINAL = {
    "hip_width": 0.18, "hip_drop": 0.07, "trunk_base": 0.10, "neck": 0.46,
    "shoulder_width": 0.38, "shoulder_height": 0.42, "head": 0.24,
    "upperarm": 0.29, "forearm": 0.27, "hand": 0.09,
    "thigh": 0.43, "shank": 0.43, "ankle_height": 0.08, "foot": 0.22,
}


@dataclass
class Person:
    """One synthetic person's signature.

    Attributes
    ----------
    name : str
    height : float
        Metres.
    lengths : dict of str to float
        Segment lengths and widths, metres (keys as in the nominal body).
    style : ndarray, shape (styles,)
        Latent style factors (standard normal).
    cadence : float
        Multiplies every action's nominal cycle duration.
    timing : float
        Stance/swing timing warp, fraction of the cycle (about ±0.15).
    asymmetry : float
        Relative extra amplitude of the left side (about ±0.08).
    """

    name: str
    height: float
    lengths: dict
    style: np.ndarray
    cadence: float
    timing: float
    asymmetry: float


@dataclass
class GroundTruth:
    """What the generator knows exactly about a trial.

    Attributes
    ----------
    rotations : ndarray, shape (frames, segments, 3, 3)
        Joint rotations: R_parent⁻¹ R_child, the root's relative to the lab.
    segment_rotations : ndarray, shape (frames, segments, 3, 3)
        Segment frames in the lab.
    origins : ndarray, shape (frames, segments, 3)
        Segment origins (proximal joint centres) in the lab, metres.
    offsets : ndarray, shape (segments, 3)
        Each segment's origin in its parent's frame, metres (root: zeros).
    contact_points : dict of str to ndarray, shape (frames, 3)
        ``l_heel``, ``l_toe``, ``r_heel``, ``r_toe`` in the lab, metres.
    rate : float
        Hz.
    person, action : str
    cycle_seconds : float
        Duration of one cycle, seconds.
    """

    rotations: np.ndarray
    segment_rotations: np.ndarray
    origins: np.ndarray
    offsets: np.ndarray
    contact_points: dict
    rate: float
    person: str
    action: str
    cycle_seconds: float

    @property
    def segments(self) -> tuple[str, ...]:
        return SEGMENT_NAMES

    @property
    def parents(self) -> tuple[int, ...]:
        return PARENT_INDEX


# --------------------------------------------------------------------------- people

_STYLES = 3          # latent style factors per person
_DOFS = (len(SEGMENTS), 3)


def make_people(count: int, seed: int = 0) -> list[Person]:
    """Draw ``count`` distinct people from a seeded generator.

    Parameters
    ----------
    count : int
        Number of people (at least 1).
    seed : int
        Same seed, same people.
    """
    if count < 1:
        raise MocapError(f"need at least one person, got {count}")
    rng = np.random.default_rng([seed, 1])
    people = []
    for index in range(count):
        name = PERSON_NAMES[index] if index < len(PERSON_NAMES) else f"p{index + 1:02d}"
        height = float(np.clip(rng.normal(1.74, 0.09), 1.50, 2.00))
        scale = height / 1.75
        leg, arm, trunk = 1.0 + rng.normal(0.0, 0.03, size=3)
        lengths = {}
        for key, value in _NOMINAL.items():
            factor = scale * (leg if key in ("thigh", "shank", "foot") else
                              arm if key in ("upperarm", "forearm", "hand") else
                              trunk if key in ("neck", "shoulder_height") else 1.0)
            lengths[key] = value * factor
        people.append(Person(
            name=name, height=height, lengths=lengths,
            style=rng.normal(0.0, 1.0, size=_STYLES),
            cadence=float(np.clip(rng.normal(1.0, 0.07), 0.82, 1.18)),
            timing=float(np.clip(rng.normal(0.0, 0.08), -0.15, 0.15)),
            asymmetry=float(np.clip(rng.normal(0.0, 0.05), -0.10, 0.10)),
        ))
    return people


def _style_effects(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-style gain and offset patterns over the 15 × 3 joint DOFs, and the
    per-action weight of each style (the person × action interaction).

    Returns
    -------
    gains : (styles, segments, 3) relative amplitude change per unit style.
    offsets : (styles, segments, 3) degrees per unit style.
    action_weights : (actions, styles).
    """
    rng = np.random.default_rng([seed, 2])
    gains = rng.normal(0.0, 0.09, size=(_STYLES,) + _DOFS)
    offsets = rng.normal(0.0, 2.5, size=(_STYLES,) + _DOFS)
    action_weights = rng.uniform(0.6, 1.4, size=(len(ACTIONS), _STYLES))
    return gains, offsets, action_weights


# --------------------------------------------------------------------------- action templates

def _bump(u: np.ndarray, centre: float, width: float) -> np.ndarray:
    """Periodic bump on the unit cycle: 1 at ``centre``, about Gaussian with std ``width``."""
    return np.exp((np.cos(2 * np.pi * (u - centre)) - 1.0) / (2 * np.pi * width) ** 2)


def _cos(u: np.ndarray, shift: float = 0.0, harmonic: int = 1) -> np.ndarray:
    return np.cos(2 * np.pi * harmonic * (u - shift))


def _sin(u: np.ndarray, shift: float = 0.0, harmonic: int = 1) -> np.ndarray:
    return np.sin(2 * np.pi * harmonic * (u - shift))


def _leg_curves(action: str, u: np.ndarray) -> dict[str, np.ndarray]:
    """Clinical leg angles (degrees) of one side over phase ``u`` (0 = that side's heel strike)."""
    if action == "walk":
        return {
            "hip_flex": 12 + 20 * _cos(u, 0.02) + 2 * _cos(u, 0.1, 2),
            "hip_abd": -2 + 4 * _bump(u, 0.20, 0.10) - 3 * _bump(u, 0.70, 0.08),
            "hip_rot": 4 * _sin(u, 0.05),
            "knee_flex": 4 + 14 * _bump(u, 0.14, 0.06) + 56 * _bump(u, 0.71, 0.09),
            "ankle_inv": 3 * _sin(u, 0.3),
        }
    if action == "run":
        return {
            "hip_flex": 18 + 28 * _cos(u, 0.02) + 4 * _cos(u, 0.15, 2),
            "hip_abd": -3 + 6 * _bump(u, 0.15, 0.08) - 4 * _bump(u, 0.65, 0.10),
            "hip_rot": 6 * _sin(u, 0.05),
            "knee_flex": 18 + 24 * _bump(u, 0.17, 0.06) + 82 * _bump(u, 0.68, 0.10),
            "ankle_inv": 4 * _sin(u, 0.25),
        }
    if action == "ascend":
        return {
            "hip_flex": 32 + 30 * _cos(u, 0.05),
            "hip_abd": -2 + 5 * _bump(u, 0.30, 0.10),
            "hip_rot": 5 * _sin(u, 0.1),
            "knee_flex": 12 + 48 * _bump(u, 0.0, 0.08) + 80 * _bump(u, 0.73, 0.09),
            "ankle_inv": 2 * _sin(u, 0.2),
        }
    if action == "descend":
        return {
            "hip_flex": 18 + 12 * _cos(u, 0.80) + 4 * _cos(u, 0.3, 2),
            "hip_abd": -1 + 4 * _bump(u, 0.35, 0.12),
            "hip_rot": 3 * _sin(u, 0.2),
            "knee_flex": 8 + 78 * _bump(u, 0.55, 0.13) + 22 * _bump(u, 0.86, 0.06),
            "ankle_inv": 3 * _sin(u, 0.4),
        }
    raise MocapError(f"unknown action {action!r}; known: {', '.join(ACTIONS)}")


#: Pitch of the foot in the lab over the cycle (degrees, toes up positive) at control
#: phases: heel strike, foot flat, heel rise, toe-off, swing.  The ankle's flexion is
#: derived from it (see :func:`_with_ankles`), so the stance foot lies flat on the floor.
_FOOT_PITCH = {
    "walk": [(0.0, 18), (0.06, 3), (0.10, 0), (0.38, 0), (0.50, -12), (0.62, -50), (0.72, -30),
             (0.85, 5), (0.95, 16)],
    "run": [(0.0, 10), (0.06, 0), (0.16, 0), (0.28, -20), (0.38, -45), (0.55, -20), (0.80, 10),
            (0.93, 12)],
    "ascend": [(0.0, 0), (0.10, 0), (0.45, 0), (0.60, -30), (0.70, -10), (0.85, 10), (0.95, 5)],
    "descend": [(0.0, -20), (0.08, 0), (0.40, 0), (0.55, -15), (0.65, -30), (0.80, -10),
                (0.93, -20)],
}


def _foot_pitch(action: str, u: np.ndarray) -> np.ndarray:
    """Periodic cubic spline through ``_FOOT_PITCH[action]``, degrees, toes up positive."""
    from scipy.interpolate import CubicSpline

    phases, pitches = np.array(_FOOT_PITCH[action] + [(1.0, _FOOT_PITCH[action][0][1])]).T
    return CubicSpline(phases, pitches, bc_type="periodic")(u % 1.0)


def _with_ankles(angles: np.ndarray, action: str, u: np.ndarray) -> np.ndarray:
    """Set each ankle's flexion so the foot follows the action's foot-pitch profile.

    In the sagittal plane the foot's pitch is the sum of the pelvis, thigh, shank and
    foot rotations about the left axis; the ankle takes whatever the person's own hip
    and knee leave (to first order: abduction and axial rotation are small).
    """
    angles = angles.copy()
    index = {name: i for i, name in enumerate(SEGMENT_NAMES)}
    pelvis_pitch = angles[:, index["pelvis"], 0]
    for side, phase in (("r", 0.0), ("l", 0.5)):
        # rotation about +Y of each link, in the sign convention of _to_rotations
        thigh = -angles[:, index[f"{side}_thigh"], 0]
        shank = -angles[:, index[f"{side}_shank"], 0]
        toes_up = _foot_pitch(action, u + phase)
        angles[:, index[f"{side}_foot"], 0] = toes_up + pelvis_pitch + thigh + shank
    return angles


def _action_angles(action: str, u: np.ndarray) -> np.ndarray:
    """Template joint angles of an action: (frames, segments, 3) = (flex, abd, rot) degrees.

    Flexion is about the segment's left axis (e2), abduction about its anterior
    axis (e1), axial rotation about its up axis (e3), in clinical sign
    (flexion, abduction and internal rotation positive on both sides).
    """
    intensity = {"walk": 1.0, "run": 1.8, "ascend": 1.2, "descend": 1.0}[action]
    lean = {"walk": 3.0, "run": 10.0, "ascend": 9.0, "descend": 2.0}[action]
    elbow = {"walk": 20.0, "run": 85.0, "ascend": 25.0, "descend": 18.0}[action]
    angles = np.zeros(u.shape + _DOFS)
    index = {name: i for i, name in enumerate(SEGMENT_NAMES)}

    def put(segment: str, flex=0.0, abd=0.0, rot=0.0) -> None:
        angles[:, index[segment]] = np.stack(np.broadcast_arrays(flex, abd, rot, u)[:3], axis=-1)

    # root: pelvis tilt (flex), obliquity (abd), rotation (yaw, rot)
    put("pelvis", flex=2 + 2 * intensity * _cos(u, 0.1, 2), abd=4 * intensity * _sin(u, 0.05),
        rot=5 * intensity * _sin(u))
    put("thorax", flex=lean + 1.5 * _cos(u, 0.1, 2), abd=-2 * intensity * _sin(u, 0.05),
        rot=-8 * intensity * _sin(u))
    put("head", flex=-lean + 2 * _cos(u, 0.2, 2), abd=1.5 * _sin(u, 0.1), rot=5 * intensity * _sin(u))
    for side, phase in (("r", 0.0), ("l", 0.5)):
        v = (u + phase) % 1.0
        leg = _leg_curves(action, v)
        put(f"{side}_thigh", leg["hip_flex"], leg["hip_abd"], leg["hip_rot"])
        put(f"{side}_shank", -leg["knee_flex"], 0.0, 2 * _sin(v, 0.1))
        put(f"{side}_foot", 0.0, leg["ankle_inv"], 2 * _sin(v, 0.3))   # flexion: see _with_ankles
        swing = 16 * intensity * _cos(v, 0.55)   # arm swings with the other leg
        put(f"{side}_upperarm", swing, 8 + 2 * _sin(v, 0.25), 3 * _sin(v))
        put(f"{side}_forearm", elbow + 0.5 * swing + 4 * _cos(v, 0.6, 2), 0.0, 4 * _sin(v, 0.2))
        put(f"{side}_hand", 5 + 4 * _sin(v, 0.6), 2 * _sin(v), 0.0)
    return angles


def _to_rotations(clinical: np.ndarray) -> np.ndarray:
    """Clinical (flex, abd, rot) degrees → joint rotation matrices, (frames, segments, 3, 3).

    Applied as intrinsic Y-X-Z (flexion first).  Signs: thigh/upper-arm/forearm
    flexion swings the distal end forward (negative about +Y), trunk and head
    flexion lean forward (positive about +Y), the knee's negative flexion above
    swings the shank back, ankle dorsiflexion lifts the toes (negative about +Y);
    left-side abduction and rotation are mirrored.
    """
    about_y = clinical[..., 0].copy()
    about_x = clinical[..., 1].copy()
    about_z = clinical[..., 2].copy()
    for i, name in enumerate(SEGMENT_NAMES):
        if name in ("pelvis", "thorax", "head"):
            continue
        about_y[:, i] = -about_y[:, i]
        if name.startswith("r_"):           # right abduction moves the limb to −Y
            about_x[:, i] = -about_x[:, i]
        else:                               # left internal rotation turns it to −Y
            about_z[:, i] = -about_z[:, i]
    euler = np.stack([about_y, about_x, about_z], axis=-1).reshape(-1, 3)
    matrices = Rotation.from_euler("YXZ", euler, degrees=True).as_matrix()
    return matrices.reshape(clinical.shape[:-1] + (3, 3))


# --------------------------------------------------------------------------- kinematics

def _offsets(person: Person) -> np.ndarray:
    """Each segment's origin in its parent's frame (neutral pose), (segments, 3) metres."""
    L = person.lengths
    table = {
        "pelvis": (0, 0, 0), "thorax": (0, 0, L["trunk_base"]), "head": (0, 0, L["neck"]),
        "l_upperarm": (0, L["shoulder_width"] / 2, L["shoulder_height"]),
        "r_upperarm": (0, -L["shoulder_width"] / 2, L["shoulder_height"]),
        "l_forearm": (0, 0, -L["upperarm"]), "r_forearm": (0, 0, -L["upperarm"]),
        "l_hand": (0, 0, -L["forearm"]), "r_hand": (0, 0, -L["forearm"]),
        "l_thigh": (0, L["hip_width"] / 2, -L["hip_drop"]),
        "r_thigh": (0, -L["hip_width"] / 2, -L["hip_drop"]),
        "l_shank": (0, 0, -L["thigh"]), "r_shank": (0, 0, -L["thigh"]),
        "l_foot": (0, 0, -L["shank"]), "r_foot": (0, 0, -L["shank"]),
    }
    return np.array([table[name] for name in SEGMENT_NAMES], dtype=float)


def forward_kinematics(joint_rotations: np.ndarray, offsets: np.ndarray,
                       root_translation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Segment frames in the lab from joint rotations.

    Parameters
    ----------
    joint_rotations : (frames, segments, 3, 3)
        R_parent⁻¹ R_child; the root's is its lab orientation.
    offsets : (segments, 3)
        Child origin in the parent frame, metres.
    root_translation : (frames, 3)
        Root origin in the lab, metres.

    Returns
    -------
    rotations : (frames, segments, 3, 3) and origins : (frames, segments, 3) metres.
    """
    frames, segments = joint_rotations.shape[:2]
    rotations = np.empty_like(joint_rotations)
    origins = np.empty((frames, segments, 3))
    for i, parent in enumerate(PARENT_INDEX):   # loop over segments; frames vectorised
        if parent < 0:
            rotations[:, i] = joint_rotations[:, i]
            origins[:, i] = root_translation
        else:
            rotations[:, i] = rotations[:, parent] @ joint_rotations[:, i]
            origins[:, i] = origins[:, parent] + rotations[:, parent] @ offsets[i]
    return rotations, origins


def _foot_points(person: Person) -> dict[str, np.ndarray]:
    """Heel and toe contact points in the foot frame, metres."""
    foot, ankle = person.lengths["foot"], person.lengths["ankle_height"]
    return {"heel": np.array([-0.25 * foot, 0.0, -ankle]),
            "toe": np.array([0.75 * foot, 0.0, -ankle])}


def _contact_points(rotations: np.ndarray, origins: np.ndarray,
                    person: Person) -> dict[str, np.ndarray]:
    points = {}
    for side in "lr":
        i = SEGMENT_NAMES.index(f"{side}_foot")
        for name, local in _foot_points(person).items():
            points[f"{side}_{name}"] = origins[:, i] + rotations[:, i] @ local
    return points


def _planted_root(joint_rotations: np.ndarray, offsets: np.ndarray, person: Person,
                  action: str, times: np.ndarray, cycle_seconds: float) -> np.ndarray:
    """Root translation that keeps the stance foot's lowest point planted, (frames, 3) metres.

    See :func:`mocap.planting.planted_translation`; stair trials then rise or fall
    by two steps per cycle.
    """
    zero = np.zeros((len(times), 3))
    rotations, origins = forward_kinematics(joint_rotations, offsets, zero)
    points = _contact_points(rotations, origins, person)
    root = planted_translation(np.stack(list(points.values()), axis=1), up=2)
    if action in ("ascend", "descend"):
        rise = 2 * STEP_RISE * person.height / 1.75 * (1 if action == "ascend" else -1)
        root[:, 2] += rise * times / cycle_seconds
    return root


def _marker_positions(rotations: np.ndarray, origins: np.ndarray) -> np.ndarray:
    """(frames, segments * 3, 3) marker positions: origin, anterior, left of each segment."""
    anterior = origins + MARKER_SPACING * rotations[..., :, 0]
    left = origins + MARKER_SPACING * rotations[..., :, 1]
    markers = np.stack([origins, anterior, left], axis=2)        # (frames, segments, 3, 3)
    return markers.reshape(origins.shape[0], -1, 3)


# --------------------------------------------------------------------------- trials

def cycle_seconds(person: Person, action: str, seed: int = 0) -> float:
    """Duration of one cycle of ``action`` for ``person``, seconds."""
    interaction = np.random.default_rng([seed, 3, ACTIONS.index(action)]).normal(0, 0.5)
    # the person's cadence scales each action a little differently
    return ACTION_CYCLE_SECONDS[action] * person.cadence ** (1.0 + 0.3 * interaction)


def person_angles(person: Person, action: str, phase: np.ndarray, seed: int = 0) -> np.ndarray:
    """Clinical joint angles of ``person`` doing ``action``, (frames, segments, 3) degrees.

    ``phase`` is the gait-cycle phase (cycles, 0 = right heel strike); it may run
    over several cycles.
    """
    if action not in ACTIONS:
        raise MocapError(f"unknown action {action!r}; known: {', '.join(ACTIONS)}")
    gains, offsets, action_weights = _style_effects(seed)
    weights = person.style * action_weights[ACTIONS.index(action)]        # (styles,)
    gain = 1.0 + np.tensordot(weights, gains, axes=1)                      # (segments, 3)
    offset = np.tensordot(weights, offsets, axes=1)
    u = phase % 1.0
    warped = u - person.timing / (2 * np.pi) * np.sin(2 * np.pi * u)      # stance/swing timing
    template = _action_angles(action, warped)
    left = np.array([name.startswith("l_") for name in SEGMENT_NAMES])
    gain = gain * np.where(left, 1.0 + person.asymmetry, 1.0)[:, None]
    return _with_ankles(offset + gain * template, action, warped)


def synthesize_trial(person: int | Person, action: str, seed: int = 0, people: int = 6,
                     rate: float = 100.0, cycles: float = 1.0, noise_mm: float = 0.0,
                     gap_fraction: float = 0.0) -> tuple[Trial, GroundTruth]:
    """One synthetic trial and its ground truth.

    Parameters
    ----------
    person : int or Person
        Index into ``make_people(people, seed)`` or a Person.
    action : str
        One of ``ACTIONS``.
    seed : int
        Seeds people, styles, noise and gaps: same seed, same trial.
    people : int
        Size of the population ``person`` indexes.
    rate : float
        Sampling rate, Hz.
    cycles : float
        Number of gait cycles in the trial; one cycle spans exactly one period
        (the last sample falls one sample before the next heel strike).
    noise_mm : float
        Standard deviation of Gaussian marker noise, millimetres.
    gap_fraction : float
        About this fraction of marker samples is removed as gaps of 3–30 frames.

    Returns
    -------
    trial : Trial
        Markers in metres, labels ``MARKER_LABELS``.
    truth : GroundTruth
    """
    if isinstance(person, int):
        population = make_people(max(people, person + 1), seed)
        person = population[person]
    if rate <= 0 or cycles <= 0:
        raise MocapError(f"rate and cycles must be positive (got {rate}, {cycles})")
    period = cycle_seconds(person, action, seed)
    frames = max(int(round(cycles * period * rate)), 2)
    times = np.arange(frames) / rate
    clinical = person_angles(person, action, times / period, seed)
    joint_rotations = _to_rotations(clinical)
    offsets = _offsets(person)
    root = _planted_root(joint_rotations, offsets, person, action, times, period)
    rotations, origins = forward_kinematics(joint_rotations, offsets, root)
    points = _marker_positions(rotations, origins)
    rng = np.random.default_rng([seed, 4, ACTIONS.index(action), sum(map(ord, person.name))])
    if noise_mm > 0:
        points = points + rng.normal(0.0, noise_mm / 1000.0, size=points.shape)
    if gap_fraction > 0:
        points = _add_gaps(points, gap_fraction, rng)
    trial = Trial(list(MARKER_LABELS), points, rate, units="m", format="synthetic",
                  metadata={"person": person.name, "action": action, "generator": "mocap.synthetic",
                            "cycle_seconds": period})
    truth = GroundTruth(joint_rotations, rotations, origins, offsets,
                        _contact_points(rotations, origins, person), rate, person.name, action,
                        period)
    return trial, truth


def _add_gaps(points: np.ndarray, fraction: float, rng: np.random.Generator) -> np.ndarray:
    """Blank random runs of 3–30 frames in random markers until ``fraction`` is missing."""
    points = points.copy()
    frames, markers = points.shape[:2]
    target = fraction * frames * markers
    missing = 0
    while missing < target:
        length = int(rng.integers(3, min(30, max(frames - 1, 4))))
        start = int(rng.integers(0, max(frames - length, 1)))
        marker = int(rng.integers(0, markers))
        before = np.isnan(points[start:start + length, marker, 0]).sum()
        points[start:start + length, marker] = np.nan
        missing += length - before
    return points


# --------------------------------------------------------------------------- corpus

def truth_angles(truth: GroundTruth, sequence: str = "ZXY"):
    """Ground-truth joint angles of a trial in ``sequence``, as a :class:`mocap.angles.JointAngles`."""
    from mocap.angles import matrices_to_angles, JointAngles

    values = matrices_to_angles(truth.rotations, sequence)
    times = np.arange(truth.rotations.shape[0]) / truth.rate
    return JointAngles(times=times, values=values, segments=list(SEGMENT_NAMES),
                       sequence=sequence, parents=list(PARENT_INDEX))


def generate_corpus(out_dir: str | Path, people: int = 6, actions: Sequence[str] = ACTIONS,
                    seed: int = 0, noise_mm: float = 0.0, gap_fraction: float = 0.0,
                    cycles: float = 1.0, rate: float = 100.0, sequence: str = "ZXY",
                    file_format: str = "c3d", show_progress: bool | None = None) -> list[Path]:
    """Write a people × actions corpus of marker trials with ground truth.

    Writes ``<person>_<action>.<file_format>`` marker files into ``out_dir`` and the
    exact joint angles as ``truth/<person>_<action>_angles.csv`` (DESIGN 3.2 angle CSV,
    ``sequence``), plus ``truth/people.csv`` with each person's signature
    parameters (height m, cadence, timing, asymmetry, style factors).

    Parameters
    ----------
    out_dir : path
        Created if needed.
    people : int
        Number of people (at least 1).
    actions : sequence of str
        Subset of ``ACTIONS``.
    seed, noise_mm, gap_fraction, cycles, rate
        As in :func:`synthesize_trial`.
    sequence : str
        Euler sequence of the ground-truth CSVs.
    file_format : {"c3d", "trc", "csv"}
    show_progress : bool, optional
        Progress bar on stderr (default: when stderr is a terminal).

    Returns
    -------
    list of Path
        The marker files written, person-major.
    """
    from mocap import io
    from mocap.angles import write_angles_csv
    from mocap.atomic import atomic_path
    from mocap.progress import progress

    unknown = [a for a in actions if a not in ACTIONS]
    if unknown:
        raise MocapError(f"unknown action(s) {', '.join(unknown)}; known: {', '.join(ACTIONS)}")
    if not actions:
        raise MocapError("need at least one action")
    if file_format not in ("c3d", "trc", "csv"):
        raise MocapError(f"unknown marker file format {file_format!r}; use c3d, trc or csv")
    out_dir = Path(out_dir)
    truth_dir = out_dir / "truth"
    truth_dir.mkdir(parents=True, exist_ok=True)
    population = make_people(people, seed)
    written = []
    cells = [(person, action) for person in population for action in actions]
    for person, action in progress(cells, "generating trials", enabled=show_progress):
        trial, truth = synthesize_trial(person, action, seed=seed, rate=rate, cycles=cycles,
                                        noise_mm=noise_mm, gap_fraction=gap_fraction)
        path = out_dir / f"{person.name}_{action}.{file_format}"
        io.write(trial, path)
        write_angles_csv(truth_angles(truth, sequence), truth_dir / f"{person.name}_{action}_angles.csv")
        written.append(path)
    with atomic_path(truth_dir / "people.csv") as tmp:
        header = "person,height_m,cadence,timing,asymmetry," + ",".join(
            f"style{k + 1}" for k in range(_STYLES))
        rows = [f"{p.name},{p.height:.4f},{p.cadence:.4f},{p.timing:.4f},{p.asymmetry:.4f},"
                + ",".join(f"{s:.4f}" for s in p.style) for p in population]
        tmp.write_text("\n".join([header] + rows) + "\n")
    return written
