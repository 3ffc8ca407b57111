"""A :class:`~synthesis.model.MotionModel`'s files: the model as ``.npz`` (:func:`save_model`,
:func:`load_model`) and a trial file read the way the model's corpus was
(:func:`read_trial_curve`). The model itself holds arrays and never reads a file.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from mocap.atomic import atomic_path
from mocap.budget import read_npz
from mocap.errors import MocapError
from mocap.io.motion import read_motion
from synthesis.corpus import read_trial_angles
from synthesis.model import FORMAT_VERSION, MotionModel
from synthesis.regression import SignatureModel
from synthesis.skeletons import trial_cycle


def save_model(model: MotionModel, path: str | os.PathLike) -> None:
    """Write a fitted ``model`` to ``path`` (.npz), atomically."""
    model._check_fitted()
    angle_arrays, angle_meta = model.angle_model_.to_arrays("angles")
    timing_arrays, timing_meta = model.timing_model_.to_arrays("timing")
    meta = {
        "format": "mocap-motion-model", "version": FORMAT_VERSION,
        "people": model.people, "actions": model.actions, "segments": model.segments,
        "parents": model.parents, "columns": model.columns, "sequence": model.sequence,
        "samples": model.samples, "markerset": model.markerset, "cycles": model.cycles,
        "cycle_column": model.cycle_column, "sources": model.sources,
        "cleaning": model.cleaning, "people_rank": model.people_rank,
        "action_rank": model.action_rank,
        "feature_rank": model.feature_rank, "ridge": model.ridge,
        "spread_rms": model.spread_rms_, "angles": angle_meta, "timing": timing_meta,
        "method": model.method, "method_": model.method_,
        "representation": model.representation, "rig": model.rig,
        "heading_removed": model.heading_removed,
    }
    # The methods' state is their data: stored once, refitted on loading.
    extra = {"transfer_angles": model.cells_.data_,
             "transfer_timing": model.timing_cells_.data_}
    if model.root_transfer_ is not None:
        extra["transfer_root"] = model.root_transfer_.data_
    if model.rotation_means is not None:
        extra["rotation_means"] = model.rotation_means
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            np.savez_compressed(handle, meta=np.array(json.dumps(meta)), **angle_arrays,
                                **timing_arrays, **extra)


def load_model(path: str | os.PathLike) -> MotionModel:
    """Read a model written by :func:`save_model`; a missing, foreign or damaged file is a
    MocapError naming it."""
    path = Path(path)
    if not path.exists():
        raise MocapError("model file not found", path)
    arrays = read_npz(path, "not a motion model file (.npz from 'mocap decompose'), or "
                            "a damaged one")
    try:
        meta = json.loads(str(arrays.pop("meta")))
    except (ValueError, KeyError):
        raise MocapError("not a motion model file (.npz from 'mocap decompose')",
                         path) from None
    if not isinstance(meta, dict) or meta.get("format") != "mocap-motion-model":
        raise MocapError("not a motion model file (.npz from 'mocap decompose')", path)
    if int(meta.get("version", 0)) > FORMAT_VERSION:
        raise MocapError(f"model format version {meta['version']} is newer than this "
                         f"toolkit reads ({FORMAT_VERSION})", path)
    try:
        model = MotionModel(people_rank=meta["people_rank"], action_rank=meta["action_rank"],
                    feature_rank=meta["feature_rank"], ridge=meta["ridge"])
        for name in ("people", "actions", "segments", "parents", "columns", "sequence",
                     "samples", "markerset", "cycles", "cycle_column", "sources"):
            setattr(model, name, meta[name])
        model.cleaning = dict(meta.get("cleaning") or {})
        model.spread_rms_ = float(meta["spread_rms"])
        model.angle_model_ = SignatureModel.from_arrays("angles", arrays, meta["angles"])
        model.timing_model_ = SignatureModel.from_arrays("timing", arrays, meta["timing"])
        model.method = meta.get("method", "signature")
        model.method_ = meta.get("method_", "signature")
        model.representation = meta.get("representation", "euler")
        model.rig = meta.get("rig")
        model.heading_removed = bool(meta.get("heading_removed", False))
        model.rotation_means = arrays.get("rotation_means")
        if "transfer_angles" not in arrays:
            # Format 1 models held signatures only: they predict missing cells by them.
            raise MocapError("motion model of format 1 (signatures only): decompose the "
                             "corpus again", path)
        model.fit_methods(arrays["transfer_angles"], arrays["transfer_timing"],
                          arrays.get("transfer_root"))
    except (KeyError, TypeError, ValueError) as error:
        raise MocapError(f"damaged motion model file (missing {error})", path) from None
    return model


def read_trial_curve(model: MotionModel, path: str | os.PathLike) -> tuple[np.ndarray, float]:
    """A trial file (marker trial with the model's marker set, angle CSV or BVH) →
    normalised ``(curve (samples, columns) degrees, duration s)``.

    Models of skeleton corpora read a BVH / ASF-AMC trial of the same rig (or any rig when
    the model is on the body model) and featurise it about the corpus' mean rotations."""
    curve, duration, _ = read_trial_cycle(model, path)
    return curve, duration


def read_trial_cycle(model: MotionModel, path: str | os.PathLike
                     ) -> tuple[np.ndarray, float, bool]:
    """:func:`read_trial_curve` and whether the trial was cut into cycles (False: used
    whole, by a model of whole trials or for want of a complete cycle)."""
    model._check_fitted()
    if model.representation == "rotvec":
        curve, _, duration, _, count = trial_cycle(read_motion(path), model.rig,
                                                   model.rotation_means, model.samples,
                                                   model.cycles, path)
        return curve, duration, count > 0
    angles = read_trial_angles(path, model.markerset, model.sequence,
                               model.cleaning.get("lowpass_hz"),
                               model.cleaning.get("max_gap_seconds"))
    try:
        curve, duration = model.normalise(angles)
    except MocapError as error:
        raise MocapError(error.problem, error.path or path) from None
    return curve, duration, bool(model.cycles)
