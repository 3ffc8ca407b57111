"""The Gait Profile Score and its Gait Variable Scores (Baker et al. 2009).

Baker R, McGinley JL, Schwartz MH, Beynon S, Rozumalski A, Graham HK, Tirosh O (2009).
The Gait Profile Score and Movement Analysis Profile. *Gait & Posture* 30:265-269.

A Gait Variable Score (GVS) is the root mean square difference, over the gait cycle,
between one kinematic curve of a cycle and the normative mean of that variable, in
degrees. The nine variables of each side (:data:`GPS_VARIABLES`): pelvic tilt, obliquity
and rotation, hip flexion, adduction and rotation, knee flexion, ankle dorsiflexion, foot
progression. A side's GPS is the RMS of its nine GVS; the overall GPS the RMS of fifteen:
both sides' hip, knee, ankle and foot progression and the left pelvis (the right side's
pelvis is the same curve half a cycle later, so Baker counts it once).

The curves are compared on the normative set's samples (51 points every 2 % as Baker's,
or 101 every 1 %): a cycle at another sampling is interpolated linearly onto them. Each
cycle is scored on its own, then a side's GVS and GPS are the means over its cycles.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from mocap.plugingait.normative import Normative

#: Baker's nine kinematic variables of a side: (Vicon name, component 0/1/2 = X/Y/Z, title).
GPS_VARIABLES: tuple[tuple[str, int, str], ...] = (
    ("PelvisAngles", 0, "Pelvic tilt"), ("PelvisAngles", 1, "Pelvic obliquity"),
    ("PelvisAngles", 2, "Pelvic rotation"), ("HipAngles", 0, "Hip flexion"),
    ("HipAngles", 1, "Hip adduction"), ("HipAngles", 2, "Hip rotation"),
    ("KneeAngles", 0, "Knee flexion"), ("AnkleAngles", 0, "Ankle dorsiflexion"),
    ("FootProgressAngles", 2, "Foot progression"),
)


@dataclass
class GaitScores:
    """GVS and GPS of one walk (or several walks of one subject pooled), degrees.

    Attributes
    ----------
    titles : list of str
        The nine variables, :data:`GPS_VARIABLES` order.
    gvs : dict of str to ndarray, shape (9,)
        Per side ``"l"``/``"r"``: each variable's GVS, the mean over the side's cycles
        (NaN: no cycle has the variable).
    gvs_cycles : dict of str to ndarray, shape (cycles, 9)
        Per side, per cycle.
    gps : dict of str to float
        Per side: the mean over its cycles of each cycle's GPS (the RMS of its GVS).
    overall : float
        RMS of the fifteen GVS (both sides, the pelvis of the left side only; of the right
        side when the left has no cycle).
    missing : list of str
        Variables no cycle had: the GPS is over the others (Baker's is over all nine).
    """

    titles: list
    gvs: dict
    gvs_cycles: dict
    gps: dict
    overall: float
    missing: list


def rms_difference(curves: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """RMS over the cycle of ``curves - reference``.

    Parameters
    ----------
    curves : ndarray, shape (..., samples)
    reference : ndarray, shape (samples,)

    Returns
    -------
    ndarray, shape (...): NaN where any sample of the curve is NaN.

    Examples
    --------
    >>> rms_difference(np.array([[1.0, 1.0, 1.0], [0.0, 3.0, 4.0]]), np.zeros(3)).round(4)
    array([1.    , 2.8868])
    """
    return np.sqrt(np.mean((np.asarray(curves, float) - reference) ** 2, axis=-1))


def _on_samples(values: np.ndarray, samples: int) -> np.ndarray:
    """(cycles, n, ...) at ``n`` points over 0-100 % -> (cycles, samples, ...), linearly."""
    n = values.shape[1]
    if n == samples:
        return values
    source, target = np.linspace(0.0, 1.0, n), np.linspace(0.0, 1.0, samples)
    right = np.clip(np.searchsorted(source, target, side="right"), 1, n - 1)
    left = right - 1
    weight = ((target - source[left]) / (source[right] - source[left]))
    shape = (1, samples) + (1,) * (values.ndim - 2)
    weight = weight.reshape(shape)
    return values[:, left] * (1 - weight) + values[:, right] * weight


def gait_scores(curves, normative: Normative) -> GaitScores:
    """GVS and GPS of the cycles in ``curves`` against ``normative``'s means.

    Parameters
    ----------
    curves : CycleCurves or list of CycleCurves
        (:mod:`mocap.plugingait.curves`); several are pooled (every cycle counts once).
    normative : Normative

    Returns
    -------
    GaitScores
    """
    from mocap.errors import MocapError

    pooled = curves if isinstance(curves, (list, tuple)) else [curves]
    needed = {name for name, _, _ in GPS_VARIABLES}
    lacking = sorted(needed - set(normative.mean))
    if lacking:
        raise MocapError(f"the normative set {normative.name!r} has no {', '.join(lacking)}")
    samples = normative.samples
    titles = [title for _, _, title in GPS_VARIABLES]
    gvs, per_cycle, gps = {}, {}, {}
    present = np.zeros(len(GPS_VARIABLES), dtype=bool)
    for side in ("l", "r"):
        rows = []
        for c in pooled:
            mine = c.of_side(side)
            count = int(sum(s == side for s in c.side))
            if not count:
                continue
            block = np.full((count, len(GPS_VARIABLES)), np.nan)
            for k, (name, component, _) in enumerate(GPS_VARIABLES):
                if name not in mine:
                    continue
                values = _on_samples(mine[name][:, :, component], samples)
                block[:, k] = rms_difference(values, normative.mean[name][:, component])
            rows.append(block)
        table = np.concatenate(rows) if rows else np.zeros((0, len(GPS_VARIABLES)))
        per_cycle[side] = table
        present |= np.isfinite(table).any(axis=0)
        with warnings.catch_warnings():                 # a variable no cycle has: NaN
            warnings.simplefilter("ignore", RuntimeWarning)
            gvs[side] = np.nanmean(table, axis=0) if len(table) else \
                np.full(len(GPS_VARIABLES), np.nan)
            cycle_gps = np.sqrt(np.nanmean(table ** 2, axis=1)) if len(table) else table[:, 0]
            gps[side] = float(np.nanmean(cycle_gps)) if len(cycle_gps) else float("nan")
    pelvis = np.array([name == "PelvisAngles" for name, _, _ in GPS_VARIABLES])
    pelvis_side = "l" if np.isfinite(gvs["l"][pelvis]).any() else "r"
    fifteen = np.concatenate([gvs["l"][~pelvis], gvs["r"][~pelvis], gvs[pelvis_side][pelvis]])
    fifteen = fifteen[np.isfinite(fifteen)]
    overall = float(np.sqrt(np.mean(fifteen ** 2))) if fifteen.size else float("nan")
    missing = [t for t, p in zip(titles, present) if not p]
    return GaitScores(titles, gvs, per_cycle, gps, overall, missing)


def normal_scores(normative: Normative) -> tuple[np.ndarray, float]:
    """The scores a walker of the normative population gets, in the RMS sense.

    A normal cycle differs from the mean by about one SD at each sample, so the root of
    the expected squared GVS is the RMS over the cycle of the SD; the GPS the RMS of those.

    Returns
    -------
    ndarray, shape (9,), and float
        Degrees, :data:`GPS_VARIABLES` order (NaN where the set has no SD).

    Examples
    --------
    >>> sd = {"PelvisAngles": np.full((3, 3), 2.0), "HipAngles": np.full((3, 3), 2.0),
    ...       "KneeAngles": np.full((3, 3), 2.0), "AnkleAngles": np.full((3, 3), 2.0),
    ...       "FootProgressAngles": np.full((3, 3), 2.0)}
    >>> gvs, gps = normal_scores(Normative("flat", sd, sd, 3))
    >>> gvs.tolist(), gps
    ([2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0], 2.0)
    """
    gvs = np.array([np.sqrt(np.mean(normative.sd[name][:, k] ** 2))
                    if name in normative.sd else np.nan for name, k, _ in GPS_VARIABLES])
    known = gvs[np.isfinite(gvs)]
    return gvs, float(np.sqrt(np.mean(known ** 2))) if known.size else float("nan")


__all__ = ["GPS_VARIABLES", "GaitScores", "gait_scores", "normal_scores", "rms_difference"]
