"""The choices inside Plug-in Gait kinetics, compared on the design subjects only.

Each choice is one the agreement with Vicon's stored moments and powers settles, so it
is made on the design subjects (HC002D, HC031A, HC033A, HC038A of
``biomechzoo_sample_study``; their walks with force-plate outputs) and reported on the
held-out ones by ``benchmarks/plugingait.py``, never looked at here:

* radius of gyration: Dempster's about the centre of mass (0.323, 0.302, 0.475) or about
  the proximal end (0.540, 0.528, 0.690, applied about the centre of mass: the default);
* segment lengths the inertias scale with: each frame's joint-centre distances (the foot
  AJC–toe), or the static's (femur, tibia, heel–toe minus the marker radius: default);
* the knee's output frame: the untorsioned shank, or the torsioned tibia (default);
* the centre of pressure at marker frames: the centred mean of each frame's analog
  samples (``plate_forces(rate="marker")``, default) or the analog sample at the frame.

Printed: per choice, the mean over trials × sides of the sagittal moment RMS (N·mm/kg)
of hip, knee and ankle, and the median power RMS (W/kg). Never asserts.

Run: ``python benchmarks/plugingait_choices.py``
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from mocap.body.anthropometry import DempsterSegment, plugingait_segments
from mocap.io import read
from mocap.plugingait.clinical import prepare_subject
from mocap.plugingait import kinetics as K
from mocap.plugingait.model import MARKERS, kinematics, markers_from_trial

STUDY = Path(__file__).resolve().parents[2] / "shared" / "realdata" / "biomechzoo_sample_study"
DESIGN = ("HC002D", "HC031A", "HC033A", "HC038A")
COM_RADII = {"thigh": 0.323, "shank": 0.302, "foot": 0.475}


def _vicon(trial) -> dict:
    m = trial.modelled
    return {label.rpartition(":")[2]: m["values"][:, k] for k, label in enumerate(m["labels"])}


def load():
    out = []
    for subject in DESIGN:
        static = read(next((STUDY / subject / "Static").glob("*.c3d")))
        for walk in sorted((STUDY / subject).glob("*/*.c3d")):
            if walk.parent.name == "Static":
                continue
            trial = read(walk)
            vicon = _vicon(trial)
            if "LHipMoment" not in vicon:
                continue
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sub = prepare_subject(trial, static=static)
                kin = kinematics(markers_from_trial(trial, MARKERS)[0], sub)
                sm = markers_from_trial(static, MARKERS)[0]
                skin = kinematics(sm, sub)
                ground, _ = K.ground_reactions(trial, kin)
            out.append(dict(trial=trial, vicon=vicon, kin=kin, ground=ground,
                            mass=K.body_mass_of(trial, static),
                            lengths=K.segment_lengths(kin, static, skin, sm, sub.radius)))
    return out


def _at_frames(trial, ground):
    """The same stances with the analog sample at each frame instead of the frame mean."""
    from mocap.io.c3d.forceplates import plate_forces

    plates = plate_forces(trial, rate="analog")
    per = int(round((trial.analog_rate or trial.rate) / trial.rate))
    out = {}
    for side, g in ground.items():
        force, cop, free = (a.copy() for a in (g.force, g.cop, g.free_moment))
        loaded = np.isfinite(force).all(axis=1)
        for p in plates:
            f, c, t = p.force[::per][:trial.frames], p.cop[::per][:trial.frames], \
                p.free_moment[::per][:trial.frames]
            # the plate that stance used: the one whose frame means match
            here = loaded & np.isfinite(c).all(axis=1)
            if here.any() and np.nanmax(np.abs(f[here, 2] - force[here, 2])) < 100.0:
                force[here], cop[here], free[here] = f[here], c[here], t[here]
        out[side] = K.GroundReaction(force, cop, free, g.unknown)
    return out


def score(data, table=None, static_lengths=True, knee="tibia", sample=False):
    moment_rms, power_rms = [], []
    frames = dict(K.DISTAL_FRAME, knee=knee)
    for d in data:
        trial, kin, mass = d["trial"], d["kin"], d["mass"]
        ground = _at_frames(trial, d["ground"]) if sample else d["ground"]
        loads = K.lab_kinetics(kin, ground, mass, trial.rate,
                               d["lengths"] if static_lengths else None, table)
        row = []
        for side in ("l", "r"):
            for joint in K.KINETIC_JOINTS:
                f, m, p = loads[f"{side}_{joint}"]
                ours = K._components(kin.frames[f"{side}_{frames[joint]}"], m,
                                     K.MOMENT_AXES[(joint, side)]) * 1000 / mass
                label = f"{side.upper()}{joint.capitalize()}"
                theirs = d["vicon"][label + "Moment"]
                ok = np.isfinite(theirs[:, 0]) & np.isfinite(ours[:, 0])
                row.append(np.sqrt(np.mean((ours[ok, 0] - theirs[ok, 0]) ** 2))
                           if ok.sum() > 10 else np.nan)
                pv = d["vicon"][label + "Power"][:, 2]
                ok = np.isfinite(pv) & np.isfinite(p)
                if ok.sum() > 10:
                    power_rms.append(np.sqrt(np.mean((p[ok] / mass - pv[ok]) ** 2)))
        moment_rms.append(row)
    m = np.nanmean(np.array(moment_rms).reshape(len(data), 2, 3), axis=(0, 1))
    return f"hip {m[0]:5.1f}  knee {m[1]:5.1f}  ankle {m[2]:5.1f} N·mm/kg;  " \
           f"power median RMS {np.median(power_rms):.3f} W/kg"


if __name__ == "__main__":
    data = load()
    print(f"design subjects {', '.join(DESIGN)}: {len(data)} walks with Vicon's kinetics")
    default = plugingait_segments()
    com = {k: DempsterSegment(v.mass_fraction, v.com_fraction, COM_RADII[k])
           for k, v in default.items()}
    print("default (proximal-end radii, static lengths, tibia, frame means):")
    print("   ", score(data))
    print("radii about the centre of mass:      ", score(data, table=com))
    print("per-frame segment lengths:           ", score(data, static_lengths=False))
    print("knee in the untorsioned shank:       ", score(data, knee="shank"))
    print("analog sample at each frame:         ", score(data, sample=True))
