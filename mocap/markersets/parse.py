"""Marker-set TOML files: reading, validation, the shipped presets.

A marker set is a TOML file (``docs/formats/markerset-toml.md``)::

    name = "example"

    [[segment]]
    name = "pelvis"                 # the root: no parent
    markers = ["SACR", "MASI", "LASI"]

    [[segment]]
    name = "l_thigh"
    parent = "pelvis"
    markers = ["LHJC", "LKNE", "LTHI"]
    axes = ["e3", "e2", "-e1"]      # optional, see below

    [[virtual]]                     # midpoint (mean) of two or more markers
    name = "MASI"
    type = "midpoint"
    markers = ["RASI", "LASI"]

    [[virtual]]                     # only when the trial has no marker called SACR
    name = "SACR"
    type = "midpoint"
    markers = ["RPSI", "LPSI"]
    fallback = true

    [[virtual]]                     # a fixed offset (metres) in a three-marker frame
    name = "LKNE_FRONT"
    type = "offset"
    markers = ["LKNE", "LANK", "LTIB"]
    offset = [0.0, 0.0, 0.05]

    [[virtual]]                     # hip joint centre regression
    name = "LHJC"
    type = "hip_joint_centre"
    method = "davis"                # davis | bell | harrington
    side = "left"
    markers = ["RASI", "LASI", "SACR"]
    ankle = "LANK"                  # davis: leg length estimated from ASIS-ankle distance
    # leg_length = 0.87             # davis: or given, metres
    marker_diameter = 0.014         # davis: metres

    [[virtual]]                     # Plug-in Gait's knee (or ankle) joint centre
    name = "LKJC"
    type = "joint_centre"
    joint = "knee"                  # knee | ankle: the subject's width and rotation offset
    side = "left"
    markers = ["LTHI", "LHJC", "LKNE"]   # wand, proximal joint centre, marker on the joint
    marker_diameter = 0.014         # when the trial stores no PROCESSING:MarkerDiameter

``markers`` of a segment are origin, axis point and plane point: per frame,
``e1 = unit(p2 - p1)``, ``e3 = unit(e1 x (p3 - p1))``, ``e2 = e3 x e1`` and the
segment's rotation is ``[e1 e2 e3]`` (columns), its origin ``p1``.  The optional
``axes`` (our extension of ``docs/formats/markerset-toml.md``) relabels those columns with a signed
permutation, so that segments whose markers naturally give a different frame
(a thigh whose exact axis is its long axis) can share one anatomical convention:
``axes = ["e3", "e2", "-e1"]`` makes the segment's x axis e3, its y axis e2 and
its z axis -e1.  The permutation must be a proper rotation (determinant +1).
The optional ``origin`` (also an extension) puts the segment's origin at another
marker than the first, e.g. a joint centre.

Virtual markers may use real markers and other virtual markers (in any order; a
cycle is an error).  A virtual marker replaces a recorded marker of the same name,
unless ``fallback = true``: it is then computed only when the trial has no marker
of that name (so one preset serves files with a sacral marker and files with two
posterior iliac spine markers).

Labels with a subject prefix (Vicon's ``"Matt:LASI"``) match the bare name when
exactly one label has it.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from mocap.errors import MocapError, reading
from mocap.resources import data_path
from mocap.tomlfile import parse_toml
from mocap.markersets.axes import AXIS_NAMES, axes_matrix
from mocap.markersets.model import MarkerSet, Segment, VirtualMarker
from mocap.markersets.virtual import HJC_METHODS, JOINT_CENTRES, VIRTUAL_TYPES

#: The shipped presets: ``data/markersets`` (a plain path: importlib.resources and the
#: zipfile and tempfile modules it loads cost ~20 ms of every command's start-up).
PRESETS = data_path("markersets")


def preset_names() -> list[str]:
    """Names of the marker sets shipped with the package."""
    return sorted(p.name[:-5] for p in PRESETS.iterdir() if p.name.endswith(".toml"))


def load_markerset(name_or_path: str | os.PathLike) -> MarkerSet:
    """A shipped preset by name (``"plugingait-lower"``) or a TOML file.

    Raises
    ------
    MocapError
        Unknown preset, unreadable file, or an invalid marker set (the message
        names the file and the problem).
    """
    text_name = os.fspath(name_or_path)
    path = Path(text_name)
    if path.suffix == ".toml" and not path.exists() and path.parent == Path(".") \
            and path.stem in preset_names():
        text_name, path = path.stem, Path(path.stem)          # "plugingait-lower.toml"
    if not path.suffix and not path.exists():
        candidate = PRESETS / f"{text_name}.toml"
        if not candidate.is_file():
            raise MocapError(f"no marker set preset '{text_name}' (presets: "
                             f"{', '.join(preset_names())}; or give a .toml file)")
        return parse_markerset(candidate.read_text(encoding="utf-8-sig"), str(candidate))
    if not path.is_file():
        raise MocapError("marker set file not found", path)
    with reading(path, "marker set"):
        text = path.read_text(encoding="utf-8-sig")
    return parse_markerset(text, str(path))


def parse_markerset(text: str, path: str | None = None) -> MarkerSet:
    """A MarkerSet from TOML text, validated (``path`` names it in errors)."""
    return markerset_from_dict(parse_toml(text, path, "marker set"), path)


def _fail(problem: str, path: str | None) -> MocapError:
    return MocapError(f"invalid marker set: {problem}", path)


def _string_list(value: Any, what: str, path: str | None) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
        raise _fail(f"{what} must be a list of marker names", path)
    return tuple(value)


#: Most segments and virtual markers one marker set may define (full-body sets have ~20
#: segments; a larger file is a mistake, and ordering it must stay quick).
MAX_SEGMENTS = 500
MAX_VIRTUAL = 2000


def markerset_from_dict(data: dict, path: str | None = None) -> MarkerSet:
    """A validated MarkerSet from parsed TOML (see the module docstring)."""
    name = data.get("name", Path(path).stem if path else "markerset")
    if not isinstance(name, str):
        raise _fail("'name' must be a string", path)
    known = {"name", "segment", "virtual", "description"}
    unknown = set(data) - known
    if unknown:
        raise _fail(f"unknown top-level key(s) {', '.join(sorted(unknown))} "
                    f"(expected [[segment]], [[virtual]], name, description)", path)
    raw_segments = data.get("segment", [])
    if not isinstance(raw_segments, list) or not raw_segments:
        raise _fail("no [[segment]] tables", path)
    if len(raw_segments) > MAX_SEGMENTS:
        raise _fail(f"{len(raw_segments)} segments; a marker set may have at most "
                    f"{MAX_SEGMENTS}", path)
    segments = [_parse_segment(i, raw, path) for i, raw in enumerate(raw_segments)]
    _check_names([s.name for s in segments], "segment", path)
    segments = _order_segments(segments, path)

    raw_virtual = data.get("virtual", [])
    if not isinstance(raw_virtual, list):
        raise _fail("'virtual' must be [[virtual]] tables", path)
    if len(raw_virtual) > MAX_VIRTUAL:
        raise _fail(f"{len(raw_virtual)} virtual markers; a marker set may have at most "
                    f"{MAX_VIRTUAL}", path)
    virtual = [_parse_virtual(i, raw, path) for i, raw in enumerate(raw_virtual)]
    _check_names([v.name for v in virtual], "virtual marker", path)
    virtual = _order_virtual(virtual, path)
    return MarkerSet(name=name, segments=segments, virtual=virtual, path=path)


def _check_names(names: list[str], what: str, path: str | None) -> None:
    seen: set[str] = set()
    for n in names:
        if n in seen:
            raise _fail(f"duplicate {what} name '{n}'", path)
        seen.add(n)


def _parse_segment(i: int, raw: Any, path: str | None) -> Segment:
    if not isinstance(raw, dict):
        raise _fail(f"segment #{i + 1} is not a table", path)
    name = raw.get("name")
    if not isinstance(name, str) or not name:
        raise _fail(f"segment #{i + 1} has no name", path)
    unknown = set(raw) - {"name", "parent", "markers", "axes", "origin", "description"}
    if unknown:
        raise _fail(f"segment '{name}': unknown key(s) {', '.join(sorted(unknown))}", path)
    parent = raw.get("parent")
    if parent is not None and (not isinstance(parent, str) or not parent):
        raise _fail(f"segment '{name}': 'parent' must be a segment name", path)
    markers = _string_list(raw.get("markers"), f"segment '{name}': 'markers'", path)
    if len(markers) != 3:
        raise _fail(f"segment '{name}' has {len(markers)} markers; exactly 3 are needed "
                    f"(origin, axis point, plane point)", path)
    if len(set(markers)) != 3:
        raise _fail(f"segment '{name}' uses a marker twice: {', '.join(markers)}", path)
    axes = raw.get("axes", ["e1", "e2", "e3"])
    if (not isinstance(axes, list) or len(axes) != 3
            or not all(isinstance(a, str) and a.lstrip("+-") in AXIS_NAMES for a in axes)
            or sorted(a.lstrip("+-") for a in axes) != ["e1", "e2", "e3"]):
        raise _fail(f"segment '{name}': 'axes' must name e1, e2 and e3 once each, "
                    f"optionally with a sign (e.g. [\"e3\", \"e2\", \"-e1\"])", path)
    if np.linalg.det(axes_matrix(axes)) < 0:
        raise _fail(f"segment '{name}': axes {axes} make a left-handed frame; "
                    f"flip the sign of one axis", path)
    origin = raw.get("origin")
    if origin is not None and (not isinstance(origin, str) or not origin):
        raise _fail(f"segment '{name}': 'origin' must be a marker name", path)
    return Segment(name, parent, markers, tuple(axes), origin)


def _order_segments(segments: list[Segment], path: str | None) -> list[Segment]:
    """Check parents and cycles; return parents before children (stable)."""
    by_name = {s.name: s for s in segments}
    for s in segments:
        if s.parent is not None and s.parent not in by_name:
            raise _fail(f"segment '{s.name}' has unknown parent '{s.parent}'", path)
        if s.parent == s.name:
            raise _fail(f"segment '{s.name}' is its own parent", path)
    depth: dict[str, int] = {}          # segments known to reach a root: their depth
    for s in segments:
        chain = [s.name]
        on_chain = {s.name}
        current = s
        while current.parent is not None and current.name not in depth:
            if current.parent in on_chain:
                cycle = chain[chain.index(current.parent):] + [current.parent]
                raise _fail(f"segment parents form a cycle: {' -> '.join(cycle)}", path)
            chain.append(current.parent)
            on_chain.add(current.parent)
            current = by_name[current.parent]
        base = depth.get(current.name, 0)
        for k, name in enumerate(reversed(chain)):
            depth.setdefault(name, base + k)
    ordered: list[Segment] = []
    placed: set[str] = set()
    while len(ordered) < len(segments):     # at most MAX_SEGMENTS passes
        for s in segments:
            if s.name not in placed and (s.parent is None or s.parent in placed):
                ordered.append(s)
                placed.add(s.name)
    return ordered


def _parse_virtual(i: int, raw: Any, path: str | None) -> VirtualMarker:
    if not isinstance(raw, dict):
        raise _fail(f"virtual marker #{i + 1} is not a table", path)
    name = raw.get("name")
    if not isinstance(name, str) or not name:
        raise _fail(f"virtual marker #{i + 1} has no name", path)
    kind = raw.get("type")
    if kind not in VIRTUAL_TYPES:
        raise _fail(f"virtual marker '{name}': 'type' must be one of "
                    f"{', '.join(VIRTUAL_TYPES)}, not {kind!r}", path)
    allowed = {"name", "type", "markers", "fallback", "description"} | {
        "midpoint": set(), "offset": {"offset"},
        "hip_joint_centre": {"method", "side", "leg_length", "ankle", "marker_diameter"},
        "joint_centre": {"joint", "side", "marker_diameter"},
    }[kind]
    unknown = set(raw) - allowed
    if unknown:
        raise _fail(f"virtual marker '{name}' ({kind}): unknown key(s) "
                    f"{', '.join(sorted(unknown))}", path)
    markers = _string_list(raw.get("markers"), f"virtual marker '{name}': 'markers'", path)
    if name in markers:
        raise _fail(f"virtual marker '{name}' is computed from itself", path)
    fallback = raw.get("fallback", False)
    if not isinstance(fallback, bool):
        raise _fail(f"virtual marker '{name}': 'fallback' must be true or false", path)
    fields: dict[str, Any] = {}
    if kind == "midpoint" and len(markers) < 2:
        raise _fail(f"virtual marker '{name}': a midpoint needs 2 or more markers", path)
    if kind in ("offset", "hip_joint_centre", "joint_centre") and len(markers) != 3:
        what = {"offset": "origin, axis point and plane point",
                "hip_joint_centre": "RASI, LASI and SACR (or the PSIS midpoint)",
                "joint_centre": "wand, proximal joint centre and the marker on the joint",
                }[kind]
        raise _fail(f"virtual marker '{name}' ({kind}) has {len(markers)} markers; "
                    f"exactly 3 are needed ({what})", path)
    if kind == "offset":
        offset = raw.get("offset")
        if (not isinstance(offset, list) or len(offset) != 3
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                           and np.isfinite(x) for x in offset)):
            raise _fail(f"virtual marker '{name}': 'offset' must be 3 numbers (metres)", path)
        fields["offset"] = tuple(float(x) for x in offset)
    if kind == "hip_joint_centre":
        method = raw.get("method", "davis")
        if method not in HJC_METHODS:
            raise _fail(f"virtual marker '{name}': 'method' must be one of "
                        f"{', '.join(HJC_METHODS)}, not {method!r}", path)
        side = raw.get("side")
        if side not in ("left", "right"):
            raise _fail(f"virtual marker '{name}': 'side' must be \"left\" or \"right\"", path)
        fields.update(method=method, side=side)
        for key in ("leg_length", "marker_diameter"):
            if key in raw:
                value = raw[key]
                if (not isinstance(value, (int, float)) or isinstance(value, bool)
                        or not np.isfinite(value) or value < 0
                        or (key == "leg_length" and value == 0)):
                    raise _fail(f"virtual marker '{name}': '{key}' must be a positive "
                                f"number of metres", path)
                if key == "leg_length" and value > 3.0:
                    raise _fail(f"virtual marker '{name}': leg_length {value} looks like "
                                f"millimetres; give metres", path)
                fields[key] = float(value)
        if "ankle" in raw:
            if not isinstance(raw["ankle"], str) or not raw["ankle"]:
                raise _fail(f"virtual marker '{name}': 'ankle' must be a marker name", path)
            fields["ankle"] = raw["ankle"]
        if method == "davis" and "leg_length" not in fields and "ankle" not in fields:
            raise _fail(f"virtual marker '{name}': the davis regression needs "
                        f"'leg_length' (metres) or an 'ankle' marker to estimate it", path)
    if kind == "joint_centre":
        joint, side = raw.get("joint"), raw.get("side")
        if joint not in JOINT_CENTRES:
            raise _fail(f"virtual marker '{name}': 'joint' must be one of "
                        f"{', '.join(JOINT_CENTRES)}, not {joint!r}", path)
        if side not in ("left", "right"):
            raise _fail(f"virtual marker '{name}': 'side' must be \"left\" or \"right\"", path)
        fields.update(joint=joint, side=side)
        if "marker_diameter" in raw:
            value = raw["marker_diameter"]
            if (not isinstance(value, (int, float)) or isinstance(value, bool)
                    or not np.isfinite(value) or not 0 <= value < 0.1):
                raise _fail(f"virtual marker '{name}': 'marker_diameter' must be a "
                            f"number of metres below 0.1", path)
            fields["marker_diameter"] = float(value)
    return VirtualMarker(name=name, type=kind, markers=markers, fallback=fallback, **fields)


def _order_virtual(virtual: list[VirtualMarker], path: str | None) -> list[VirtualMarker]:
    """Inputs before dependants (file order otherwise); a cycle among virtual markers is an
    error. Iterative, linear in the markers and their inputs (any chain depth)."""
    by_name = {v.name: v for v in virtual}
    # a fallback marker's own name may be recorded; a dependency on it is still a
    # dependency on the virtual definition
    needs = {v.name: [item for item in v.inputs if item in by_name] for v in virtual}
    ordered: list[VirtualMarker] = []
    state: dict[str, int] = {}  # 1 on the current path, 2 done
    for root in virtual:
        if state.get(root.name) == 2:
            continue
        path_names = [root.name]
        pending = [iter(needs[root.name])]
        state[root.name] = 1
        while pending:
            item = next(pending[-1], None)
            if item is None:
                done = path_names.pop()
                pending.pop()
                state[done] = 2
                ordered.append(by_name[done])
            elif state.get(item) == 1:
                cycle = path_names[path_names.index(item):] + [item]
                raise _fail(f"virtual markers form a cycle: {' -> '.join(cycle)}", path)
            elif state.get(item) != 2:
                state[item] = 1
                path_names.append(item)
                pending.append(iter(needs[item]))
    return ordered
