"""Synthetic people: the body model's segments and markers, each person's signature
(size, proportions, cadence, style factors), their segment offsets and marker positions."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocap.errors import MocapError
from mocap.skeleton import Motion, Skeleton

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


def lab_frames(joint_rotations: np.ndarray, offsets: np.ndarray,
               root_translation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Segment frames in the lab from joint rotations, by
    :meth:`mocap.skeleton.Motion.forward_kinematics` of the body's skeleton.

    Parameters
    ----------
    joint_rotations : ndarray, shape (frames, segments, 3, 3)
        R_parent⁻¹ R_child; the root's is its lab orientation.
    offsets : ndarray, shape (segments, 3), metres
        Child origin in the parent frame (the root's row is zero).
    root_translation : ndarray, shape (frames, 3), metres
        Root origin in the lab.

    Returns
    -------
    rotations : ndarray, shape (frames, segments, 3, 3)
    origins : ndarray, shape (frames, segments, 3), metres
    """
    skeleton = Skeleton(list(SEGMENT_NAMES), list(PARENT_INDEX), offsets)
    # The pose does not depend on the rate: any positive one will do.
    return Motion(skeleton, root_translation, joint_rotations, 1.0).forward_kinematics()


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


def cycle_seconds(person: Person, action: str, seed: int = 0) -> float:
    """Duration of one cycle of ``action`` for ``person``, seconds."""
    interaction = np.random.default_rng([seed, 3, ACTIONS.index(action)]).normal(0, 0.5)
    # the person's cadence scales each action a little differently
    return ACTION_CYCLE_SECONDS[action] * person.cadence ** (1.0 + 0.3 * interaction)
