"""Segment masses, centres of mass and inertias from de Leva (1996), scaled to a skeleton.

de Leva P. (1996) "Adjustments to Zatsiorsky-Seluyanov's segment inertia parameters",
J. Biomech. 29(9):1223-1230, table 4, stored in ``data/bodies/de-leva-1996.toml``. Mass as a fraction of body mass; centre of mass as
a fraction of the segment length from the proximal end (from the upper end for head and
trunk); radii of gyration as fractions of the segment length.

Axis naming of the radii: "sagittal" is the radius about the sagittal (anteroposterior)
axis, "transverse" about the transverse (mediolateral) axis, "longitudinal" about the long
axis. The table itself shows it: the upper trunk, wide from left to right, has r_sag 0.716 >
r_trans 0.454, while the head, deeper than wide, has r_sag 0.362 < r_trans 0.376.

Segment endpoints in our 15-segment body (each frame is the identity in the neutral pose,
Y up, Z anterior, X left; a segment's origin is its proximal joint):

* upper arm, forearm, thigh, shank: origin → first child's origin;
* hand: origin (wrist) → end site, the fingertip (default 0.74 forearm lengths along the
  forearm, Winter's 0.108 vs 0.146 of the height). de Leva's hand ends at the third
  metacarpale (86.2 mm of the 188 mm wrist-to-fingertip length of his reference male,
  78.0 of 187 mm female), so his COM fraction (0.790) and radii are scaled by that ratio:
  the COM sits 0.362 of the wrist-to-fingertip length from the wrist (Dumas et al. 2007
  give 0.361 for the same landmarks), not 0.79 of it, which would put it 9 cm too far;
* head: origin → end site (head top); de Leva's COM is measured from the vertex;
* thorax (upper + mid trunk merged): origin → head origin; COM from the bottom 0.584 L
  (merged with the parallel-axis theorem below);
* pelvis (lower trunk): midpoint of the hip joints → thorax origin, COM 0.3885 L above the
  hips (de Leva: 0.6115 from the upper end);
* foot: heel → toe tip; the toe is the end site, the heel is under the ankle at sole level,
  0.2 of the horizontal ankle-to-toe distance behind the ankle (the calcaneus contact, a
  few centimetres ahead of the back of the heel).

The female radii of gyration are transcribed from de Leva's table 4 but were not
cross-checked against the project's reference notes (which list male radii only); masses
and centres of mass of both sexes were.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocap.body.segments import BODY_PARENTS, BODY_SEGMENTS, default_skeleton
from mocap.errors import MocapError
from mocap.resources import data_path
from mocap.skeleton import Motion
from mocap.tomlfile import parse_toml

def _de_leva_table() -> dict:
    """de Leva's table 4 as stored in ``data/bodies/de-leva-1996.toml`` (source cited there)."""
    path = data_path("bodies", "de-leva-1996.toml")
    return parse_toml(path.read_text(encoding="utf-8"), path, "body table")


_TABLE = _de_leva_table()
_KINDS = ("head", "upper_trunk", "mid_trunk", "lower_trunk", "upperarm", "forearm", "hand",
          "thigh", "shank", "foot")
#: (mass fraction, COM fraction from proximal/upper end, r_sag, r_trans, r_long), male.
DE_LEVA_MALE = {kind: tuple(_TABLE["male"][kind]) for kind in _KINDS}
DE_LEVA_FEMALE = {kind: tuple(_TABLE["female"][kind]) for kind in _KINDS}
#: Lengths (mm) of the reference subjects, used only to merge the trunk parts.
_LENGTHS_MALE = {part: _TABLE["male"]["reference_lengths_mm"][part]
                 for part in ("upper_trunk", "mid_trunk")}
_LENGTHS_FEMALE = {part: _TABLE["female"]["reference_lengths_mm"][part]
                   for part in ("upper_trunk", "mid_trunk")}
#: de Leva's hand length (wrist joint centre to the third metacarpale), mm, and the
#: wrist-to-fingertip length of the same reference subject (Winter: 0.108 of the height).
_HAND_LENGTH = {sex: _TABLE[sex]["reference_lengths_mm"]["hand"] for sex in ("male", "female")}
_FINGERTIP_HAND = {sex: 0.108 * _TABLE[sex]["reference_lengths_mm"]["stature"]
                   for sex in ("male", "female")}


