"""Clinical gait angles of a walk with the Plug-in Gait model: the workflow.

:mod:`mocap.plugingait.model` holds the model (joint centres, frames, angle
conventions) and :mod:`mocap.plugingait.calibration` the static calibration; this module
puts them together for one walk: which subject values to use
(:func:`prepare_subject`), gap filling that stays inside each rigid segment
(:func:`fill_plugingait`), and the clinical angle table
(:func:`plugingait_angles`).
"""
from __future__ import annotations

import warnings
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from mocap.errors import MocapError, MocapWarning
from mocap.markersets.model import MissingMarkerWarning, _LabelIndex
from mocap.plugingait.estimates import EstimatedMeasurementWarning, estimate_missing
from mocap.plugingait.model import (CLINICAL_SEGMENTS, DEFAULT_MARKER_DIAMETER_M, JOINTS,
                                    MARKERS, PLANES, SIDES, AnatomicalOffsetWarning,
                                    Kinematics, Subject, clinical_angles,
                                    foot_progression_angles, kinematics, markers_from_trial,
                                    progression_frame, subject_from_trial)
from mocap.trial import Trial

if TYPE_CHECKING:
    from mocap.clean.gapfill import GapReport
    from mocap.plugingait.upper import UpperSubject


def _merge(primary: Subject, secondary: Subject) -> Subject:
    """``primary``'s values, ``secondary``'s where primary has none (None, or a rotation
    of 0: Vicon's "not measured"), with their ``sources``."""
    out = replace(primary, sources=dict(primary.sources))

    def take(key: str, side: str | None) -> None:
        if (key, side) in secondary.sources:
            out.sources[(key, side)] = secondary.sources[(key, side)]

    for key in ("leg_length", "asis_trochanter", "knee_width", "ankle_width",
                "tibial_torsion", "thigh_rotation", "shank_rotation"):
        mine, other = getattr(primary, key), getattr(secondary, key)
        merged = dict(mine)
        for side in SIDES:
            missing = not mine[side] if key in _ROTATIONS else mine[side] is None
            if missing and other[side] is not None:
                merged[side] = other[side]
                take(key, side)
        setattr(out, key, merged)
    for key in ("inter_asis", "marker_diameter"):
        if getattr(out, key) is None and getattr(secondary, key) is not None:
            setattr(out, key, getattr(secondary, key))
            take(key, None)
    return out


_ROTATIONS = ("tibial_torsion", "thigh_rotation", "shank_rotation")


def _given(subject: Subject) -> Subject:
    """A caller's subject with every value it holds labelled "given" (unless labelled)."""
    out = replace(subject, sources=dict(subject.sources))
    for key in ("inter_asis", "marker_diameter"):
        if getattr(subject, key) is not None:
            out.sources.setdefault((key, None), "given")
    for key in ("leg_length", "asis_trochanter", "knee_width", "ankle_width") + _ROTATIONS:
        for side in SIDES:
            if getattr(subject, key)[side]:
                out.sources.setdefault((key, side), "given")
    return out


def _marker_diameter(subject: Subject, path: str | None, warn: bool, why: str) -> Subject:
    """The subject with its marker diameter: :data:`DEFAULT_MARKER_DIAMETER_M` (with an
    :class:`EstimatedMeasurementWarning` ending with ``why``) when it has none."""
    if subject.marker_diameter is not None:
        return subject
    if warn:
        warnings.warn(f"{path or 'trial'}: marker diameter not measured: assumed "
                      f"{DEFAULT_MARKER_DIAMETER_M * 1000:.0f} mm ({why})", EstimatedMeasurementWarning,
                      stacklevel=4)
    out = replace(subject, marker_diameter=DEFAULT_MARKER_DIAMETER_M,
                  sources=dict(subject.sources))
    out.sources[("marker_diameter", None)] = "assumed (not recorded)"
    return out


