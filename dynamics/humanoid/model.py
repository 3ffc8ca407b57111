"""The humanoid model: a Pinocchio body built from a 15-segment skeleton.

The body is built from a 15-segment :class:`~mocap.skeleton.Skeleton` (free-flyer root at
the pelvis, spherical joints elsewhere) with de Leva (1996) inertias scaled by body mass
and the skeleton's segment lengths (:mod:`mocap.body.anthropometry`), and six contact
points per foot (heel and ball, medial and lateral, plus heel and toe on the long axis).

This is the *model* half of Pinocchio's model/data split: :class:`Humanoid` is the constant
description of the body; the per-frame work lives in :mod:`dynamics.humanoid.kinematics`
(q, v, a of a motion), :mod:`dynamics.humanoid.inverse` (RNEA, joint torques),
:mod:`dynamics.humanoid.contact` (ground reaction forces) and
:mod:`dynamics.humanoid.check` (the plausibility check). The Pinocchio ``Data`` buffers
those algorithms need are kept on the humanoid (:meth:`Humanoid.model_pool`), not in a
module-level cache.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from mocap.body.anthropometry import (SegmentInertia, foot_points, lumped_segments,
                                      segment_inertias)
from mocap.errors import MocapError
from mocap.body.segments import BODY_SEGMENTS, LOWER_BODY
from mocap.skeleton import Skeleton

GRAVITY = 9.81
#: The joint at the proximal end of each body segment (joint torques are named by segment).
JOINT_OF_SEGMENT = {"thorax": "lumbar", "head": "neck", "upperarm": "shoulder",
                    "forearm": "elbow", "hand": "wrist", "thigh": "hip", "shank": "knee",
                    "foot": "ankle"}


@dataclass
class Humanoid:
    """The constant description of the body: Pinocchio model, inertias and contact points.

    Attributes
    ----------
    model : pinocchio.Model
        Free-flyer root (nq 7, nv 6) then one spherical joint (nq 4, nv 3) per segment, in
        skeleton order; gravity -9.81 m/s² along Y.
    skeleton : Skeleton
        The 15-segment body.
    mass : float, kg
    inertias : list of SegmentInertia
    contact_points : ndarray, shape (points, 3), metres
        Contact points in their segment's frame.
    contact_segments : list of int
        Segment index of each contact point.
    contact_names : list of str
        ``<foot>.<point>``.
    contact_frames : list of int
        Pinocchio frame id of each contact point.
    lumped : list of (name, segment index, SegmentInertia)
        Body segments the skeleton lacks (a lower-body marker set: head, arms, trunk),
        carried rigidly by a present segment (``mocap.body.anthropometry.lumped_segments``).
    """

    model: object
    skeleton: Skeleton
    mass: float
    inertias: list[SegmentInertia]
    contact_points: np.ndarray
    contact_segments: list[int]
    contact_names: list[str]
    contact_frames: list[int]
    lumped: list = field(default_factory=list)
    #: Pinocchio ModelPools by size (``rnea_batch``'s Data buffers), built on first use.
    pools: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    @property
    def weight(self) -> float:
        """Body weight in newtons."""
        return self.mass * GRAVITY

    @property
    def nq(self) -> int:
        return int(self.model.nq)

    @property
    def nv(self) -> int:
        return int(self.model.nv)

    def with_contact_points(self, points: np.ndarray) -> "Humanoid":
        """The same body with its contact points (and their Pinocchio frames) moved.

        Parameters
        ----------
        points : ndarray, shape (points, 3), metres
            New contact points in their segment's frame, in ``contact_points`` order (a
            rig's soles, :func:`dynamics.humanoid.soles.rig_soles`).

        Returns
        -------
        Humanoid
            A copy (its own model); this one is unchanged.
        """
        # deferred: Pinocchio is imported only by the code that builds or runs a model
        import pinocchio as pin

        points = np.array(points, dtype=float)
        if points.shape != self.contact_points.shape:
            raise ValueError(f"expected contact points of shape {self.contact_points.shape}, "
                             f"got {points.shape}")
        model = pin.Model(self.model)
        for frame_id, point in zip(self.contact_frames, points):
            frame = model.frames[frame_id]
            frame.placement = pin.SE3(np.eye(3), point.copy())
            model.frames[frame_id] = frame
        return replace(self, model=model, contact_points=points)

    def model_pool(self, size: int):
        """A Pinocchio ``ModelPool`` of ``size`` Data objects for this model.

        Built on first use and kept on the humanoid (one per size), so repeated batched
        calls reuse the buffers and they live exactly as long as the model.
        """
        # deferred: Pinocchio is imported only by the code that builds or runs a model
        import pinocchio as pin

        if size not in self.pools:
            self.pools[size] = pin.ModelPool(self.model, size)
        return self.pools[size]


def build_humanoid(skeleton: Skeleton, body_mass: float = 75.0, sex: str = "male"
                   ) -> Humanoid:
    """A Pinocchio model of the 15-segment body.

    Parameters
    ----------
    skeleton : Skeleton
        With the segment names of ``mocap.body.segments.BODY_SEGMENTS`` (reduce foreign
        skeletons with ``reduce_to_segments``); end sites give the hands, head top and toes.
    body_mass : float, kg
    sex : {"male", "female"}
        Which de Leva table.

    Returns
    -------
    Humanoid
    """
    # deferred: Pinocchio is imported only by the code that builds or runs a model
    import pinocchio as pin

    names = skeleton.names
    if not set(LOWER_BODY) <= set(names) <= set(BODY_SEGMENTS) or \
            names != [n for n in BODY_SEGMENTS if n in names]:
        raise MocapError("the body model needs the 15 body segments ("
                         + ", ".join(BODY_SEGMENTS) + "), or at least the pelvis and legs, "
                         f"in that order; got {', '.join(names)}")
    if not body_mass > 0:
        raise MocapError(f"body mass must be positive, got {body_mass}")
    try:
        inertias = segment_inertias(skeleton, body_mass, sex)
        lumped = lumped_segments(skeleton, body_mass, sex)
    except ValueError as error:
        raise MocapError(str(error)) from None
    model = pin.Model()
    model.name = "humanoid"
    model.gravity = pin.Motion(np.array([0.0, -GRAVITY, 0.0, 0.0, 0.0, 0.0]))
    joint_ids = []
    for i, (name, parent) in enumerate(zip(skeleton.names, skeleton.parents)):
        if parent < 0:
            joint = pin.JointModelFreeFlyer()
            placement = pin.SE3.Identity()
            parent_joint = 0
        else:
            joint = pin.JointModelSpherical()
            placement = pin.SE3(np.eye(3), skeleton.offsets[i].copy())
            parent_joint = joint_ids[parent]
        joint_id = model.addJoint(parent_joint, joint, placement, name)
        segment = inertias[i]
        model.appendBodyToJoint(joint_id, pin.Inertia(segment.mass, segment.com.copy(),
                                                      segment.inertia.copy()),
                                pin.SE3.Identity())
        model.addJointFrame(joint_id)
        joint_ids.append(joint_id)
    for _, host, part in lumped:
        model.appendBodyToJoint(joint_ids[host], pin.Inertia(part.mass, part.com.copy(),
                                                             part.inertia.copy()),
                                pin.SE3.Identity())
    points, segments, names, frames = [], [], [], []
    for foot in ("l_foot", "r_foot"):
        index = skeleton.index(foot)
        for label, point in foot_points(skeleton.end_sites[index]).items():
            frame = pin.Frame(f"{foot}.{label}", joint_ids[index], pin.SE3(np.eye(3), point),
                              pin.FrameType.OP_FRAME)
            frames.append(model.addFrame(frame, False))
            points.append(point)
            segments.append(index)
            names.append(f"{foot}.{label}")
    return Humanoid(model, skeleton, float(body_mass), inertias, np.array(points), segments,
                    names, frames, lumped)