def _merged_thorax(table: dict, lengths: dict) -> tuple[float, float, float, float, float]:
    """Upper + mid trunk as one segment: (mass, COM from the bottom, r_sag, r_trans, r_long).

    Both parts lie on one long axis (upper above mid); their inertias add about the
    merged COM with the parallel-axis theorem (the long-axis term has no offset).
    """
    mu, cu, su, tu, lu = table["upper_trunk"]
    mm, cm, sm, tm, lm = table["mid_trunk"]
    length_u, length_m = lengths["upper_trunk"], lengths["mid_trunk"]
    total = length_u + length_m
    # COM positions measured from the top of the merged segment.
    zu, zm = cu * length_u, length_u + cm * length_m
    mass = mu + mm
    z = (mu * zu + mm * zm) / mass
    def radius(ru: float, rm: float, parallel: bool) -> float:
        inertia = mu * (ru * length_u) ** 2 + mm * (rm * length_m) ** 2
        if parallel:
            inertia += mu * (zu - z) ** 2 + mm * (zm - z) ** 2
        return float(np.sqrt(inertia / mass) / total)
    return (mass, 1.0 - z / total, radius(su, sm, True), radius(tu, tm, True),
            radius(lu, lm, False))


def segment_table(sex: str = "male") -> dict[str, tuple[float, float, float, float, float]]:
    """de Leva parameters per body-segment kind: (mass fraction, COM fraction from our
    proximal point, r_sag, r_trans, r_long).

    Kinds: pelvis, thorax, head, upperarm, forearm, hand, thigh, shank, foot. The COM
    fractions are converted to "from the proximal point" of our segment definitions (see
    the module docstring): head and pelvis measured from below.
    """
    if sex not in ("male", "female"):
        raise ValueError(f"sex must be 'male' or 'female', got {sex!r}")
    table = DE_LEVA_MALE if sex == "male" else DE_LEVA_FEMALE
    lengths = _LENGTHS_MALE if sex == "male" else _LENGTHS_FEMALE
    result = {kind: table[kind] for kind in
              ("upperarm", "forearm", "thigh", "shank", "foot")}
    # de Leva's hand ends at the third metacarpale; ours at the fingertip (module docstring).
    m, c, s, t, lo = table["hand"]
    k = _HAND_LENGTH[sex] / _FINGERTIP_HAND[sex]
    result["hand"] = (m, c * k, s * k, t * k, lo * k)
    m, c, s, t, lo = table["head"]
    result["head"] = (m, 1.0 - c, s, t, lo)
    m, c, s, t, lo = table["lower_trunk"]
    result["pelvis"] = (m, 1.0 - c, s, t, lo)
    result["thorax"] = _merged_thorax(table, lengths)
    return result


def segment_kind(name: str) -> str:
    """The de Leva kind of one of our body segments ('l_thigh' → 'thigh')."""
    return name[2:] if name[:2] in ("l_", "r_") else name


@dataclass
class SegmentInertia:
    """Inertial parameters of one segment in its own frame.

    Attributes
    ----------
    mass : float, kg
    com : ndarray, shape (3,), metres, in the segment frame
    inertia : ndarray, shape (3, 3), kg m², about the COM, segment axes
    proximal, distal : ndarray, shape (3,), metres
        The segment's end points used for length and long axis.
    """

    mass: float
    com: np.ndarray
    inertia: np.ndarray
    proximal: np.ndarray
    distal: np.ndarray

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self.distal - self.proximal))


