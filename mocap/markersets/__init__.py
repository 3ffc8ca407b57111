"""Marker sets: which markers define each body segment, and the markers computed from others.

Modules
-------
model
    :class:`MarkerSet`, :class:`Segment`, :class:`VirtualMarker` (the segment tree, marker
    look-up behind subject prefixes, applying virtual markers to a trial).
parse
    Marker-set TOML files (``docs/formats/markerset-toml.md``): :func:`load_markerset`,
    :func:`parse_markerset`, :func:`markerset_from_dict`, :func:`preset_names`.
virtual
    Virtual markers and the hip joint centre regressions (:func:`pelvis_frame`,
    :func:`hip_joint_centre_offset`).
axes
    The three-marker frame (:func:`frame_from_markers`) and a segment's axis permutation.
``data/markersets/``
    The shipped marker sets (``synthetic15``, ``plugingait-lower``, ``plugingait-full``).

Examples
--------
>>> from mocap.markersets import load_markerset
>>> load_markerset("synthetic15").segment_names[:3]
['pelvis', 'thorax', 'head']
"""
from mocap.markersets.axes import axes_matrix, frame_from_markers
from mocap.markersets.model import MarkerSet, Segment, VirtualMarker
from mocap.markersets.parse import (load_markerset, markerset_from_dict, parse_markerset,
                                    preset_names)
from mocap.markersets.virtual import (HJC_METHODS, VIRTUAL_TYPES, hip_joint_centre_offset,
                                      pelvis_frame, virtual_positions)

__all__ = ["MarkerSet", "Segment", "VirtualMarker", "load_markerset", "parse_markerset",
           "markerset_from_dict", "preset_names", "frame_from_markers", "axes_matrix",
           "pelvis_frame", "hip_joint_centre_offset", "virtual_positions", "VIRTUAL_TYPES",
           "HJC_METHODS"]
