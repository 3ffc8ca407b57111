"""Physical animation: forward dynamics (ABA) of the humanoid tracking a motion.

The joints are driven by computed torques: each joint's desired acceleration is the
reference's plus a PD servo on the configuration error, ``a* = a_ref + ω² e + 2ζω ė``
(``e`` from ``pin.difference``, ``ω = 2π·frequency``); the root, unactuated, gets the
acceleration the root rows of ``M a + h − Jᵀf = [assist; τ]`` give with the contact forces
acting now, so the whole body (its composite inertia) responds to the floor; the joint
torques are then RNEA of that acceleration with the contact forces, and ABA with those
torques and forces advances the state (it reproduces the accelerations: the servo decides,
physics moves). A foot that lands earlier, later or elsewhere than the motion says thus
changes the body's motion instead of getting torques meant for another contact state. The root is
not actuated — the body stays up only through its feet on the floor — except for an
optional "root assist" (a helping hand, the root's own servo scaled by ``root_assist``, with
no vertical force — it keeps the body upright and on its path but never holds it up — and
whose force is reported so a user sees how much outside help the motion needs). The floor is a
penalty contact at the foot points (spring-damper along y; tangential spring-damper to the
touch-down point for static friction, capped by the Coulomb cone so the foot slides when
it must). Semi-implicit Euler on the manifold (``pin.integrate``) at 1 kHz.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from mocap.body.retarget import reduce_to_segments
from mocap.progress import progress
from mocap.skeleton import Motion

from dynamics.humanoid.soles import rig_soles
from dynamics.humanoid.kinematics import motion_kinematics
from dynamics.humanoid.model import Humanoid, build_humanoid


@dataclass
class TrackingResult:
    """A simulated motion and what it took.

    Attributes
    ----------
    motion : Motion
        The simulated motion on the body skeleton, at the reference's frame rate.
    assist_force : ndarray, shape (frames,), N
        Magnitude of the root-assist force (0 when the assist is off).
    contact_force : ndarray, shape (frames, 3), N
        Total ground reaction force (world axes).
    joint_error_deg : ndarray, shape (frames,)
        Mean angle between simulated and reference joint rotations.
    root_error_m : ndarray, shape (frames,)
        Distance between simulated and reference root positions.
    """

    motion: Motion
    assist_force: np.ndarray
    contact_force: np.ndarray
    joint_error_deg: np.ndarray
    root_error_m: np.ndarray


def simulate_tracking(motion: Motion, body_mass: float = 75.0, sex: str = "male",
                      dt: float = 1e-3, frequency: float = 8.0, damping_ratio: float = 1.0,
                      root_assist: float = 0.25, ground_stiffness: float = 3.0e4,
                      ground_damping: float = 600.0, mu: float = 0.8,
                      humanoid: Humanoid | None = None) -> TrackingResult:
    """Simulate the body tracking a motion with PD servos and penalty ground contact.

    Parameters
    ----------
    motion : Motion
        Any skeleton our body model can map; floor y = 0, Y up. A rig whose feet end at
        joints (BVH, ASF) stands on the soles the check lays out below them
        (:func:`dynamics.humanoid.soles.rig_soles`), not on the joints.
    body_mass : float, kg
    sex : {"male", "female"}
    dt : float, s
        Integration step (stiff contacts need about 1 ms).
    frequency : float, Hz
        Natural frequency of the joint servos.
    damping_ratio : float
    root_assist : float
        Fraction of the root's own servo applied as an outside helping wrench, horizontal
        force and torque only (0: none, the body may topple when the motion does not
        balance; 1: the root follows the motion's path and orientation).
    ground_stiffness : float, N/m per contact point (6 points per foot)
    ground_damping : float, N·s/m per contact point (the defaults damp the body's bounce on
        its feet at about 0.7 of critical)
    mu : float
        Friction coefficient.
    humanoid : Humanoid, optional

    Returns
    -------
    TrackingResult
    """
    # deferred: Pinocchio is imported only by the code that builds or runs a model
    import pinocchio as pin

    body = reduce_to_segments(motion, partial=True)
    if humanoid is None:
        humanoid = build_humanoid(body.skeleton, body_mass, sex)
    if body.metadata.get("feet_at_joints"):
        # A rig's feet end at joints: it stands on the soles the check finds below them.
        humanoid = humanoid.with_contact_points(rig_soles(body, humanoid)[0])
    model = humanoid.model
    data = model.createData()
    kin = motion_kinematics(body)

    omega = 2.0 * np.pi * frequency
    kp, kd = omega ** 2, 2.0 * damping_ratio * omega        # acceleration-level servo gains

    # Tangential springs a little softer than the normal ones (sliding is resisted less
    # stiffly than sinking); the explicit damper needs c·dt/m < 2 for the body mass m.
    tangential_stiffness, tangential_damping = ground_stiffness / 2.0, ground_damping / 2.0
    contact_joint = [model.frames[f].parentJoint for f in humanoid.contact_frames]
    frame_time = 1.0 / body.rate
    steps_per_frame = max(1, int(round(frame_time / dt)))
    h = frame_time / steps_per_frame
    q, v = kin.q[0].copy(), kin.v[0].copy()
    recorded = np.empty_like(kin.q)
    assist = np.zeros(body.frames)
    contact_total = np.zeros((body.frames, 3))
    zero_force = pin.Force.Zero()
    anchors: list[np.ndarray | None] = [None] * len(humanoid.contact_frames)
    # Time stepping is sequential (each state depends on the previous one).
    for frame in progress(range(body.frames), "replaying under physics"):
        recorded[frame] = q
        if frame == body.frames - 1:
            break
        total = np.zeros(3)
        for sub in range(steps_per_frame):
            fraction = sub / steps_per_frame
            q_ref = pin.interpolate(model, kin.q[frame], kin.q[frame + 1], fraction)
            v_ref = (1 - fraction) * kin.v[frame] + fraction * kin.v[frame + 1]
            blend = lambda x: (1 - fraction) * x[frame] + fraction * x[frame + 1]  # noqa: E731
            pin.forwardKinematics(model, data, q, v)
            pin.updateFramePlacements(model, data)
            fext = pin.StdVec_Force()
            for _ in range(model.njoints):
                fext.append(zero_force)
            touching = set()
            for k, frame_id in enumerate(humanoid.contact_frames):
                position = data.oMf[frame_id].translation
                if position[1] >= 0.0:
                    anchors[k] = None
                    continue
                velocity = pin.getFrameVelocity(model, data, frame_id,
                                                pin.LOCAL_WORLD_ALIGNED).linear
                normal = max(0.0, -ground_stiffness * position[1]
                             - ground_damping * velocity[1])
                force = _friction(position, velocity, normal, anchors, k, tangential_stiffness,
                                  tangential_damping, mu)
                force[1] = normal
                touching.add(k)
                total += force / steps_per_frame
                joint = contact_joint[k]
                placement = data.oMi[joint]
                local_force = placement.rotation.T @ force
                lever = placement.rotation.T @ (position - placement.translation)
                fext[joint] = fext[joint] + pin.Force(local_force, np.cross(lever, local_force))
            # Joints follow the reference exactly up to the servo: desired accelerations.
            error = pin.difference(model, q, q_ref)
            desired = blend(kin.a) + kp * error + kd * (v_ref - v)
            # The root is free: its acceleration follows from the root rows of
            # M a + h − Jᵀf = [assist, τ] with the joints' accelerations imposed.
            mass_matrix = pin.crba(model, data, q)
            root_block = np.triu(mass_matrix[:6, :6]) + np.triu(mass_matrix[:6, :6], 1).T
            bias = pin.rnea(model, data, q, v, np.zeros(model.nv), fext)      # h − Jᵀf
            # The helping hand keeps the body upright and on its path, but never holds it
            # up: no vertical force (support must come from the floor).
            wrench = root_assist * (root_block @ desired[:6])
            rotation = data.oMi[1].rotation
            upward = rotation.T @ np.array([0.0, 1.0, 0.0])             # world up, root frame
            wrench[:3] -= (wrench[:3] @ upward) * upward
            desired[:6] = np.linalg.solve(
                root_block, wrench - bias[:6] - mass_matrix[:6, 6:] @ desired[6:])
            tau = pin.rnea(model, data, q, v, desired, fext)
            tau[:6] = wrench            # only the assist acts on the root; ABA checks the rest
            acceleration = pin.aba(model, data, q, v, tau, fext)
            v = v + h * acceleration
            q = pin.integrate(model, q, v * h)
        root_rotation = Rotation.from_quat(q[3:7]).as_matrix()
        assist[frame + 1] = np.linalg.norm(root_rotation @ tau[:3])
        contact_total[frame + 1] = total

    skeleton = body.skeleton
    quats = recorded[:, 3:].reshape(body.frames, skeleton.count, 4)
    rotations = Rotation.from_quat(quats.reshape(-1, 4)).as_matrix().reshape(
        body.frames, skeleton.count, 3, 3)
    simulated = Motion(skeleton, recorded[:, :3] - skeleton.offsets[0], rotations, body.rate,
                       {"source": motion.metadata.get("source"), "simulated": True})
    relative = np.einsum("fsji,fsjk->fsik", kin.rotations, rotations)
    angle = np.degrees(np.arccos(np.clip((np.trace(relative, axis1=2, axis2=3) - 1) / 2,
                                         -1.0, 1.0)))
    return TrackingResult(simulated, assist, contact_total, angle[:, 1:].mean(axis=1),
                          np.linalg.norm(recorded[:, :3] - kin.q[:, :3], axis=1))


def _friction(position: np.ndarray, velocity: np.ndarray, normal: float, anchors: list,
              k: int, stiffness: float, damping: float, mu: float) -> np.ndarray:
    """Tangential ground force at one contact point: a spring-damper to the point where it
    touched down (static friction), capped at the Coulomb limit ``mu · normal`` (sliding,
    the anchor is dragged along). Updates ``anchors[k]``; returns the force (y = 0)."""
    planar = np.array([position[0], 0.0, position[2]])
    if anchors[k] is None:
        anchors[k] = planar.copy()
    stretch = planar - anchors[k]
    force = -stiffness * stretch - damping * np.array([velocity[0], 0.0, velocity[2]])
    size = np.linalg.norm(force)
    limit = mu * normal
    if size > limit:
        force *= limit / size
        # Slip: move the anchor so the spring alone would give the limit force.
        anchors[k] = planar + force / stiffness
    return force
