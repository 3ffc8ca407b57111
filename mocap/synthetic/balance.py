"""Balance: segment masses (de Leva), the body's centre of mass and turning rate, and
the root path that rides the centres of pressure like an inverted pendulum."""
from __future__ import annotations

import numpy as np
from scipy.sparse import diags
from scipy.sparse.linalg import spsolve

from mocap.body.anthropometry import segment_inertias
from mocap.body.retarget import Z_UP_TO_Y_UP, _default_end_sites
from mocap.errors import MocapError
from mocap.skeleton import Skeleton
from mocap.synthetic.feet import _FootPath, _Gait, _gait, _loads
from mocap.synthetic.legs import _leg_length, _leg_rotations
from mocap.synthetic.people import (ACTIONS, PARENT_INDEX, SEGMENT_NAMES, Person, _offsets,
                                    lab_frames)
from mocap.synthetic.templates import _stance_knee, _template, _to_clinical, _to_rotations

def _mass_model(person: Person) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The body the dynamics check sees: mass fractions (segments,) summing to 1, centres
    of mass in the segment frames (segments, 3) metres, and inertias about them per unit
    body mass in the segment axes (segments, 3, 3) m².

    de Leva (1996, male) by :func:`mocap.body.anthropometry.segment_inertias`, on the
    person's skeleton as the check rebuilds it from the ``synthetic15`` markers (the same
    offsets, turned to Y up, and the default end sites of
    :func:`mocap.body.retarget.motion_from_trial` for head, hands and feet), so that the
    motion's centre of mass and angular momentum are the ones the check computes.
    """
    skeleton = Skeleton(list(SEGMENT_NAMES), list(PARENT_INDEX), _offsets(person) @ Z_UP_TO_Y_UP.T)
    _default_end_sites(skeleton)
    parts = segment_inertias(skeleton, 1.0, "male")
    turn = Z_UP_TO_Y_UP                       # generator segment axes → the check's (Y up)
    fractions = np.array([part.mass for part in parts])
    centres = np.array([part.com for part in parts]) @ turn
    inertias = np.einsum("ji,sjk,kl->sil", turn, np.array([part.inertia for part in parts]),
                         turn)
    return fractions / fractions.sum(), centres, inertias / fractions.sum()


def _centre_of_mass(rotations: np.ndarray, origins: np.ndarray, person: Person) -> np.ndarray:
    """Whole-body centre of mass, (frames, 3) metres, from segment poses in the lab."""
    fractions, centres, _ = _mass_model(person)
    points = origins + np.einsum("fsij,sj->fsi", rotations, centres)
    return np.einsum("s,fsi->fi", fractions, points)


def _angular_momentum(rotations: np.ndarray, origins: np.ndarray, person: Person,
                      period: float, advance: np.ndarray) -> np.ndarray:
    """The body's angular momentum about its centre of mass per unit body mass, (N, 3)
    m²/s, over one cycle sampled uniformly (segment masses at their centres of mass and
    their spin ``R I Rᵀ ω``; positions advance by ``advance`` per cycle)."""
    fractions, centres, inertias = _mass_model(person)
    n = len(origins)
    points = origins + np.einsum("fsij,sj->fsi", rotations, centres)
    trend = np.outer(np.arange(n) / n, advance)[:, None, :]
    velocity = _periodic_rate(points - trend, period) + advance / period
    centre = np.einsum("s,fsi->fi", fractions, points)
    drift = np.einsum("s,fsi->fi", fractions, velocity)
    momentum = np.einsum("s,fsi->fi", fractions, np.cross(points - centre[:, None],
                                                          velocity - drift[:, None]))
    spin = _periodic_rate(rotations, period) @ np.swapaxes(rotations, 2, 3)   # ω̂ = Ṙ Rᵀ
    angular = np.stack([spin[..., 2, 1], spin[..., 0, 2], spin[..., 1, 0]], axis=-1)
    world_inertia = rotations @ inertias @ np.swapaxes(rotations, 2, 3)
    return momentum + np.einsum("fsij,fsj->fi", world_inertia, angular)


def _periodic_rate(values: np.ndarray, period: float) -> np.ndarray:
    """Spectral time derivative of samples over one period along the first axis."""
    n = len(values)
    omega = 2j * np.pi * np.fft.rfftfreq(n, d=period / n)
    flat = values.reshape(n, -1)
    return np.fft.irfft(omega[:, None] * np.fft.rfft(flat, axis=0), n, axis=0).reshape(
        values.shape)


#: The segments that turn against the legs in a run's flight: the trunk, with head and arms.
_UPPER = ("thorax", "head", "l_upperarm", "l_forearm", "l_hand", "r_upperarm", "r_forearm",
          "r_hand")

def _periodic_integral(values: np.ndarray, period: float) -> np.ndarray:
    """Zero-mean periodic antiderivative of zero-mean samples over one period, (N, …)."""
    n = len(values)
    omega = 2j * np.pi * np.fft.rfftfreq(n, d=period / n)
    spectrum = np.fft.rfft(values.reshape(n, -1), axis=0)
    spectrum[1:] /= omega[1:, None]
    spectrum[0] = 0.0
    return np.fft.irfft(spectrum, n, axis=0).reshape(values.shape)


def _upper_inertia(rotations: np.ndarray, origins: np.ndarray, person: Person) -> np.ndarray:
    """Moment of inertia of the trunk, head and arms about the lumbar joint (the thorax's
    origin) per unit body mass, about the lab's X, Y and Z axes, (N, 3) m²."""
    fractions, centres, inertias = _mass_model(person)
    upper = [SEGMENT_NAMES.index(name) for name in _UPPER]
    joint = origins[:, SEGMENT_NAMES.index("thorax")]
    arm = origins[:, upper] + np.einsum("fsij,sj->fsi", rotations[:, upper],
                                        centres[upper]) - joint[:, None]
    world = rotations[:, upper] @ inertias[upper] @ np.swapaxes(rotations[:, upper], 2, 3)
    off_axis = (arm ** 2).sum(axis=2)[..., None] - arm ** 2          # distance² off each axis
    return np.einsum("s,fsk->fk", fractions[upper], off_axis) \
        + np.diagonal(world, axis1=2, axis2=3).sum(axis=1)


