"""Rotations: Euler/Cardan angles, quaternions, segment frames from markers, joint angles.

Modules
-------
euler
    Euler/Cardan angles of rotation matrices in closed form, whole-array numpy.
quaternions
    Unit quaternions and rotation matrices, vectorised over any leading axes.
frames
    Segment frames from three markers per segment (``docs/formats/markerset-toml.md``).
angles
    Joint angles: relative segment rotations as continuous Euler/Cardan angles
    (:func:`~mocap.rotations.angles.joint_angles`, :class:`~mocap.rotations.angles.JointAngles`).

Importing the package loads none of them; import the module you need.
"""
