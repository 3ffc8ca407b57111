"""Synthetic marker data: people × actions with ground-truth joint angles.

Each person has a *motion signature*: body size and proportions, cadence, a few
latent style factors that move the gait (stride, step width, toe-out, foot pitch at
landing and push-off, step clearance, knee flexion in stance, heel-rise timing) and
scale and offset the trunk, arm and head curves (interacting with the action: a
long-striding walker is not a long-striding stair climber in the same proportion), a
stance/swing timing shift and a left/right asymmetry.

The motion is built the way a body has to move, so that it is physically plausible:

1. **Feet.**  Each foot lands (heel first; toe first down stairs) at its place on the
   floor or on a stair tread, rolls flat, stays still while it carries the body, rolls
   over the toe and swings to the next place along quintic curves that match the
   rockers' position, velocity and acceleration and clear the floor (or the nosing).
2. **Centre of mass.**  It rides the centre of pressure, which rolls from heel to toe
   under each foot and passes from foot to foot in double support, like an inverted
   pendulum: the periodic solution of x'' = k(t)(x − p(t)) + L'(t)/h(t), where the last
   term is what the body's turning (the rate of its angular momentum about the centre of
   mass, from the posture) asks of the floor's force, so the floor can supply every
   acceleration and every moment.  Its height is what the supporting leg gives at
   its nominal knee flexion (walking, stairs: loading response, nearly straight in
   mid-stance), smoothed and kept within reach, or a spring-mass bounce with a
   ballistic flight phase (running).  The root follows from the centre of mass and the
   posture (segment masses after de Leva).
3. **Legs.**  Two-link inverse kinematics in 3-D gives hip flexion and abduction and
   the knee from the hip-to-ankle vector; the hip's axial rotation keeps the ankle's
   axial rotation at its template; the ankle takes the foot's orientation.  The heel
   rises during push-off as much as the knee's nominal flexion asks.

Stance feet are planted exactly (no skating, no penetration); the floor is flat for
walk and run, a staircase of ``STEP_RISE`` × ``STEP_GOING`` steps for ascend and descend
(two steps per cycle).  Measured with :func:`dynamics.humanoid.check_motion`, the default
people's walks need a residual force of 0.2–0.6 % body weight RMS (captured walks:
5–10 %; over 24 people of two seeds the median is 0.6 %, the worst, extreme styles, 8 %),
their runs 6–10 %, nearly all of it around the short flight phases, which the check's
0.1 s smoothing window blurs into the stance.

Forward kinematics puts three markers on each of the 15 segments of the
``synthetic15`` marker set (origin at the proximal joint centre, one marker
0.10 m anterior, one 0.10 m to the left), in a Z-up lab facing +X.

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
    "thigh": 0.43, "shank": 0.43, "ankle_height": 0.0817, "foot": 0.2293,
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
        Stance/swing timing: shifts heel rise and toe-off by ``0.04 * timing`` cycles
        (about ±0.15).
    asymmetry : float
        Relative extra amplitude of the left side: foot pitches, clearance, step length
        and the left limbs' template curves (about ±0.08).
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
            factor = scale * (leg if key in ("thigh", "shank", "foot", "ankle_height") else
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
    gains = rng.normal(0.0, 0.12, size=(_STYLES,) + _DOFS)
    offsets = rng.normal(0.0, 3.5, size=(_STYLES,) + _DOFS)
    action_weights = rng.uniform(0.6, 1.4, size=(len(ACTIONS), _STYLES))
    return gains, offsets, action_weights


# --------------------------------------------------------------------------- templates

def _bump(u: np.ndarray, centre: float, width: float) -> np.ndarray:
    """Periodic bump on the unit cycle: 1 at ``centre``, about Gaussian with std ``width``."""
    return np.exp((np.cos(2 * np.pi * (u - centre)) - 1.0) / (2 * np.pi * width) ** 2)


def _cos(u: np.ndarray, shift: float = 0.0, harmonic: int = 1) -> np.ndarray:
    return np.cos(2 * np.pi * harmonic * (u - shift))


def _sin(u: np.ndarray, shift: float = 0.0, harmonic: int = 1) -> np.ndarray:
    return np.sin(2 * np.pi * harmonic * (u - shift))


def _stance_knee(action: str, u: np.ndarray) -> np.ndarray:
    """Knee flexion (degrees) the supporting leg aims for over its phase ``u`` (0 = its
    landing); it sets the pelvis height while that leg leads the support."""
    if action == "walk":      # loading response peak, nearly straight in mid-stance
        return 4 + 14 * _bump(u, 0.14, 0.06) + 56 * _bump(u, 0.71, 0.09)
    if action == "run":
        return 18 + 24 * _bump(u, 0.17, 0.06)
    if action == "ascend":    # lands bent on the higher step, then straightens
        return 12 + 48 * _bump(u, 0.0, 0.08) + 80 * _bump(u, 0.73, 0.09)
    return 8 + 78 * _bump(u, 0.55, 0.13) + 22 * _bump(u, 0.86, 0.06)    # descend: lowers


def _action_angles(action: str, u: np.ndarray) -> np.ndarray:
    """Template joint angles of an action: (frames, segments, 3) = (flex, abd, rot) degrees.

    Flexion is about the segment's left axis (e2), abduction about its anterior
    axis (e1), axial rotation about its up axis (e3), in clinical sign
    (flexion, abduction and internal rotation positive on both sides).  Hip, knee
    and ankle flexion and abduction are zero here: they follow from the feet by
    inverse kinematics (:func:`_leg_rotations`); the knee and ankle axial rotations
    are targets for it.  Phase 0 is the right foot's landing: the pelvis is turned
    with the right hip forward and the right arm back.
    """
    intensity = {"walk": 1.0, "run": 1.8, "ascend": 1.2, "descend": 1.0}[action]
    lean = {"walk": 3.0, "run": 10.0, "ascend": 9.0, "descend": 2.0}[action]
    elbow = {"walk": 20.0, "run": 85.0, "ascend": 25.0, "descend": 18.0}[action]
    angles = np.zeros(u.shape + _DOFS)
    index = {name: i for i, name in enumerate(SEGMENT_NAMES)}

    def put(segment: str, flex=0.0, abd=0.0, rot=0.0) -> None:
        angles[:, index[segment]] = np.stack(np.broadcast_arrays(flex, abd, rot, u)[:3], axis=-1)

    # root: pelvis tilt (flex), obliquity (abd: the swing side drops), rotation (yaw)
    put("pelvis", flex=2 + 2 * intensity * _cos(u, 0.1, 2), abd=-4 * intensity * _sin(u, 0.05),
        rot=5 * intensity * _cos(u))
    put("thorax", flex=lean + 1.5 * _cos(u, 0.1, 2), abd=2 * intensity * _sin(u, 0.05),
        rot=-8 * intensity * _cos(u))          # counter-rotates the pelvis
    put("head", flex=-lean + 2 * _cos(u, 0.2, 2), abd=1.5 * _sin(u, 0.1),
        rot=3 * intensity * _cos(u))           # keeps the gaze forward
    for side, phase in (("r", 0.0), ("l", 0.5)):
        v = (u + phase) % 1.0
        put(f"{side}_shank", 0.0, 0.0, 2 * _sin(v, 0.1))
        put(f"{side}_foot", 0.0, 0.0, 2 * _sin(v, 0.3))
        swing = 16 * intensity * _cos(v, 0.55)   # arm swings with the other leg
        put(f"{side}_upperarm", swing, 8 + 2 * _sin(v, 0.25), 3 * _sin(v))
        put(f"{side}_forearm", elbow + 0.5 * swing + 4 * _cos(v, 0.6, 2), 0.0, 4 * _sin(v, 0.2))
        put(f"{side}_hand", 5 + 4 * _sin(v, 0.6), 2 * _sin(v), 0.0)
    return angles


#: Sign of (about +Y, about +X, about +Z) per segment for clinical (flex, abd, rot): limb
#: flexion swings the distal end forward (negative about +Y), trunk and head flexion lean
#: forward (positive about +Y), right abduction moves the limb to −Y, left internal
#: rotation turns it to −Y.
_CLINICAL_SIGNS = np.array([
    (1.0, 1.0, 1.0) if name in ("pelvis", "thorax", "head") else
    (-1.0, -1.0, 1.0) if name.startswith("r_") else (-1.0, 1.0, -1.0)
    for name in SEGMENT_NAMES])


def _to_rotations(clinical: np.ndarray) -> np.ndarray:
    """Clinical (flex, abd, rot) degrees → joint rotation matrices, (frames, segments, 3, 3).

    Applied as intrinsic Y-X-Z (flexion first), signs per ``_CLINICAL_SIGNS``: the knee's
    negative flexion swings the shank back, ankle dorsiflexion lifts the toes.
    """
    euler = (clinical * _CLINICAL_SIGNS).reshape(-1, 3)
    matrices = Rotation.from_euler("YXZ", euler, degrees=True).as_matrix()
    return matrices.reshape(clinical.shape[:-1] + (3, 3))


def _to_clinical(rotations: np.ndarray, segment: int) -> np.ndarray:
    """Inverse of :func:`_to_rotations` for one segment: (frames, 3, 3) → (frames, 3) degrees."""
    euler = Rotation.from_matrix(rotations).as_euler("YXZ", degrees=True)
    return euler * _CLINICAL_SIGNS[segment]


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


def _marker_positions(rotations: np.ndarray, origins: np.ndarray) -> np.ndarray:
    """(frames, segments * 3, 3) marker positions: origin, anterior, left of each segment."""
    anterior = origins + MARKER_SPACING * rotations[..., :, 0]
    left = origins + MARKER_SPACING * rotations[..., :, 1]
    markers = np.stack([origins, anterior, left], axis=2)        # (frames, segments, 3, 3)
    return markers.reshape(origins.shape[0], -1, 3)


#: Segment mass fractions and centres of mass (fraction of the segment's length along its
#: long axis from the proximal joint), after de Leva (1996, male); the trunk is split into
#: the pelvis (lower trunk) and the thorax (middle and upper trunk).
_MASS = {"pelvis": (0.1117, 0.0), "thorax": (0.3229, 0.5), "head": (0.0694, 0.5),
         "upperarm": (0.0271, 0.577), "forearm": (0.0162, 0.457), "hand": (0.0061, 0.4),
         "thigh": (0.1416, 0.41), "shank": (0.0433, 0.446), "foot": (0.0137, 0.44)}


def _mass_model(person: Person) -> tuple[np.ndarray, np.ndarray]:
    """Mass fractions (segments,) summing to 1 and centres of mass in the segment frames
    (segments, 3), metres."""
    L = person.lengths
    down = {"upperarm": L["upperarm"], "forearm": L["forearm"], "hand": L["hand"],
            "thigh": L["thigh"], "shank": L["shank"]}
    fractions, centres = [], []
    for name in SEGMENT_NAMES:
        kind = name.split("_")[-1]
        fraction, along = _MASS[kind]
        if kind == "thorax":
            centre = (0.0, 0.0, along * L["neck"])
        elif kind == "head":
            centre = (0.0, 0.0, along * L["head"])
        elif kind == "pelvis":
            centre = (0.0, 0.0, -0.3 * L["hip_drop"])
        elif kind == "foot":
            centre = ((along - 0.25) * L["foot"], 0.0, -0.5 * L["ankle_height"])
        else:
            centre = (0.0, 0.0, -along * down[kind])
        fractions.append(fraction)
        centres.append(centre)
    fractions = np.array(fractions)
    return fractions / fractions.sum(), np.array(centres)


def _centre_of_mass(rotations: np.ndarray, origins: np.ndarray, person: Person) -> np.ndarray:
    """Whole-body centre of mass, (frames, 3) metres, from segment poses in the lab."""
    fractions, centres = _mass_model(person)
    points = origins + np.einsum("fsij,sj->fsi", rotations, centres)
    return np.einsum("s,fsi->fi", fractions, points)


def _turning_rate(rotations: np.ndarray, origins: np.ndarray, person: Person,
                  period: float, advance: np.ndarray) -> np.ndarray:
    """Rate of change of the body's angular momentum about its centre of mass, per unit
    body mass, (N, 3) m²/s², over one cycle sampled uniformly (segments as point masses;
    positions advance by ``advance`` per cycle)."""
    fractions, centres = _mass_model(person)
    n = len(origins)
    points = origins + np.einsum("fsij,sj->fsi", rotations, centres)
    trend = np.outer(np.arange(n) / n, advance)[:, None, :]
    omega = 2j * np.pi * np.fft.rfftfreq(n, d=period / n)
    velocity = np.fft.irfft(omega[:, None, None] * np.fft.rfft(points - trend, axis=0), n,
                            axis=0) + advance / period
    centre = np.einsum("s,fsi->fi", fractions, points)
    drift = np.einsum("s,fsi->fi", fractions, velocity)
    momentum = np.einsum("s,fsi->fi", fractions, np.cross(points - centre[:, None],
                                                          velocity - drift[:, None]))
    return np.fft.irfft(omega[:, None] * np.fft.rfft(momentum, axis=0), n, axis=0)


# --------------------------------------------------------------------------- gait

#: Depth of one stair tread, metres (the right foot lands on even steps, the left on odd).
STEP_GOING = 0.28

#: Nominal gait of each action.  ``stride`` is per leg length (thigh + shank + ankle
#: height) on the flat; phases are fractions of the cycle from the foot's landing:
#: ``landed`` foot flat, ``heel_rise``, ``toe_off``; pitches are of the foot in the lab,
#: degrees, toes up positive; ``clearance`` of the swinging foot over the floor (or the
#: nosing of the step it passes), metres; ``lift`` the least rise of the swing (metres at
#: mid-swing: a walking foot is picked up well clear, the knee bending to about 60 degrees);
#: ``width`` between the feet's long axes, metres;
#: ``toe_out`` degrees; ``knee_min`` the least knee flexion of a supporting leg, degrees.
_GAITS = {
    "walk": dict(stride=1.50, landed=0.08, heel_rise=0.30, toe_off=0.62, land_pitch=17.0,
                 off_pitch=-55.0, clearance=0.015, lift=0.06, width=0.10, toe_out=6.0,
                 knee_min=3.0),
    "run": dict(stride=2.45, landed=0.07, heel_rise=0.15, toe_off=0.36, land_pitch=8.0,
                off_pitch=-38.0, clearance=0.05, lift=0.0, width=0.05, toe_out=5.0,
                knee_min=16.0),
    "ascend": dict(stride=0.0, landed=0.05, heel_rise=0.42, toe_off=0.64, land_pitch=3.0,
                   off_pitch=-25.0, clearance=0.03, lift=0.0, width=0.12, toe_out=8.0,
                   knee_min=4.0),
    "descend": dict(stride=0.0, landed=0.10, heel_rise=0.40, toe_off=0.62, land_pitch=-18.0,
                    off_pitch=-22.0, clearance=0.03, lift=0.0, width=0.12, toe_out=8.0,
                    knee_min=4.0),
}

#: How much one unit of (action-weighted) style moves each gait parameter: relative
#: change for lengths, gains and pitches; degrees for ``toe_out``; cycles for ``heel_rise``.
_GAIT_STYLE_SCALE = {"stride": 0.035, "width": 0.15, "toe_out": 2.5, "land_pitch": 0.12,
                     "off_pitch": 0.10, "clearance": 0.20, "knee": 0.08, "heel_rise": 0.02}


@dataclass(frozen=True)
class _Gait:
    """Gait of one person doing one action: what the feet do, and how.

    Lengths in metres, angles in degrees, phases in cycles from the right foot's landing;
    pairs are (right, left).
    """

    action: str
    period: float
    advance: np.ndarray        # (3,) displacement of each foot per cycle
    placement: tuple           # heel position of each foot at its landing in cycle 0
    phase: tuple               # landing phase of each foot
    yaw: tuple                 # foot heading, degrees (toe out)
    landed: float
    heel_rise: float
    toe_off: float
    land_pitch: tuple
    off_pitch: tuple
    clearance: tuple
    lift: tuple                # least lift of the swing at mid-swing, metres
    land_on_toe: bool
    knee_gain: float
    knee_min: float
    tread: float               # stair tread depth (0 on the flat)
    step_rise: float           # signed rise of one step (0 on the flat)


def _gait_style_effects(seed: int) -> np.ndarray:
    """Per-style effect on each gait parameter, (styles, parameters) in the units of
    ``_GAIT_STYLE_SCALE``."""
    rng = np.random.default_rng([seed, 5])
    scale = np.array(list(_GAIT_STYLE_SCALE.values()))
    return rng.normal(0.0, 1.0, size=(_STYLES, len(scale))) * scale


def _gait(person: Person, action: str, seed: int = 0) -> _Gait:
    """The gait parameters of ``person`` doing ``action``."""
    nominal = _GAITS[action]
    _, _, action_weights = _style_effects(seed)
    weights = person.style * action_weights[ACTIONS.index(action)]
    scale = np.array(list(_GAIT_STYLE_SCALE.values()))
    # linear for usual styles, saturating at two scales for extreme ones
    raw = weights @ _gait_style_effects(seed)
    effect = dict(zip(_GAIT_STYLE_SCALE, 2 * scale * np.tanh(raw / (2 * scale))))
    L = person.lengths
    leg = L["thigh"] + L["shank"] + L["ankle_height"]
    left = 1.0 + person.asymmetry
    heel_rise = nominal["heel_rise"] + 0.04 * person.timing + effect["heel_rise"]
    toe_off = nominal["toe_off"] + 0.04 * person.timing
    width = nominal["width"] * (1 + effect["width"]) * person.height / 1.75
    toe_out = nominal["toe_out"] + effect["toe_out"]
    if action in ("ascend", "descend"):
        sign = 1.0 if action == "ascend" else -1.0
        tread, step_rise = STEP_GOING, sign * STEP_RISE
        # the foot in the middle of the tread, or back from the riser when going up
        margin = (0.25 if action == "ascend" else 0.5) * (tread - L["foot"])
        advance = np.array([2 * tread, 0.0, 2 * step_rise])
        placements = ((margin, -width / 2, 0.0), (margin + tread, width / 2, step_rise))
    else:
        tread, step_rise = 0.0, 0.0
        stride = nominal["stride"] * leg * (1 + effect["stride"])
        advance = np.array([stride, 0.0, 0.0])
        placements = ((0.0, -width / 2, 0.0), ((0.5 + 0.1 * person.asymmetry) * stride,
                                                width / 2, 0.0))
    land = nominal["land_pitch"] * (1 + effect["land_pitch"])
    push = nominal["off_pitch"] * (1 + effect["off_pitch"])
    clear = nominal["clearance"] * (1 + effect["clearance"])
    return _Gait(
        action=action, period=cycle_seconds(person, action, seed), advance=advance,
        placement=tuple(np.array(p) for p in placements), phase=(0.0, 0.5),
        yaw=(-toe_out, toe_out), landed=nominal["landed"],
        heel_rise=float(np.clip(heel_rise, nominal["landed"] + 0.04, toe_off - 0.06)),
        toe_off=toe_off, land_pitch=(land, land * left), off_pitch=(push, push * left),
        clearance=(clear, clear * left),
        lift=(nominal["lift"] * leg / 0.94,) * 2,
        land_on_toe=action == "descend",
        knee_gain=float(np.clip(1.0 + effect["knee"], 0.8, 1.25)),
        knee_min=nominal["knee_min"] * float(np.clip(1.0 + effect["knee"], 0.8, 1.25)),
        tread=tread, step_rise=step_rise)


def _foot_rotation(yaw: float, pitch: np.ndarray) -> np.ndarray:
    """Foot frame in the lab: heading ``yaw``, toes up by ``pitch``; (frames, 3, 3)."""
    angles = np.stack(np.broadcast_arrays(yaw, -pitch), axis=-1)
    return Rotation.from_euler("ZY", angles, degrees=True).as_matrix()


def _quintic(start: tuple, end: tuple, duration: float, s: np.ndarray) -> np.ndarray:
    """Quintic Hermite curve matching position, velocity and acceleration at both ends.

    ``start`` and ``end`` are (value, rate, acceleration) per unit phase, each (dims,);
    ``s`` (frames,) runs over [0, 1] in ``duration`` cycles; returns (frames, dims).
    """
    s = s[:, None]
    basis = (1 - 10 * s**3 + 15 * s**4 - 6 * s**5, s - 6 * s**3 + 8 * s**4 - 3 * s**5,
             0.5 * s**2 - 1.5 * s**3 + 1.5 * s**4 - 0.5 * s**5,
             0.5 * s**3 - s**4 + 0.5 * s**5, -4 * s**3 + 7 * s**4 - 3 * s**5,
             10 * s**3 - 15 * s**4 + 6 * s**5)
    (p0, v0, a0), (p1, v1, a1) = start, end
    return (basis[0] * p0 + basis[1] * v0 * duration + basis[2] * a0 * duration**2
            + basis[3] * a1 * duration**2 + basis[4] * v1 * duration + basis[5] * p1)


def _lift(s: np.ndarray) -> np.ndarray:
    """Swing lift profile: 0 with zero rate and acceleration at both ends, 1 at mid-swing."""
    return 64.0 * (s * (1.0 - s)) ** 3


def _floor_height(gait: _Gait, x: np.ndarray) -> np.ndarray:
    """Height of the floor (stairs: the step) at forward distance ``x`` from a foot's
    landing heel position, metres."""
    if gait.tread == 0.0:
        return np.zeros_like(x)
    margin = gait.placement[0][0]
    return gait.step_rise * np.floor((x + margin) / gait.tread)


_MID_SWING = 0.4   # fraction of the swing where the foot passes level


class _FootPath:
    """The lab trajectory of one foot over its cycle, relative to its landing heel position.

    Stance: a landing rocker about the heel (toe for stair descent) from the landing pitch
    to flat, the foot flat and still, then a push-off rocker about the toe; swing: quintic
    Hermite curves (ankle position and foot pitch) matching the rockers' position, rate
    and acceleration at toe-off and at the next landing, lifted enough to clear the floor.
    """

    def __init__(self, gait: _Gait, person: Person, side: int):
        self.gait, self.side, self.person = gait, side, person
        points = _foot_points(person)
        self.heel, self.toe = points["heel"], points["toe"]
        self.flat = _foot_rotation(gait.yaw[side], np.zeros(1))[0]
        self.pivot = self.toe if gait.land_on_toe else self.heel
        self.hip = None
        self._plan_swing()

    def follow(self, hip) -> None:
        """Let the push-off follow the body: ``hip(u)`` gives the hip joint centre (frames, 3)
        relative to the landing heel position at this foot's phase ``u``.  The heel then
        rises as much as the knee's nominal flexion asks, rather than by a fixed profile."""
        self.hip = hip
        self._plan_swing()

    def _plan_swing(self) -> None:
        """Swing boundary states by one-sided differences of the rockers, per unit phase."""
        g, step = self.gait, 1e-4
        self.lift = 0.0
        off = [self._push(np.array([g.toe_off - k * step])) for k in range(3)]
        land = [self._landing(np.array([k * step])) for k in range(3)]
        self.start = self._state(off, -step)
        self.end = self._state(land, step, shift=g.advance)
        self.lift = self._needed_lift(self.person)

    @staticmethod
    def _state(samples, step, shift=np.zeros(3)):
        """(value, rate, acceleration) of [ankle xyz, pitch] from three samples ``step`` apart."""
        f = [np.concatenate([ankle[0] + shift, pitch]) for ankle, pitch in samples]
        rate = (-3 * f[0] + 4 * f[1] - f[2]) / (2 * step)
        return f[0], rate, (f[0] - 2 * f[1] + f[2]) / step**2

    def _rocker(self, pivot: np.ndarray, pitch: np.ndarray) -> np.ndarray:
        """Ankle positions that keep the foot point ``pivot`` where it is when flat."""
        rotation = _foot_rotation(self.gait.yaw[self.side], pitch)
        return self.flat @ (pivot - self.heel) - rotation @ pivot

    def _landing(self, u):
        s = u / self.gait.landed
        # walking: the foot comes down gently (half the rate at contact of the quick
        # roll of a running foot, which keeps the run's short stance smooth)
        ease = (1 + s) if self.gait.toe_off > 0.5 else 1.0
        pitch = self.gait.land_pitch[self.side] * (1 - s) ** 2 * ease
        return self._rocker(self.pivot, pitch), pitch

    def _push(self, u):
        g = self.gait
        s = (u - g.heel_rise) / (g.toe_off - g.heel_rise)
        pitch = g.off_pitch[self.side] * s**2
        if self.hip is not None and len(u):
            # Pitch about the toe that puts the ankle at the nominal knee's leg length
            # from the hip: |h − t + R(φ) r| = d, i.e. A cos φ + B sin φ = C in the foot's
            # heading (φ about the left axis, toes down positive).
            knee = np.maximum(g.knee_gain * _stance_knee(g.action, u), g.knee_min)
            length = _leg_length(self.person, knee)
            toe = self.flat @ (self.toe - self.heel)
            q = (self.hip(u) - toe) @ self.flat                  # in the foot heading
            r = self.toe
            a = q[:, 0] * r[0] + q[:, 2] * r[2]
            b = q[:, 0] * r[2] - q[:, 2] * r[0]
            c = 0.5 * (length**2 - (q**2).sum(axis=1) - r @ r)
            spread = np.arccos(np.clip(c / np.hypot(a, b), -1.0, 1.0))
            roots = [-np.degrees((np.arctan2(b, a) + sign * spread + np.pi) % (2 * np.pi) - np.pi)
                     for sign in (-1.0, 1.0)]
            solved = np.where(np.abs(roots[0] - pitch) < np.abs(roots[1] - pitch), *roots)
            # within about 30 degrees of the nominal profile (soft limit), never heel down
            solved = pitch + 30.0 * np.tanh((solved - pitch) / 30.0)
            # eased in after heel rise and out before toe-off (the swing starts nominally)
            blend = _smoothstep(3 * s) * (1 - _smoothstep((s - 0.6) / 0.4))
            pitch = np.minimum((1 - blend) * pitch + blend * solved, 0.0)
        return self._rocker(self.toe, pitch), pitch

    def _swing(self, u, lift):
        g = self.gait
        duration = 1.0 - g.toe_off
        s = (u - g.toe_off) / duration
        curve = _quintic(self.start, self.end, duration, s)
        # The foot pitch passes level at mid-swing rather than overshooting toe-off's.
        rate = (self.end[0][3] - self.start[0][3]) / duration
        middle = (np.array([-5.0]), np.array([rate]), np.zeros(1))
        first = s < _MID_SWING
        start, end = [tuple(x[3:] for x in state) for state in (self.start, self.end)]
        curve[first, 3] = _quintic(start, middle, _MID_SWING * duration,
                                   s[first] / _MID_SWING)[:, 0]
        curve[~first, 3] = _quintic(middle, end, (1 - _MID_SWING) * duration,
                                    (s[~first] - _MID_SWING) / (1 - _MID_SWING))[:, 0]
        if g.tread > 0:      # stairs: up before over the next step; over before down
            lead = -0.3 if g.step_rise > 0 else 0.3
            curve[:, 0] = _quintic(self.start, self.end, duration, s + lead * _lift(s))[:, 0]
        ankle = curve[:, :3]
        ankle[:, 2] += lift * _lift(s)
        return ankle, curve[:, 3]

    def _needed_lift(self, person: Person) -> float:
        """Lift of the swing (metres at mid-swing) for the clearance over the floor below."""
        g = self.gait
        # clearance in mid-swing; on the flat, at least not below the floor throughout
        # (leaving and reaching a stair tread is the rockers' job)
        s = np.linspace(0.02, 0.98, 97) if g.tread == 0 else np.linspace(0.25, 0.75, 51)
        wanted = np.where((s >= 0.25) & (s <= 0.75), g.clearance[self.side], 0.0)
        ankle, pitch = self._swing(g.toe_off + s * (1 - g.toe_off), 0.0)
        rotation = _foot_rotation(g.yaw[self.side], pitch)
        profile = _lift(s)
        need = 0.0
        for point in (self.heel, self.toe):
            where = ankle + rotation @ point
            height = where[:, 2] - _floor_height(g, where[:, 0])
            need = max(need, float(np.max(wanted - height / profile)))
        leg = person.lengths["thigh"] + person.lengths["shank"]
        return min(max(need, g.lift[self.side]), 0.25 * leg)

    def pose(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Ankle position relative to the landing heel position (frames, 3) and foot pitch
        (frames,) degrees at phase ``u`` ∈ [0, 1) from the landing."""
        g = self.gait
        ankle = np.empty(u.shape + (3,))
        pitch = np.zeros(u.shape)
        pieces = (u < g.landed, (u >= g.landed) & (u < g.heel_rise),
                  (u >= g.heel_rise) & (u < g.toe_off), u >= g.toe_off)
        ankle[pieces[0]], pitch[pieces[0]] = self._landing(u[pieces[0]])
        ankle[pieces[1]] = -self.flat @ self.heel
        ankle[pieces[2]], pitch[pieces[2]] = self._push(u[pieces[2]])
        ankle[pieces[3]], pitch[pieces[3]] = self._swing(u[pieces[3]], self.lift)
        return ankle, pitch

    def in_lab(self, phase: np.ndarray, pace: float = 1.0) -> dict[str, np.ndarray]:
        """The foot at ``phase`` (cycles from the right foot's landing; any range).

        Returns ``ankle`` (frames, 3), ``rotation`` (frames, 3, 3), ``u`` (frames,) phase
        from this foot's landing, ``heel`` and ``toe`` contact points (frames, 3),
        ``along`` (frames,) how far from heel (0) to toe (1) it presses on the floor, and
        ``cop`` (frames, 3) that point, with ``along`` raised to the power ``pace`` (below
        1 the pressure rolls forward sooner).
        """
        g = self.gait
        local = phase - g.phase[self.side]
        cycle = np.floor(local)
        u = local - cycle
        ankle, pitch = self.pose(u)
        ankle = ankle + g.placement[self.side] + cycle[:, None] * g.advance
        rotation = _foot_rotation(g.yaw[self.side], pitch)
        heel, toe = ankle + rotation @ self.heel, ankle + rotation @ self.toe
        if g.land_on_toe:      # forefoot landing: the pressure goes back, then forward again
            along = 1.0 - 0.5 * np.sin(np.pi * np.clip(u / g.heel_rise, 0.0, 1.0))
        else:                  # heel to ball by heel rise, to the toe by toe-off
            along = 0.75 * _smoothstep(u / g.heel_rise) + 0.25 * _smoothstep(
                (u - g.heel_rise) / (g.toe_off - g.heel_rise))
        return {"ankle": ankle, "rotation": rotation, "u": u, "heel": heel, "toe": toe,
                "along": along, "cop": heel + along[:, None] ** pace * (toe - heel)}


def _smoothstep(s: np.ndarray) -> np.ndarray:
    """0 → 1 with zero rate and acceleration at both ends (clipped outside [0, 1])."""
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10 - 15 * s + 6 * s**2)


def _loads(gait: _Gait, u: np.ndarray) -> np.ndarray:
    """Share of the body weight on a foot at its phase ``u``: 1 in single support, handed
    over smoothly in double support, 0 in swing; (frames,)."""
    overlap = gait.toe_off - 0.5
    load = (u < gait.toe_off).astype(float)
    if overlap > 0:
        load = np.where(u < overlap, _smoothstep(u / overlap), load)
        load = np.where((u >= 0.5) & (u < gait.toe_off),
                        1.0 - _smoothstep((u - 0.5) / overlap), load)
    return load


def _leg_length(person: Person, knee: np.ndarray | float) -> np.ndarray:
    """Hip-to-ankle distance with the knee flexed by ``knee`` degrees, metres."""
    t, s = person.lengths["thigh"], person.lengths["shank"]
    return np.sqrt(t * t + s * s + 2 * t * s * np.cos(np.radians(knee)))


def _leg_rotations(person: Person, side: str, pelvis: np.ndarray, hip: np.ndarray,
                   ankle: np.ndarray, foot: np.ndarray, clinical: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hip, knee and ankle joint rotations that put the ankle and the foot where asked.

    The knee is a hinge, so the hip-to-ankle distance gives its flexion (two-link inverse
    kinematics); the hip's flexion and abduction point the leg at the ankle; the hip's
    axial rotation is chosen so that the ankle's axial rotation is the template's
    (``clinical``, which carries the knee's axial rotation too); the ankle takes the rest
    of the foot's orientation.

    Parameters
    ----------
    pelvis : (frames, 3, 3) pelvis frame in the lab
    hip, ankle : (frames, 3) joint centres in the lab, metres
    foot : (frames, 3, 3) foot frame in the lab
    clinical : (frames, segments, 3) template angles, degrees

    Returns
    -------
    thigh, shank, foot joint rotations, each (frames, 3, 3).
    """
    shank_i, foot_i = (SEGMENT_NAMES.index(f"{side}_{name}") for name in ("shank", "foot"))
    t, s = person.lengths["thigh"], person.lengths["shank"]
    target = np.einsum("fji,fj->fi", pelvis, ankle - hip)             # in the pelvis frame
    distance = np.linalg.norm(target, axis=1)
    reach = np.minimum(distance, _leg_length(person, 0.5))           # never quite straight
    knee = np.arccos(np.clip((reach**2 - t * t - s * s) / (2 * t * s), -1.0, 1.0))
    target = target * (reach / distance)[:, None]
    leg = np.stack([-s * np.sin(knee), np.zeros_like(knee), -t - s * np.cos(knee)], axis=1)
    knee_joint = Rotation.from_euler(
        "YZ", np.stack([np.degrees(knee), clinical[:, shank_i, 2] * _CLINICAL_SIGNS[shank_i, 2]],
                       axis=1), degrees=True).as_matrix()
    wanted = np.radians(clinical[:, foot_i, 2] * _CLINICAL_SIGNS[foot_i, 2])

    def pose(twist):
        """Hip and ankle joints, and the ankle's axial rotation, for a hip axial rotation."""
        turned = np.stack([leg[:, 0] * np.cos(twist), leg[:, 0] * np.sin(twist), leg[:, 2]],
                          axis=1)
        radius = np.hypot(turned[:, 1], turned[:, 2])
        about_x = -np.arccos(np.clip(target[:, 1] / radius, -1.0, 1.0)) - np.arctan2(
            turned[:, 2], turned[:, 1])
        about_x = (about_x + np.pi) % (2 * np.pi) - np.pi
        rolled_z = turned[:, 1] * np.sin(about_x) + turned[:, 2] * np.cos(about_x)
        about_y = np.arctan2(target[:, 0], target[:, 2]) - np.arctan2(turned[:, 0], rolled_z)
        hip_joint = Rotation.from_euler("YXZ", np.stack([about_y, about_x, twist], axis=1)
                                        ).as_matrix()
        ankle_joint = np.swapaxes(pelvis @ hip_joint @ knee_joint, 1, 2) @ foot
        axial = Rotation.from_matrix(ankle_joint).as_euler("YXZ")[:, 2]
        return hip_joint, ankle_joint, (axial - wanted + np.pi) % (2 * np.pi) - np.pi

    # Secant method on the hip's axial rotation, starting from slope −1 (turning the
    # thigh turns the shank over the foot); the slope stays away from 0 while the knee is
    # not bent past a right angle.
    twist, slope = np.zeros_like(knee), -np.ones_like(knee)
    hip_joint, ankle_joint, error = pose(twist)
    for _ in range(8):
        if np.abs(error).max() < 1e-12:
            break
        step = -np.clip(error / slope, -0.5, 0.5)
        twist = twist + step
        hip_joint, ankle_joint, new_error = pose(twist)
        moved = np.abs(step) > 1e-12
        slope = np.where(moved, (new_error - error) / np.where(moved, step, 1.0), slope)
        slope = np.where(np.abs(slope) > 0.2, slope, -1.0)
        error = new_error
    return hip_joint, knee_joint, ankle_joint


# --------------------------------------------------------------------------- body path

GRAVITY = 9.81
_GRID = 200            # samples per cycle for the centre-of-mass solve
_HEIGHT_HARMONICS = 4  # harmonics per cycle kept in a walking centre of mass's height


def _template(person: Person, action: str, phase: np.ndarray, seed: int) -> np.ndarray:
    """Template angles with the person's style (gains, offsets, asymmetry),
    (frames, segments, 3) degrees."""
    gains, offsets, action_weights = _style_effects(seed)
    weights = person.style * action_weights[ACTIONS.index(action)]        # (styles,)
    gain = 1.0 + np.tensordot(weights, gains, axes=1)                      # (segments, 3)
    offset = np.tensordot(weights, offsets, axes=1)
    left = np.array([name.startswith("l_") for name in SEGMENT_NAMES])
    gain = gain * np.where(left, 1.0 + person.asymmetry, 1.0)[:, None]
    return offset + gain * _action_angles(action, phase % 1.0)


def _posture(person: Person, clinical: np.ndarray, root: np.ndarray,
             feet: list[dict]) -> np.ndarray:
    """Joint rotations (frames, segments, 3, 3): the template's, with both legs solved to
    put the feet where ``feet`` (right, left; see :meth:`_FootPath.in_lab`) says."""
    joints = _to_rotations(clinical)
    offsets = _offsets(person)
    pelvis = joints[:, 0]
    for side, foot in zip("rl", feet):
        thigh = SEGMENT_NAMES.index(f"{side}_thigh")
        hip = root + pelvis @ offsets[thigh]
        joints[:, thigh:thigh + 3] = np.stack(_leg_rotations(
            person, side, pelvis, hip, foot["ankle"], foot["rotation"], clinical), axis=1)
    return joints


def _periodic_second_derivative(values: np.ndarray, period: float) -> np.ndarray:
    """Spectral second time derivative of samples over one period, (N,) → (N,)."""
    n = len(values)
    omega = 2 * np.pi * np.fft.rfftfreq(n, d=period / n)
    return np.fft.irfft(-omega**2 * np.fft.rfft(values), n)


def _low_pass(values: np.ndarray, harmonics: int) -> np.ndarray:
    """Keep the first ``harmonics`` harmonics of samples over one period, (N,) → (N,)."""
    spectrum = np.fft.rfft(values)
    spectrum[harmonics + 1:] = 0.0
    return np.fft.irfft(spectrum, len(values))


def _below(values: np.ndarray, limit: np.ndarray, width: float = 0.1) -> np.ndarray:
    """Lower periodic samples smoothly where they exceed ``limit``, (N,) → (N,).

    The excess, widened by ``width`` cycles either side and blurred over as much, is
    taken off until nothing exceeds the limit (a smooth local dent, not a global shift).
    """
    n = len(values)
    reach = max(1, int(round(width * n)))
    frequencies = np.fft.rfftfreq(n, d=1.0 / n)
    kernel = np.exp(-0.5 * (2 * np.pi * frequencies * width / 2) ** 2)   # Gaussian, std width/2
    for _ in range(20):
        excess = np.maximum(values - limit, 0.0)
        if excess.max() <= 1e-6:
            break
        widened = np.max([np.roll(excess, k) for k in range(-reach, reach + 1)], axis=0)
        values = values - 1.2 * np.fft.irfft(np.fft.rfft(widened) * kernel, n) - 1e-6
    return values


def _periodic_interpolate(values: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Trigonometric interpolation of (N, dims) samples over one cycle at phases ``u``."""
    n = len(values)
    spectrum = np.fft.rfft(values, axis=0) / n
    k = np.arange(spectrum.shape[0])
    weight = np.where((k == 0) | (2 * k == n), 1.0, 2.0)                   # one-sided sum
    waves = np.exp(2j * np.pi * np.outer(u, k)) * weight
    return np.real(waves @ spectrum)


def _pendulum_solve(stiffness: np.ndarray, pressure: np.ndarray, period: float,
                    push: np.ndarray | float = 0.0) -> np.ndarray:
    """Periodic solution of x'' = k(t) (x − p(t)) on a uniform grid over one period.

    The centre of mass is pushed away from the centre of pressure p by the floor's force
    (an inverted pendulum whose stiffness k = (g + z'') / height varies, 0 in flight), plus
    ``push`` (m/s²), the part of the floor's force that turns the body (a changing angular
    momentum moves the force off the line through the centre of mass).
    Second differences with wrap-around; (N,) arrays, seconds.
    """
    from scipy.sparse import diags
    from scipy.sparse.linalg import spsolve

    n = len(stiffness)
    ones = np.full(n, 1.0 / (period / n) ** 2)
    matrix = diags([ones[:1], ones[1:], -2 * ones - stiffness, ones[1:], ones[:1]],
                   [-(n - 1), -1, 0, 1, n - 1], format="csc")            # cyclic tridiagonal
    return spsolve(matrix, -stiffness * pressure + push)


def _follow(paths: list[_FootPath], person: Person, gait: _Gait, periodic: np.ndarray,
            seed: int) -> None:
    """Make both feet's push-off follow the root path (``periodic``: root minus the
    cycle's advance, (_GRID, 3) over one cycle)."""
    grid = np.arange(_GRID) / _GRID
    pelvis = _to_rotations(_template(person, gait.action, grid, seed))[:, 0]
    offsets = _offsets(person)
    for path, side in zip(paths, "rl"):
        # the hip's path over one cycle, less the advance: interpolated at any phase
        hips = periodic + pelvis @ offsets[SEGMENT_NAMES.index(f"{side}_thigh")]
        start, placement = gait.phase[path.side], gait.placement[path.side]

        def hip(u, hips=hips, start=start, placement=placement):
            phase = u + start
            return (_periodic_interpolate(hips, phase % 1.0) + np.outer(phase, gait.advance)
                    - placement)

        path.follow(hip)


def _body_path(person: Person, gait: _Gait, paths: list[_FootPath], seed: int
               ) -> np.ndarray:
    """Root (pelvis origin) positions over one cycle, (_GRID, 3) metres, at phases
    ``arange(_GRID) / _GRID``, with the feet where ``paths`` put them.

    The centre of mass moves like an inverted pendulum on the centre of pressure, which
    rolls from heel to toe under each foot and passes from foot to foot in double
    support, so the floor can supply the accelerations.  Its height: walking and stairs,
    what the leading supporting leg gives at its nominal knee flexion (smoothed, and never
    higher than the supporting legs reach); running, a spring-mass bounce with a
    ballistic flight.  The root follows from the centre of mass and the posture; a few
    fixed-point passes settle the coupling.
    """
    u = np.arange(_GRID) / _GRID
    period = gait.period
    feet = [path.in_lab(u) for path in paths]
    clinical = _template(person, gait.action, u, seed)
    offsets = _offsets(person)
    pelvis = _to_rotations(clinical)[:, 0]
    hips = [pelvis @ offsets[SEGMENT_NAMES.index(f"{side}_thigh")] for side in "rl"]
    loads = np.stack([_loads(gait, foot["u"]) for foot in feet])           # (2, N)
    support = loads.sum(axis=0)

    def centre_of_pressure(pace):
        cops = np.stack([f["heel"] + f["along"][:, None] ** pace * (f["toe"] - f["heel"])
                         for f in feet])
        return np.einsum("sn,snd->nd", loads, cops) / np.maximum(support, 1e-12)[:, None]

    pressure = centre_of_pressure(1.0)
    trend = np.outer(u, gait.advance)
    if gait.toe_off > 0.5:
        # walking: at the right foot's landing the hips are half-way between the ankles
        moment = 0
        between = 0.5 * (feet[0]["ankle"][0, 0] + feet[1]["ankle"][0, 0]) - 0.5 * (
            hips[0][0, 0] + hips[1][0, 0])
    else:
        # running: the right hip passes over its ankle a little before mid-stance
        moment = int(round(0.45 * gait.toe_off * _GRID))
        between = feet[0]["ankle"][moment, 0] - hips[0][moment, 0]
    standing = clinical.copy()
    standing[:, 9:] = 0.0
    rotations, origins = forward_kinematics(_to_rotations(standing), offsets, np.zeros((_GRID, 3)))
    offset = _centre_of_mass(rotations, origins, person)                   # COM − root
    lengths = person.lengths
    com_z = trend[:, 2] + lengths["ankle_height"] + 0.95 * (lengths["thigh"] + lengths["shank"]) \
        + lengths["hip_drop"] + offset[:, 2]
    bounce = None
    if gait.action == "run":     # spring-mass: half-sine floor force, ballistic flight
        force = sum(np.where(f["u"] < gait.toe_off, np.pi / (4 * gait.toe_off)
                             * np.sin(np.pi * np.minimum(f["u"] / gait.toe_off, 1.0)), 0.0)
                    for f in feet)
        omega = 2 * np.pi * np.fft.rfftfreq(_GRID, d=period / _GRID)
        spectrum = np.fft.rfft(GRAVITY * (force - 1.0))
        spectrum[1:] /= -omega[1:] ** 2
        spectrum[0] = 0.0
        bounce = np.fft.irfft(spectrum, _GRID)
    turning = np.zeros((_GRID, 3))       # rate of angular momentum about the COM, per kg
    for _ in range(4):
        height = com_z - pressure[:, 2]
        accel = _periodic_second_derivative(com_z - trend[:, 2], period)
        stiffness = np.where(support > 0, (GRAVITY + accel) / height, 0.0)
        # the turning body moves the floor's force off the centre of mass
        push_x = np.where(support > 0, -turning[:, 1] / height, 0.0)
        push_y = np.where(support > 0, turning[:, 0] / height, 0.0)

        def ahead(pace):
            """How far the root is ahead of its place at the right landing, metres."""
            nonlocal pressure
            pressure = centre_of_pressure(pace)
            x = trend[:, 0] + _pendulum_solve(stiffness, pressure[:, 0] - trend[:, 0], period,
                                              push_x)
            return x[moment] - offset[moment, 0] - between

        # How soon the pressure rolls forward under the foot sets where the body rides
        # over the feet: choose it (bisection on a log scale) to centre the body between
        # the feet when they swap.
        low, high = np.log(0.4), np.log(2.5)
        if ahead(np.exp(low)) < 0:
            high = low
        elif ahead(np.exp(high)) < 0:
            for _ in range(12):
                mid = 0.5 * (low + high)
                low, high = (mid, high) if ahead(np.exp(mid)) > 0 else (low, mid)
        else:
            low = high
        ahead(np.exp(0.5 * (low + high)))
        com_x = trend[:, 0] + _pendulum_solve(stiffness, pressure[:, 0] - trend[:, 0], period,
                                              push_x)
        com_y = _pendulum_solve(stiffness, pressure[:, 1], period, push_y)
        root_xy = np.stack([com_x, com_y], axis=1) - offset[:, :2]
        goal = np.zeros(_GRID)
        ceiling = np.full(_GRID, np.inf)
        for foot, hip, load in zip(feet, hips, loads):
            across = np.linalg.norm(root_xy + hip[:, :2] - foot["ankle"][:, :2], axis=1)

            def root_height(length):
                return (foot["ankle"][:, 2] - hip[:, 2]
                        + np.sqrt(np.maximum(length**2 - across**2, (0.5 * length) ** 2)))

            stance = foot["u"] < gait.toe_off
            ceiling = np.where(stance, np.minimum(ceiling, root_height(
                _leg_length(person, gait.knee_min))), ceiling)
            knee = np.clip(gait.knee_gain * _stance_knee(gait.action, foot["u"]),
                           gait.knee_min, 80.0)
            # The leading leg sets the height; a trailing leg pushing off only limits it
            # (except down stairs, where it bends to lower the body onto the next step).
            leads = (foot["u"] < 0.5) | (gait.action == "descend")
            target = np.where(leads, root_height(_leg_length(person, knee)),
                              root_height(_leg_length(person, gait.knee_min)))
            goal += load * np.where(stance, target, 0.0)
        if bounce is not None:
            com_z = bounce + np.min(ceiling + offset[:, 2] - bounce)
        else:
            com_z = trend[:, 2] + _low_pass(goal + offset[:, 2] - trend[:, 2], _HEIGHT_HARMONICS)
            com_z = _below(com_z, ceiling + offset[:, 2])
        root = np.column_stack([root_xy, com_z - offset[:, 2]])
        _follow(paths, person, gait, root - trend, seed)
        feet = [path.in_lab(u) for path in paths]
        joints = _posture(person, clinical, root, feet)
        rotations, origins = forward_kinematics(joints, offsets, root)
        offset = _centre_of_mass(rotations, origins, person) - root
        turning = _turning_rate(rotations, origins, person, period, gait.advance)
    return root


def _motion(person: Person, action: str, phase: np.ndarray, seed: int = 0
            ) -> tuple[np.ndarray, np.ndarray, _Gait]:
    """Clinical joint angles (frames, segments, 3) degrees and root positions (frames, 3)
    metres of ``person`` doing ``action`` at ``phase`` (cycles from the right landing)."""
    if action not in ACTIONS:
        raise MocapError(f"unknown action {action!r}; known: {', '.join(ACTIONS)}")
    phase = np.asarray(phase, dtype=float)
    gait = _gait(person, action, seed)
    paths = [_FootPath(gait, person, side) for side in (0, 1)]
    grid = np.arange(_GRID) / _GRID
    path = _body_path(person, gait, paths, seed) - np.outer(grid, gait.advance)
    _follow(paths, person, gait, path, seed)
    root = _periodic_interpolate(path, phase % 1.0) + np.outer(phase, gait.advance)
    clinical = _template(person, action, phase, seed)
    joints = _posture(person, clinical, root, [p.in_lab(phase) for p in paths])
    for side in "rl":
        for name in ("thigh", "shank", "foot"):
            i = SEGMENT_NAMES.index(f"{side}_{name}")
            clinical[:, i] = _to_clinical(joints[:, i], i)
    return clinical, root, gait


# --------------------------------------------------------------------------- trials

def cycle_seconds(person: Person, action: str, seed: int = 0) -> float:
    """Duration of one cycle of ``action`` for ``person``, seconds."""
    interaction = np.random.default_rng([seed, 3, ACTIONS.index(action)]).normal(0, 0.5)
    # the person's cadence scales each action a little differently
    return ACTION_CYCLE_SECONDS[action] * person.cadence ** (1.0 + 0.3 * interaction)


def person_angles(person: Person, action: str, phase: np.ndarray, seed: int = 0) -> np.ndarray:
    """Clinical joint angles of ``person`` doing ``action``, (frames, segments, 3) degrees.

    ``phase`` is the gait-cycle phase (cycles, 0 = right foot landing); it may run
    over several cycles.  Leg angles come from the feet's paths by inverse kinematics
    (see the module docstring), the others from the action's templates.
    """
    return _motion(person, action, phase, seed)[0]


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
    clinical, root, _ = _motion(person, action, times / period, seed)
    joint_rotations = _to_rotations(clinical)
    offsets = _offsets(person)
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