def prepare_subject(trial: Trial, subject: Subject | None = None, *,
                    static: Trial | None = None, flat_foot: bool | str = "auto",
                    warn: bool = True) -> Subject:
    """The subject a walk is processed with: measurements, calibration, estimates.

    Measurements come from ``subject``, else the static's PROCESSING group, then the
    walk's (a given ``subject``'s missing values are taken from the static's
    PROCESSING only: without a static it is used as given, the rest estimated); a
    static's medial markers measure the knee and ankle widths still unknown; a
    ``static`` calibrates the offsets
    (:func:`mocap.plugingait.calibration.calibrate`); without one (and an uncalibrated
    ``subject``) an :class:`AnatomicalOffsetWarning` says the offsets are
    uncorrected.  What is still unknown is estimated from the walk's recorded
    (never gap-filled) frames (:func:`estimate_missing`), with one
    :class:`EstimatedMeasurementWarning` each, the marker diameter too (14 mm assumed).
    ``Subject.sources`` says where each value came from.  An empty SACR with
    both PSIS markers gives a :class:`MissingMarkerWarning` (the PSIS midpoint
    stands in).  ``warn=False`` says nothing (a caller that prepared the
    subject already did).
    """
    path = trial.path
    markers, empty = markers_from_trial(trial, MARKERS)
    if warn and "SACR" in empty and "LPSI" in markers and "RPSI" in markers:
        warnings.warn(f"{path or 'trial'}: SACR has no data; using the LPSI-RPSI "
                      f"midpoint as the sacrum", MissingMarkerWarning, stacklevel=3)
    from_static = None if static is None else \
        subject_from_trial(static, source="static PROCESSING")
    given = subject is not None
    if subject is None:
        subject = subject_from_trial(trial, source="walk PROCESSING")
        if from_static is not None:
            subject = _merge(from_static, subject)
    else:
        subject = _given(subject)
        if from_static is not None:
            subject = _merge(subject, from_static)
    why = {(False, False): "no PROCESSING:MarkerDiameter in the walk",
           (False, True): "no PROCESSING:MarkerDiameter in the static or the walk",
           (True, False): "none in the Subject given",
           (True, True): "none in the Subject given or the static's PROCESSING"}
    subject = _marker_diameter(subject, path, warn, why[(given, static is not None)])
    keep = None
    if trial.filled:
        from mocap.clean.gapfill import recorded_frames

        index = _LabelIndex(trial.labels)
        keep = {name: recorded_frames(trial, [trial.labels[index.find(name)]])
                for name in markers if index.find(name) is not None}
    if static is not None:
        from mocap.plugingait.calibration import calibrate, resolve_flat_foot

        _warn_if_moving(static)
        subject = _estimate_unmeasurable_widths(subject, static, markers, path, keep, warn)

        flat = resolve_flat_foot(static, subject, flat_foot, walk=trial)
        subject = calibrate(static, subject, flat_foot=flat)
    elif warn and not subject.calibrated:
        warnings.warn(f"{path or 'trial'}: no static trial: anatomical offsets are "
                      f"uncorrected (foot plantar-flexion and rotation offsets taken as 0; "
                      f"give --static for Plug-in Gait's calibration)",
                      AnatomicalOffsetWarning, stacklevel=3)
    return estimate_missing(subject, markers, path, keep, warn=warn)


def _estimate_unmeasurable_widths(subject: Subject, static: Trial, markers: dict,
                                  path: str | None, keep: dict | None, warn: bool) -> Subject:
    """The knee and ankle widths neither given nor measurable by the static's medial
    markers, estimated from the walk (:func:`estimate_missing`); the rest as given."""
    from mocap.plugingait.calibration import (MEDIAL_ANKLE, MEDIAL_KNEE, _first_present,
                                              static_markers)

    unknown = [(key, side) for key in ("knee_width", "ankle_width") for side in SIDES
               if getattr(subject, key)[side] is None]
    if not unknown:
        return subject
    standing = static_markers(static)
    medial = {"knee_width": MEDIAL_KNEE, "ankle_width": MEDIAL_ANKLE}
    blind = [(key, side) for key, side in unknown
             if _first_present(standing, medial[key], side) is None]
    if not blind:
        return subject
    return estimate_missing(subject, markers, path, keep, warn=warn, lengths=False,
                            widths=blind)


#: Horizontal travel of the ASIS midpoint beyond which a "static" trial is not one,
#: metres: standing sway is a few centimetres, one walking step is 0.5-0.8 m.
STATIC_TRAVEL_M = 0.25


def _warn_if_moving(static: Trial) -> None:
    """A MocapWarning when the static's pelvis travels like a walk's (its offsets would
    be averaged over a gait, not taken from a standing pose)."""
    markers, _ = markers_from_trial(static, ("LASI", "RASI"))
    if len(markers) < 2:
        return
    origin = (markers["LASI"] + markers["RASI"])[:, :2] / 2.0
    origin = origin[np.isfinite(origin).all(axis=1)]
    if len(origin) < 2:
        return
    travel = float(np.max(np.ptp(origin, axis=0)))
    if travel > STATIC_TRAVEL_M:
        warnings.warn(f"{static.path or 'static'}: the pelvis travels {travel:.2f} m during "
                      f"the static trial (standing sway is a few cm): is it a walk? Its "
                      f"calibration is averaged over the movement", MocapWarning, stacklevel=4)


