"""One self-contained HTML page from a :class:`~mocap.view.scene.Scene`.

The page holds, inline: the vendored three.js (``vendor/three.view.min.js``, MIT, licence
in ``vendor/three.LICENSE``), the viewer (``viewer.js``, ``viewer.css``) and the data as
one JSON block. It fetches nothing, so it opens from disk, from an e-mail, inside an
``<iframe>`` or as a Jupyter cell's output (:meth:`View._repr_html_`).

Size: every moving array travels as little-endian float32 in base64 (4 bytes per number,
4/3 for the encoding: 5.3 bytes per coordinate, NaN kept for gaps), so a 10 s, 40-marker,
100 Hz trial is 0.64 MB of data beside the 0.57 MB of three.js.
"""
from __future__ import annotations

import base64
import html
import json
import os
from importlib import resources
from pathlib import Path

import numpy as np

from mocap.atomic import atomic_path
from mocap.view.scene import Scene

#: Colours of the layers, in order (then again): blue, orange-red, green, purple, amber, teal.
PALETTE = ("#2f7fc1", "#e4572e", "#3aa655", "#9b59b6", "#f0a202", "#17becf")
#: Colours of the plate reactions and of the check's estimated reaction.
PLATE_COLOUR, CHECK_COLOUR = "#d62728", "#8c2bd6"


def _f32(values: np.ndarray) -> str:
    """base64 of the values as little-endian float32, row-major."""
    return base64.b64encode(np.ascontiguousarray(values, dtype="<f4").tobytes()).decode("ascii")


def _asset(name: str) -> str:
    return resources.files("mocap.view").joinpath(name).read_text(encoding="utf-8")


def scene_payload(scene: Scene) -> dict:
    """The JSON object the page's script reads (arrays as base64 float32)."""
    layers = []
    for k, layer in enumerate(scene.layers):
        layers.append({
            "name": layer.name, "kind": layer.kind, "rate": layer.rate,
            "frames": layer.frames, "count": len(layer.labels), "labels": layer.labels,
            "bones": layer.bones.reshape(-1).tolist(),
            "virtual": np.flatnonzero(layer.virtual).tolist(), "skeleton": layer.skeleton,
            "colour": PALETTE[k % len(PALETTE)], "points": _f32(layer.points)})
    plates = [{"name": p.name, "corners": np.asarray(p.corners, float).reshape(-1).tolist(),
               "rate": p.rate, "frames": int(len(p.force)), "force": _f32(p.force),
               "point": _f32(p.cop), "colour": PLATE_COLOUR} for p in scene.plates]
    forces = [{"name": f.name, "rate": f.rate, "frames": int(len(f.force)),
               "force": _f32(f.force), "point": _f32(f.point), "colour": CHECK_COLOUR}
              for f in scene.forces]
    curves = None
    if scene.curves is not None:
        c = scene.curves
        curves = {"columns": list(c.columns), "samples": int(len(c.times)),
                  "times": _f32(c.times), "values": _f32(c.values)}
    return {"title": scene.title, "up": scene.up, "notes": list(scene.notes),
            "layers": layers, "plates": plates, "forces": forces, "curves": curves}


def page_html(scene: Scene) -> str:
    """The whole page as a string (see the module docstring)."""
    data = json.dumps(scene_payload(scene), separators=(",", ":"), allow_nan=False)
    data = data.replace("</", "<\\/")           # the JSON cannot end its <script> block
    title = html.escape(scene.title or "mocap view")
    three = _asset("vendor/three.view.min.js")
    if "</script" in three.lower():             # never true of the shipped build
        raise ValueError("the vendored three.js holds '</script' and cannot be inlined")
    return (
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
        f"<meta name=\"generator\" content=\"mocap view\"><title>{title}</title>\n"
        f"<style>{_asset('viewer.css')}</style></head>\n<body>\n"
        f"{_asset('viewer.html')}\n"
        f"<script type=\"application/json\" id=\"mocap-view-data\">{data}</script>\n"
        "<!-- three.js r187, (c) 2010-2026 three.js authors, MIT licence "
        "(mocap/view/vendor/three.LICENSE) -->\n"
        f"<script>{three}</script>\n<script>{_asset('viewer.js')}</script>\n"
        "</body></html>\n")


class View:
    """A viewer page for a scene: write it, or show it in Jupyter.

    Parameters
    ----------
    scene : Scene

    In Jupyter, a View as a cell's value shows the viewer.

    Examples
    --------
    >>> from mocap.view import view_files               # doctest: +SKIP
    >>> v = view_files(["walk.c3d"])                    # doctest: +SKIP
    >>> v.write("walk.html")                            # doctest: +SKIP
    >>> v                      # doctest: +SKIP
    """

    def __init__(self, scene: Scene):
        self.scene = scene

    def html(self) -> str:
        """The self-contained page (:func:`page_html`)."""
        return page_html(self.scene)

    def write(self, path: str | os.PathLike) -> int:
        """Write the page to ``path`` (all or nothing); its size in bytes."""
        text = self.html().encode("utf-8")
        with atomic_path(path) as tmp:
            Path(tmp).write_bytes(text)
        return len(text)

    def _repr_html_(self) -> str:
        """The page in an ``<iframe srcdoc>``, so that it runs apart from the notebook."""
        return (f"<iframe srcdoc=\"{html.escape(self.html(), quote=True)}\" "
                "style=\"width:100%;height:760px;border:0\" "
                "title=\"mocap view\"></iframe>")
