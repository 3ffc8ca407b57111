"""The 15-segment body.

* :mod:`mocap.body.segments` — segment names and parents, the default skeleton, joint names
  of other tools mapped onto the segments;
* :mod:`mocap.body.retarget` — motions from world frames, marker trials and foreign skeletons
  (``reduce_to_segments``), and back to a Z-up lab (``motion_to_lab``);
* :mod:`mocap.body.angles` — the one motion ↔ joint angles;
* :mod:`mocap.body.anthropometry` — the one de Leva table, segment inertias;
* :mod:`mocap.body.planting` — feet planted on the floor.
"""
