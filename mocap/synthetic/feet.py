"""The feet: each action's gait, and each foot's path — landing, rolling over heel and
toe, swinging to its next place on the floor or on a stair tread."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.synthetic.legs import _leg_length
from mocap.synthetic.people import (_STYLES, ACTIONS, STEP_RISE, Person, _foot_points,
                                    _style_effects, cycle_seconds)
from mocap.synthetic.templates import _stance_knee

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
                off_pitch=-38.0, clearance=0.05, lift=0.10, width=0.05, toe_out=5.0,
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
            # (a smooth corner: a kink in the pitch would jolt the whole leg, which the
            # floor could not follow)
            solved = _soft_nonpositive(pitch + 30.0 * np.tanh((solved - pitch) / 30.0), 10.0)
            # eased in after heel rise and out before toe-off (the swing starts nominally)
            blend = _smoothstep(3 * s) * (1 - _smoothstep((s - 0.6) / 0.4))
            blend = blend * (g.action != "run")
            pitch = (1 - blend) * pitch + blend * solved
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


def _soft_nonpositive(x: np.ndarray, width: float) -> np.ndarray:
    """``min(x, 0)`` with the corner rounded over ``±width``, twice continuously
    differentiable: ``x − r(x)`` where r' is the quintic smoothstep across the corner."""
    t = np.clip((x + width) / (2 * width), 0.0, 1.0)
    return np.where(x >= width, 0.0, x - 2 * width * t**4 * (2.5 - 3 * t + t**2))


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