#: Force (per body weight) below which the floor hardly turns the body: the weight of a
#: sample's turning rate in :func:`_flight_turn` is ``1 / (f + _FORCE_FLOOR)²``.
_FORCE_FLOOR = 0.05
#: Cost of the trunk's extra turning rate (rad/s)² against the turning (m²/s² per kg)²
#: that the floor could not supply, and of its extra angle (rad²).
_SPIN_COST, _TURN_COST = 10.0, 10.0


def _flight_turn(momentum: np.ndarray, inertia: np.ndarray, force: np.ndarray,
                 period: float) -> np.ndarray:
    """How much more the trunk (with head and arms) turns about the lumbar joint so that
    the floor can supply the body's turning, (N, 3) radians about the lab's X, Y, Z.

    The floor turns the body about its centre of mass only through its force, so the
    rate of the angular momentum must vanish in flight and fade with the force at landing
    and take-off.  The trunk turning by θ adds ``J θ'`` to the momentum ``L`` (``J`` its
    inertia about the joint, ``inertia`` (N, 3) m² per kg); θ minimises, per axis,
    ``Σ (L + J θ')'² / (f + F)² + a Σ θ'² + b Σ θ²`` over the cycle — the turning the
    floor would have to give, weighted by how little force it has (``force`` f per body
    weight, 0 in flight; F = :data:`_FORCE_FLOOR`), against the trunk's extra turning
    (a, b = :data:`_SPIN_COST`, :data:`_TURN_COST`).  With the legs swinging in flight the
    trunk turns the other way, and back in the stances.  ``momentum`` is L per unit body
    mass, (N, 3) m²/s, on a uniform grid over one period.
    """
    n = len(momentum)
    derivative = _periodic_rate(np.eye(n), period)                  # D @ x = x'
    weight = 1.0 / (force + _FORCE_FLOOR) ** 2
    rate = _periodic_rate(momentum, period)
    turn = np.zeros((n, 3))
    for axis in range(3):
        spin = derivative @ (inertia[:, axis, None] * derivative)    # θ ↦ (J θ')'
        normal = spin.T @ (weight[:, None] * spin) \
            + _SPIN_COST * derivative.T @ derivative + _TURN_COST * np.eye(n)
        turn[:, axis] = np.linalg.solve(normal, -spin.T @ (weight * rate[:, axis]))
    return turn


# --------------------------------------------------------------------------- body path

GRAVITY = 9.81
_GRID = 200            # samples per cycle for the centre-of-mass solve
_HEIGHT_HARMONICS = 4  # harmonics per cycle kept in a walking centre of mass's height


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