def foot_points(end_site: np.ndarray, half_width: tuple[float, float] = (0.025, 0.04),
                up: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Heel and toe contact points of a foot in its frame (origin at the ankle).

    Parameters
    ----------
    end_site : ndarray, shape (3,), metres
        The toe tip in the foot frame (Y up, Z anterior at rest).
    half_width : (heel, toe) half-widths, metres.
    up : ndarray, shape (3,), optional
        The sole's normal in the foot frame (default Y): the heel lies under the ankle at
        the toe's level along it, the widths across it (a rig's foot frame whose axes are
        not anatomical, e.g. X along the foot bone, gives it from the stance phases).

    Returns
    -------
    dict
        ``heel``, ``toe`` (on the long axis) and ``heel_medial``/``heel_lateral``/
        ``toe_medial``/``toe_lateral`` (sign of X does not matter: both sides are used).
    """
    toe = np.asarray(end_site, float)
    up = np.array([0.0, 1.0, 0.0]) if up is None else np.asarray(up, float) / np.linalg.norm(up)
    horizontal = toe - (toe @ up) * up
    heel = (toe @ up) * up - 0.2 * horizontal
    forward = horizontal / max(np.linalg.norm(horizontal), 1e-9)
    side = np.cross(up, forward)                              # +X when facing +Z
    # Ball of the foot (metatarsal heads) at 80 % of heel→toe, where the width is.
    ball = heel + 0.8 * (toe - heel)
    return {
        "heel": heel, "toe": toe,
        "heel_a": heel + half_width[0] * side, "heel_b": heel - half_width[0] * side,
        "toe_a": ball + half_width[1] * side, "toe_b": ball - half_width[1] * side,
    }


def segment_inertias(skeleton, body_mass: float, sex: str = "male") -> list[SegmentInertia]:
    """de Leva inertial parameters of every segment of a 15-segment body skeleton.

    Parameters
    ----------
    skeleton : mocap.skeleton.Skeleton
        Names must be those of ``mocap.body.segments.BODY_SEGMENTS`` (use
        ``reduce_to_segments`` first); end sites for head, hands and feet.
    body_mass : float, kg
    sex : {"male", "female"}

    Returns
    -------
    list of SegmentInertia, one per skeleton segment.
    """
    table = segment_table(sex)
    names = skeleton.names
    result = []
    for i, name in enumerate(names):
        kind = segment_kind(name)
        if kind not in table:
            raise ValueError(f"no de Leva parameters for segment {name!r}")
        mass_fraction, com_fraction, r_sag, r_trans, r_long = table[kind]
        proximal, distal = _end_points(skeleton, i, kind)
        axis = distal - proximal
        length = float(np.linalg.norm(axis))
        if length < 1e-6:
            raise MocapError(f"segment {name!r} has no length")
        long_axis = axis / length
        ap = np.array([0.0, 0.0, 1.0])
        if abs(long_axis @ ap) > 0.9:                 # the foot: long axis is anterior
            ap = np.array([0.0, 1.0, 0.0])
        ap = ap - (ap @ long_axis) * long_axis
        ap /= np.linalg.norm(ap)
        ml = np.cross(long_axis, ap)
        mass = mass_fraction * body_mass
        inertia = mass * length ** 2 * (r_long ** 2 * np.outer(long_axis, long_axis)
                                        + r_sag ** 2 * np.outer(ap, ap)
                                        + r_trans ** 2 * np.outer(ml, ml))
        com = proximal + com_fraction * axis
        result.append(SegmentInertia(mass, com, inertia, proximal, distal))
    return result


def leg_length(skeleton) -> float:
    """Mean thigh + shank length (hip to ankle) of a body skeleton, metres."""
    names = skeleton.names
    total = []
    for side in ("l_", "r_"):
        shank, foot = names.index(side + "shank"), names.index(side + "foot")
        total.append(np.linalg.norm(skeleton.offsets[shank])
                     + np.linalg.norm(skeleton.offsets[foot]))
    return float(np.mean(total))


def lumped_segments(skeleton, body_mass: float, sex: str = "male"
                    ) -> list[tuple[str, int, SegmentInertia]]:
    """Segments missing from a partial body, as rigid inertias of a present ancestor.

    A lower-body skeleton (pelvis and legs) still carries the head, arms and trunk: they
    are placed as in the neutral standing pose of :func:`mocap.body.segments.default_skeleton`,
    scaled to the skeleton's leg length (hip to ankle), and added to the nearest present
    ancestor (the pelvis, aligned at the hip-joint midpoint) with their de Leva masses and
    inertias — the "HAT" of lower-limb models, rigid with the pelvis.

    Returns
    -------
    list of (missing segment name, index of the ancestor it is lumped into,
    SegmentInertia expressed in that ancestor's frame)
    """
    missing = [n for n in BODY_SEGMENTS if n not in skeleton.names]
    if not missing:
        return []
    reference = default_skeleton(1.75)
    scale = leg_length(skeleton) / leg_length(reference)
    reference = default_skeleton(1.75 * scale)
    parts = segment_inertias(reference, body_mass, sex)
    rest = Motion.still(reference, 1, 1.0).forward_kinematics()[1][0]
    actual_rest = Motion.still(skeleton, 1, 1.0).forward_kinematics()[1][0]

    def anchor(name: str, rest_points: np.ndarray, names: list[str]) -> np.ndarray:
        """Where a segment is aligned: the hip midpoint for the pelvis, else its origin."""
        if name == "pelvis":
            return rest_points[[names.index("l_thigh"), names.index("r_thigh")]].mean(axis=0)
        return rest_points[names.index(name)]

    result = []
    for name in missing:
        ancestor = BODY_PARENTS[BODY_SEGMENTS.index(name)]
        while BODY_SEGMENTS[ancestor] not in skeleton.names:
            ancestor = BODY_PARENTS[BODY_SEGMENTS.index(BODY_SEGMENTS[ancestor])]
        host = BODY_SEGMENTS[ancestor]
        host_index = skeleton.names.index(host)
        shift = (anchor(host, actual_rest, skeleton.names) - actual_rest[host_index]
                 - anchor(host, rest, reference.names) + rest[reference.names.index(host)])
        own = parts[reference.names.index(name)]
        origin = rest[reference.names.index(name)] - rest[reference.names.index(host)] + shift
        result.append((name, host_index, SegmentInertia(
            own.mass, origin + own.com, own.inertia, origin + own.proximal,
            origin + own.distal)))
    return result


def _end_points(skeleton, index: int, kind: str) -> tuple[np.ndarray, np.ndarray]:
    names = skeleton.names
    children = skeleton.children(index)
    end = skeleton.end_sites[index]
    origin = np.zeros(3)
    if kind == "pelvis":
        hips = [c for c in children if segment_kind(names[c]) == "thigh"]
        trunk = [c for c in children if segment_kind(names[c]) == "thorax"]
        if not hips:
            raise MocapError("the pelvis needs two thighs as children")
        middle = skeleton.offsets[hips].mean(axis=0)
        if trunk:
            return middle, skeleton.offsets[trunk[0]]
        # No trunk (a lower-body marker set): de Leva's lower trunk is 0.0837 of the
        # standing height, about 0.2 of the thigh + shank length, straight up.
        leg = leg_length(skeleton)
        return middle, middle + np.array([0.0, 0.2 * leg, 0.0])
    if kind == "thorax":
        head = [c for c in children if segment_kind(names[c]) == "head"]
        return origin, skeleton.offsets[head[0] if head else children[0]]
    if kind == "foot":
        if not np.isfinite(end).all():
            raise MocapError(f"foot {names[index]!r} needs an end site (toe tip)")
        points = foot_points(end)
        return points["heel"], points["toe"]
    if kind in ("hand", "head"):
        if np.isfinite(end).all():
            return origin, end
        parent = skeleton.parents[index]
        along = skeleton.offsets[index]
        fraction = 0.74 if kind == "hand" else 0.85
        return origin, along * fraction if parent >= 0 else np.array([0, 0.2, 0])
    if not children:
        raise MocapError(f"segment {names[index]!r} has no child to give its length")
    return origin, skeleton.offsets[children[0]]


@dataclass(frozen=True)
class DempsterSegment:
    """One segment's inertial parameters as fractions (Plug-in Gait's Dempster table).

    Attributes
    ----------
    mass_fraction : float
        Of the body mass.
    com_fraction : float
        Of the segment length, from the proximal end.
    radius_of_gyration : float
        Of the segment length, applied about the centre of mass across the segment
        (Dempster's radius about the proximal end, as Plug-in Gait; see the TOML).
    """

    mass_fraction: float
    com_fraction: float
    radius_of_gyration: float


def plugingait_segments() -> dict[str, DempsterSegment]:
    """Plug-in Gait's lower-limb inertial parameters: ``thigh``, ``shank``, ``foot``.

    Dempster (1955) as Winter tabulates it and Plug-in Gait uses it, stored in
    ``data/bodies/plugingait-dempster.toml`` (source and segment ends cited there).

    >>> plugingait_segments()["thigh"].mass_fraction
    0.1
    """
    path = data_path("bodies", "plugingait-dempster.toml")
    table = parse_toml(path.read_text(encoding="utf-8"), path, "body table")
    return {kind: DempsterSegment(*(float(v) for v in table[kind]))
            for kind in ("thigh", "shank", "foot")}