def clinical_columns() -> list[str]:
    """Segment names of the clinical output: l_pelvis, l_hip, l_knee, l_ankle,
    l_foot_progress, r_pelvis … r_foot_progress (:data:`~mocap.plugingait.model.
    CLINICAL_SEGMENTS` per side)."""
    return [f"{side}_{segment}" for side in SIDES for segment in CLINICAL_SEGMENTS]


def vicon_label(segment: str) -> str:
    """Vicon's output label of a clinical angle segment (the upper body's too).

    Examples
    --------
    >>> vicon_label("l_hip"), vicon_label("r_foot_progress")
    ('LHipAngles', 'RFootProgressAngles')
    """
    from mocap.plugingait.upper import VICON_NAMES

    side, _, joint = segment.partition("_")
    if side not in SIDES or joint not in CLINICAL_SEGMENTS + tuple(VICON_NAMES):
        raise KeyError(segment)
    name = VICON_NAMES.get(joint) or "".join(w.capitalize() for w in joint.split("_")) + "Angles"
    return side.upper() + name


def plugingait_angles(trial: Trial, subject: Subject | None = None, *,
                      static: Trial | None = None, flat_foot: bool | str = "auto",
                      upper_body: bool = False, upper_subject: UpperSubject | None = None,
                      walk_kinematics: Kinematics | None = None):
    """Plug-in Gait joint angles (clinical convention) of a walk.

    Parameters
    ----------
    trial : Trial
        The walk; ``points`` (frames, markers, 3) in metres.  Subject
        measurements come from its C3D PROCESSING group (then the static's).
    subject : Subject, optional
        Measurements (and offsets, if ``calibrated``) to use instead, as
        :func:`prepare_subject` gives them; nothing is then warned about again.
    static : Trial, optional
        Standing trial of the same subject: calibrates the foot offsets
        (:func:`mocap.plugingait.calibration.calibrate`).  Without a static or a
        subject, an :class:`AnatomicalOffsetWarning` says the offsets are
        uncorrected.
    flat_foot : bool or "auto"
        Plug-in Gait's foot-flat static option; ``"auto"`` (the default, as on the
        command line) takes the option that reproduces the offsets a previous
        Plug-in Gait run stored in the walk or the static (PROCESSING
        StaticPlantFlex), else off.
    upper_body : bool
        Also the upper body (:mod:`mocap.plugingait.upper`): segments ``l_thorax,
        l_spine, l_neck, l_head, l_shoulder, l_elbow, l_wrist, r_…`` follow the
        lower body's, each Vicon's ``<Side><Joint>Angles``.  Parts whose markers
        or measurements are missing are NaN, with an
        :class:`~mocap.plugingait.upper.UpperBodyWarning`.
    upper_subject : UpperSubject, optional
        Upper-body measurements to use instead of the walk's (then the static's)
        PROCESSING group (:func:`mocap.plugingait.upper.upper_subject_from_trial`).
    walk_kinematics : Kinematics, optional
        The walk's :func:`~mocap.plugingait.model.kinematics` with ``subject``, when the
        caller has it already (``mocap plugingait`` computes it once for the angles, the
        kinetics and the joint centres); default computed here.

    Returns
    -------
    JointAngles
        Segments ``l_pelvis, l_hip, l_knee, l_ankle, l_foot_progress, r_…``
        (:func:`clinical_columns`; then the upper body's), axes ``flexion,
        adduction, rotation`` (degrees, Vicon's X, Y, Z of ``<Side><Joint>Angles``;
        ``<side>_foot_progress`` is ``<Side>FootProgressAngles``, the foot relative
        to the progression frame, :func:`~mocap.plugingait.model.
        foot_progression_angles`), sequence ``"YXZ"``; NaN where markers are
        missing; columns of joints whose markers are absent are all NaN (with a
        :class:`MissingMarkerWarning`).
    """
    from mocap.rotations.angles import JointAngles

    path = trial.path
    given = subject is not None and static is None
    subject = prepare_subject(trial, subject, static=static, flat_foot=flat_foot,
                              warn=not given)
    kin = walk_kinematics
    if kin is None:
        kin = kinematics(markers_from_trial(trial, MARKERS)[0], subject, path)
    for note in kin.notes:
        warnings.warn(f"{path or 'trial'}: {note}", MissingMarkerWarning, stacklevel=2)
    frames = trial.frames
    pelvis = kin.frames["pelvis"]
    progression = np.broadcast_to(progression_frame(kin.centres["pelvis"], pelvis),
                                  pelvis.shape)
    values = np.full((frames, len(SIDES) * len(CLINICAL_SEGMENTS), 3), np.nan)
    chain = {"pelvis": ("progression", "pelvis"), "hip": ("pelvis", "thigh"),
             "knee": ("thigh", "tibia"), "ankle": ("shank", "foot")}
    for i, side in enumerate(SIDES):
        column = i * len(CLINICAL_SEGMENTS)
        for j, joint in enumerate(JOINTS):
            proximal, distal = chain[joint]
            p = progression if proximal == "progression" else \
                kin.frames.get(proximal if proximal == "pelvis" else f"{side}_{proximal}")
            d = kin.frames.get(distal if distal == "pelvis" else f"{side}_{distal}")
            if p is None or d is None:
                continue
            values[:, column + j] = clinical_angles(p, d, joint, side)
        foot = kin.frames.get(f"{side}_foot")
        if foot is not None:
            values[:, column + CLINICAL_SEGMENTS.index("foot_progress")] = \
                foot_progression_angles(progression, foot, side)
    segments = clinical_columns()
    if upper_body:
        from mocap.plugingait.upper import (UPPER_MARKERS, UpperBodyWarning, upper_angles,
                                            upper_columns, upper_kinematics,
                                            upper_subject_from_trial)

        if upper_subject is None:
            upper_subject = upper_subject_from_trial(static, trial)
        upper_markers = markers_from_trial(trial, UPPER_MARKERS)[0]
        if not upper_markers:
            raise MocapError(f"no Plug-in Gait upper-body markers with data "
                             f"({', '.join(UPPER_MARKERS[:4])}, …) in the trial", path)
        upper = upper_kinematics(upper_markers, upper_subject)
        for note in upper.notes:
            warnings.warn(f"{path or 'trial'}: {note}", UpperBodyWarning, stacklevel=2)
        values = np.concatenate([values, upper_angles(kin, upper, progression)], axis=1)
        segments += upper_columns()
    return JointAngles(times=trial.times, values=values, segments=segments,
                       sequence="YXZ", parents=[-1] * values.shape[1], axes=list(PLANES))


