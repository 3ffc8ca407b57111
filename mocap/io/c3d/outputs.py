"""Model outputs that a C3D file stores as points, told apart from the markers.

Vicon Nexus (Plug-in Gait, the Oxford Foot Model) and other modelling packages write what
they computed into the POINT section beside the captured markers. Two kinds exist:

- **outputs listed by kind** in POINT:ANGLES, FORCES, MOMENTS, POWERS, SCALARS or
  REACTIONS (``LKneeAngles``, ``LHipMoment`` …): not positions at all (degrees, N, N·mm,
  W). :func:`listed_outputs` reads those lists; the reader keeps these points in
  ``trial.modelled``.
- **positions the model computed**, which no parameter lists: each segment's axis points
  (Plug-in Gait's origin, anterior, lateral and proximal points ``PELO/PELA/PELL/PELP``,
  ``HEDO`` …, and the Oxford Foot Model's numbered ``LFOF0`` … ``LFOF3``), joint centres
  (``LHJC``, ``RAJC``), the centre of mass (``CentreOfMass``, ``CentreOfMassFloor``) and the
  Oxford Foot Model's virtual points (``LHE1``, ``LD1M0``, ``LPROXFF``, ``LArchHeight``).
  They are positions in the file's unit, so the reader keeps them among the points (code
  reading ``trial.marker("PELO")`` goes on working); :func:`computed_positions` names them
  from their labels so that ``mocap info`` counts them apart and ``mocap convert`` writes
  the markers only (OpenSim would otherwise track ``HEDO`` as a marker).

The axis points are recognised as whole sets only (all of ``X`` + O, A, L, P; or ``X`` + 0,
1, 2, 3; the Oxford tibia's ``LTIB1`` … ``LTIB3``), so a marker set that happens to use
one such name keeps it as a marker, and numbered marker clusters (``ArmL1`` … ``ArmL4``,
``Marker_1`` …) stay markers: their numbers start at 1.
"""
from __future__ import annotations

import re

#: POINT parameters listing computed (non-marker) points, as Vicon and others write them.
MODELLED_KINDS = ("ANGLES", "FORCES", "MOMENTS", "POWERS", "SCALARS", "REACTIONS")

#: Kinds of computed positions, as :func:`computed_positions` names them.
AXES = "axis points"
CENTRES = "joint centres"
CENTRE_OF_MASS = "centre of mass"
VIRTUAL = "virtual points"

#: Plug-in Gait's axis-point suffixes: origin, anterior, lateral, proximal.
_PIG_AXIS_SUFFIXES = ("O", "A", "L", "P")
#: The Oxford Foot Model's virtual points (after the side letter), as Nexus writes them.
_OFM_VIRTUAL = ("HE1", "D1M0", "PROXFF", "ArchHeight")
#: The Oxford Foot Model's tibia axes (its origin is the tibia marker itself, LTIB).
_OFM_TIBIA = re.compile(r"^[LR]TIB[123]$")
_JOINT_CENTRE = re.compile(r"^[LR][A-Z]{1,3}JC(_[A-Za-z0-9_.]+)?$")
_CENTRE_OF_MASS = re.compile(r"^(Centre|Center)OfMass", re.IGNORECASE)


def _string_list(value) -> list[str]:
    if isinstance(value, str):
        return [value] if value else []
    if isinstance(value, list):
        return [str(v) for v in value]
    return []


def listed_outputs(point_group: dict) -> dict[str, str]:
    """Labels that POINT:ANGLES, FORCES … list, each with its kind (``"ANGLES"`` …).

    Parameters
    ----------
    point_group : dict
        The file's POINT group (``trial.parameters["POINT"]``).

    Examples
    --------
    >>> listed_outputs({"ANGLES": ["LKneeAngles "], "POWERS": ["LHipPower"]})
    {'LKneeAngles': 'ANGLES', 'LHipPower': 'POWERS'}
    """
    kinds: dict[str, str] = {}
    for kind in MODELLED_KINDS:
        for label in _string_list(point_group.get(kind)):
            if label.strip():
                kinds.setdefault(label.strip(), kind)
    return kinds


def computed_positions(labels: list[str]) -> dict[str, str]:
    """Labels of positions a model computed, each with its kind; the rest are markers.

    Parameters
    ----------
    labels : list of str
        A trial's point labels.

    Returns
    -------
    dict
        label -> :data:`AXES`, :data:`CENTRES`, :data:`CENTRE_OF_MASS` or :data:`VIRTUAL`,
        in the order of ``labels``.

    Examples
    --------
    >>> computed_positions(["PELO", "PELA", "PELL", "PELP", "LASI", "LHJC", "CentreOfMass"])
    {'PELO': 'axis points', 'PELA': 'axis points', 'PELL': 'axis points', 'PELP': 'axis points', 'LHJC': 'joint centres', 'CentreOfMass': 'centre of mass'}
    >>> computed_positions(["PELO", "LASI"])           # no whole set: a marker
    {}
    """
    present = set(labels)
    found: dict[str, str] = {}
    for label in labels:
        stem, last = label[:-1], label[-1:]
        name = label.rsplit(":", 1)[-1]             # without a subject prefix ("Matt:LHJC")
        if len(stem) >= 2 and last in _PIG_AXIS_SUFFIXES \
                and all(stem + s in present for s in _PIG_AXIS_SUFFIXES):
            found[label] = AXES
        elif len(stem) >= 2 and last in "0123" and not stem[-1].isdigit() \
                and all(stem + s in present for s in "0123"):
            found[label] = AXES                     # origin 0 and axes 1-3 (Oxford Foot Model)
        elif _OFM_TIBIA.match(name) and all(stem + s in present for s in "123"):
            found[label] = AXES
        elif _JOINT_CENTRE.match(name):
            found[label] = CENTRES
        elif _CENTRE_OF_MASS.match(name):
            found[label] = CENTRE_OF_MASS
        elif name[:1] in ("L", "R") and name[1:] in _OFM_VIRTUAL:
            found[label] = VIRTUAL
    return found


def marker_labels(labels: list[str]) -> list[str]:
    """``labels`` without the computed positions (:func:`computed_positions`), in order."""
    computed = computed_positions(labels)
    return [label for label in labels if label not in computed]


__all__ = ["MODELLED_KINDS", "AXES", "CENTRES", "CENTRE_OF_MASS", "VIRTUAL", "listed_outputs",
           "computed_positions", "marker_labels"]
