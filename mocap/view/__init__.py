"""``mocap view``: an interactive 3-D viewer of trials and motions in one HTML file.

Modules
-------
scene
    What a view shows as arrays (:class:`Scene`, :class:`Layer`, plates, forces, curves).
sources
    Files to a scene (:func:`view_files`).
page
    A scene to one self-contained page (:class:`View`: ``write``, ``html``, Jupyter).
viewer.js, viewer.css, viewer.html, vendor/
    The player in the page and the vendored three.js (MIT).

Examples
--------
>>> from mocap.view import view_files                          # doctest: +SKIP
>>> view_files(["walk.c3d", "walk_synthesised.bvh"]).write("walk.html")   # doctest: +SKIP
"""
from mocap.view.page import View, page_html
from mocap.view.scene import (Curves, ForceTrack, Layer, PlateTrack, Scene, angle_curves,
                              marker_layer, plate_tracks, skeleton_layer)
from mocap.view.sources import file_layers, view_files

__all__ = ["View", "page_html", "Scene", "Layer", "PlateTrack", "ForceTrack", "Curves",
           "marker_layer", "skeleton_layer", "plate_tracks", "angle_curves", "view_files",
           "file_layers"]