#: Markers of each rigid segment of the model (a marker's donors for gap filling
#: are the others of its own segment only: the knee marker is on the thigh, the
#: ankle marker on the shank; nothing spans a joint).
RIGID_SEGMENTS = (("LASI", "RASI", "SACR", "LPSI", "RPSI"),
                  ("LTHI", "LKNE"), ("RTHI", "RKNE"),
                  ("LTIB", "LANK"), ("RTIB", "RANK"),
                  ("LHEE", "LTOE"), ("RHEE", "RTOE"))


#: Rigid marker groups of the upper body, filled from each other (the thorax's four and
#: the head's four); the arm markers have no rigid set of their own and keep their splines.
UPPER_RIGID_SEGMENTS = (("C7", "T10", "CLAV", "STRN"), ("LFHD", "RFHD", "LBHD", "RBHD"))


def plugingait_labels(trial: Trial, upper_body: bool = False) -> list[str]:
    """The trial's labels the model reads (subject prefixes allowed), in file order;
    with ``upper_body``, the upper body's markers too."""
    names = MARKERS
    if upper_body:
        from mocap.plugingait.upper import UPPER_MARKERS

        names = MARKERS + UPPER_MARKERS
    index = _LabelIndex(trial.labels)
    columns = sorted({c for c in (index.find(n) for n in names) if c is not None})
    if not columns:
        raise MocapError("no Plug-in Gait markers (LASI, RASI, …) in the trial", trial.path)
    return [trial.labels[c] for c in columns]


def plugingait_donors(labels: list[str]) -> dict[str, list[str]]:
    """Gap-filling donors: each label → the other labels of its rigid segment."""
    bare = {label.rpartition(":")[2]: label for label in labels}
    donors: dict[str, list[str]] = {}
    for segment in RIGID_SEGMENTS:
        present = [bare[n] for n in segment if n in bare]
        for label in present:
            donors[label] = [d for d in present if d != label]
    return donors


