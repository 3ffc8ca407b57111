"""Plug-in Gait (the Conventional Gait Model as Vicon's Plug-in Gait computes it).

Modules
-------
model
    The model: subject measurements, joint centres, anatomical frames and the clinical
    angle conventions, vectorised over frames.
calibration
    Static calibration: subject measurements, tibial torsion, foot offsets, KAD.
clinical
    The clinical recipe for one walk: subject values, gap filling inside each rigid
    segment, the clinical angle table (:func:`~mocap.plugingait.clinical.plugingait_angles`).
events
    Gait events (from the file or detected) and gait cycles at 0–100 %.

Importing the package loads none of them; import the module you need.
"""
