"""Plug-in Gait (the Conventional Gait Model as Vicon's Plug-in Gait computes it).

Modules
-------
model
    The model: subject measurements, joint centres, anatomical frames and the clinical
    angle conventions (the foot progression's too), vectorised over frames.
calibration
    Static calibration: subject measurements, tibial torsion, foot offsets, KAD.
clinical
    The clinical recipe for one walk: subject values, gap filling inside each rigid
    segment, the clinical angle table (:func:`~mocap.plugingait.clinical.plugingait_angles`).
upper
    The upper body (thorax, head, arms), as Vicon's ``<Side><Joint>Angles``
    (``plugingait_angles(..., upper_body=True)``).
events
    Gait events (from the file or detected) and gait cycles at 0–100 %.
curves, normative, scores
    Outputs per gait cycle under Vicon's names; normative mean ± SD curves (built in, or
    a lab's own); the Gait Profile Score and Gait Variable Scores (Baker et al. 2009).
walks, report
    One walk analysed for a report (curves, parameters, subject, notes); the HTML report.

The recipe from a walk (and its static) to clinical angles, with the command line's
defaults, is :func:`mocap.pipeline.clinical_angles`.

Why a model of its own and not a marker set plus a clinical step: a marker set
(``docs/formats/markerset-toml.md``) maps three markers to a segment frame and takes
relative Euler angles. Plug-in Gait needs what such a table cannot say: subject
measurements and a static calibration (foot offsets, tibial torsion, a knee alignment
device), frames built from joint centres and wands with per-side conventions, and per-joint
clinical signs and axis orders. The geometry it shares with marker sets has one home
there: the pelvis frame and the Davis hip joint centre
(:mod:`mocap.markersets.virtual`), the knee and ankle chord (:mod:`mocap.markersets.chord`);
its Cardan angles are :func:`mocap.rotations.euler.euler_from_components` (intrinsic YXZ).
The ``plugingait-lower`` preset is the same geometry as a marker set, for segment angles.

Units: metres throughout, like ``Trial.points`` (markers, joint centres, the
:class:`~mocap.plugingait.model.Subject`'s lengths, every threshold); angles in radians
inside, degrees in the angle tables.  The one conversion is where Vicon's PROCESSING
group (millimetres) is read, :func:`~mocap.plugingait.model.subject_from_trial`.

Importing the package loads none of them; import the module you need.
"""