def fill_plugingait(trial: Trial, subject: Subject, max_gap_frames: int
                    ) -> tuple[Trial, GapReport]:
    """Fill gaps of the model's markers segment by segment, joint centres as donors.

    Each marker is filled only from its own rigid segment: the other markers of
    it (:data:`RIGID_SEGMENTS`) and the segment's proximal joint centre, which
    moves with it — the hip centre (from the pelvis markers) for the thigh, the
    knee centre for the shank, the ankle centre for the foot.  The segments are
    filled from the pelvis down, so each joint centre comes from an already
    filled segment; the joint centres are not kept in the result.  The upper
    body's thorax and head markers are filled from the others of their group
    (:data:`UPPER_RIGID_SEGMENTS`), like the pelvis's; any other marker by its
    spline.  See
    :func:`mocap.clean.gapfill.fill_gaps` for the methods and what stays unfilled.

    Parameters
    ----------
    trial : Trial
        Points in metres, with (at least) the model's markers.
    subject : Subject
        Measurements for the joint centres (prepare_subject).
    max_gap_frames : int

    Returns
    -------
    Trial, GapReport
        Frames outside the gaps are bit-identical to the input's.
    """
    from mocap.clean.gapfill import GapReport, fill_gaps, filled_masks

    labels = list(trial.labels)
    donors = plugingait_donors(labels)
    bare = {label.rpartition(":")[2]: label for label in labels}
    report = GapReport(max_gap_frames)
    current = trial
    stages = (("pelvis", None), ("thigh", "hip"), ("shank", "knee"), ("foot", "ankle"))
    groups = {"pelvis": RIGID_SEGMENTS[0]}
    for side, k in (("l", 1), ("r", 2)):
        groups[f"{side}_thigh"] = RIGID_SEGMENTS[k]
        groups[f"{side}_shank"] = RIGID_SEGMENTS[k + 2]
        groups[f"{side}_foot"] = RIGID_SEGMENTS[k + 4]
    for segment, centre in stages:
        is_pelvis = segment == "pelvis"
        names = [segment] if segment == "pelvis" else [f"{s}_{segment}" for s in SIDES]
        extra_labels, extra_points, stage_donors, references = [], [], {}, {}
        kin = None
        if centre is not None:
            markers, _ = markers_from_trial(current, MARKERS)
            try:
                kin = kinematics(markers, subject, trial.path, feet=False)
            except MocapError:
                kin = None
        for name in names:
            members = [bare[n] for n in groups[name] if n in bare]
            for label in members:
                stage_donors[label] = list(donors.get(label, []))
            key = f"{name.split('_')[0]}_{centre}" if centre is not None else None
            if kin is not None and centre is not None and key in kin.centres:
                joint = f"__{key}"
                extra_labels.append(joint)
                extra_points.append(kin.centres[key])
                # the proximal joint's medio-lateral axis turns with the segment
                # about its long axis (a hinge's axis; nearly so at the hip)
                side = name.split("_")[0]
                parent = {"thigh": "pelvis", "shank": f"{side}_thigh",
                          "foot": f"{side}_tibia"}[segment]
                axis = kin.frames.get(parent)
                for label in members:
                    stage_donors[label].append(joint)
                    if axis is not None:
                        references[label] = axis[..., 1]
        only = [label for label in stage_donors]
        work = current
        if extra_labels:
            work = current.with_markers(
                labels + extra_labels,
                np.concatenate([current.points, np.stack(extra_points, axis=1)], axis=1))
        filled, stage = fill_gaps(work, max_gap_frames=max_gap_frames, donors=stage_donors,
                                  only=only, references=references,
                                  correlate=not is_pelvis, rehearse=is_pelvis)
        report.filled += stage.filled
        report.unfilled += stage.unfilled
        current = current.with_points(filled.points[:, :len(labels)])
    # the upper body's rigid groups from each other, as the pelvis (a root segment)
    upper: dict[str, list[str]] = {}
    for group in UPPER_RIGID_SEGMENTS:
        present = [bare[n] for n in group if n in bare]
        upper.update({label: [d for d in present if d != label] for label in present})
    if upper:
        filled, stage = fill_gaps(current, max_gap_frames=max_gap_frames, donors=upper,
                                  only=list(upper), correlate=False, rehearse=True)
        report.filled += stage.filled
        report.unfilled += stage.unfilled
        current = filled
    # markers of no segment (if any were passed) are filled by their spline
    rest = [label for label in labels if label not in donors and label not in upper]
    if rest:
        filled, stage = fill_gaps(current, max_gap_frames=max_gap_frames, only=rest)
        report.filled += stage.filled
        report.unfilled += stage.unfilled
        current = filled
    current.filled = filled_masks(trial, report)
    return current, report