def _low_pass(values: np.ndarray, harmonics: int, taper: float = np.inf) -> np.ndarray:
    """Keep the first ``harmonics`` harmonics of samples over one period, (N,) → (N,),
    weighted by ``exp(−½ (k / taper)²)`` (the default keeps them whole)."""
    spectrum = np.fft.rfft(values)
    spectrum[harmonics + 1:] = 0.0
    k = np.arange(harmonics + 1)
    spectrum[:harmonics + 1] *= np.exp(-0.5 * (k / taper) ** 2)
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
               ) -> tuple[np.ndarray, np.ndarray]:
    """Root (pelvis origin) positions over one cycle at phases ``arange(_GRID) / _GRID``,
    with the feet where ``paths`` put them, and the trunk's turn.

    The centre of mass moves like an inverted pendulum on the centre of pressure, which
    rolls from heel to toe under each foot and passes from foot to foot in double
    support, so the floor can supply the accelerations.  Its height: walking and stairs,
    what the leading supporting leg gives at its nominal knee flexion (smoothed, and never
    higher than the supporting legs reach); running, a spring-mass bounce with a
    ballistic flight, the trunk turning against the legs (:func:`_flight_turn`).  The
    root follows from the centre of mass and the posture; a few fixed-point passes settle
    the coupling.

    Returns
    -------
    root : (_GRID, 3) metres
    lean : (_GRID, 3) radians
        The trunk's extra turn about the lab's X, Y, Z (zero but running), added to the
        thorax's template by :func:`_leaning`.
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
    rotations, origins = lab_frames(_to_rotations(standing), offsets, np.zeros((_GRID, 3)))
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
    lean = np.zeros((_GRID, 3))          # the trunk's turn (running), radians about X, Y, Z
    thorax = SEGMENT_NAMES.index("thorax")
    passes = 10 if bounce is not None else 8
    for ordinal in range(passes):
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
            # Within reach of the supporting legs; running, of the swinging ones too (leaving
            # the floor behind the body, reaching for the next landing in front of it in
            # flight): else the leg's inverse kinematics would straighten short of its foot
            # and the body would jerk in the air.  (A walk's swinging leg reaches its foot.)
            reach = stance | (bounce is not None)
            ceiling = np.where(reach, np.minimum(ceiling, root_height(
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
            # The floor can only push: where the smoothed height would fall faster than
            # the floor lets it (its force below a quarter of the weight in support) the
            # higher harmonics ring, and they are tapered until it does not.
            for taper in (np.inf, 3.0, 2.0, 1.5, 1.0):
                com_z = trend[:, 2] + _low_pass(goal + offset[:, 2] - trend[:, 2],
                                                _HEIGHT_HARMONICS, taper)
                com_z = _below(com_z, ceiling + offset[:, 2])
                lift = GRAVITY + _periodic_second_derivative(com_z - trend[:, 2], period)
                if lift.min() >= 0.25 * GRAVITY:
                    break
        root = np.column_stack([root_xy, com_z - offset[:, 2]])
        _follow(paths, person, gait, root - trend, seed)
        feet = [path.in_lab(u) for path in paths]
        joints = _posture(person, _leaning(clinical, lean), root, feet)
        rotations, origins = lab_frames(joints, offsets, root)
        offset = _centre_of_mass(rotations, origins, person) - root
        momentum = _angular_momentum(rotations, origins, person, period, gait.advance)
        if bounce is not None and ordinal < passes - 3:   # the last passes settle the root
            # the turn for the momentum without it (to first order), so it does not pile up
            inertia = _upper_inertia(rotations, origins, person)
            lean = _flight_turn(momentum - inertia * _periodic_rate(lean, period), inertia,
                                force, period)
        turning = _periodic_rate(momentum, period)
    return root, lean


def _leaning(clinical: np.ndarray, lean: np.ndarray) -> np.ndarray:
    """Template angles (frames, segments, 3) degrees with the trunk's extra turn ``lean``
    (frames, 3) radians about the lab's X, Y, Z added to the thorax's abduction, flexion
    and rotation."""
    leaning = clinical.copy()
    leaning[:, SEGMENT_NAMES.index("thorax")] += np.degrees(lean[:, [1, 0, 2]])
    return leaning


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
    path, lean = _body_path(person, gait, paths, seed)
    path = path - np.outer(grid, gait.advance)
    _follow(paths, person, gait, path, seed)
    root = _periodic_interpolate(path, phase % 1.0) + np.outer(phase, gait.advance)
    clinical = _leaning(_template(person, action, phase, seed),
                        _periodic_interpolate(lean, phase % 1.0))
    joints = _posture(person, clinical, root, [p.in_lab(phase) for p in paths])
    for side in "rl":
        for name in ("thigh", "shank", "foot"):
            i = SEGMENT_NAMES.index(f"{side}_{name}")
            clinical[:, i] = _to_clinical(joints[:, i], i)
    return clinical, root, gait
