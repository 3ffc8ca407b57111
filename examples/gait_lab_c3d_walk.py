"""A Plug-in Gait C3D walk -> clinical joint angles, gait cycles and their plot.

    python examples/gait_lab_c3d_walk.py [WALK.c3d --static STATIC.c3d] [-o OUT_DIR]

With a walk (and its standing static) from a Vicon Plug-in Gait session, the subject's
measurements come from the files' PROCESSING group and the static calibrates the foot
offsets. Without one, a walk is generated: a synthetic walker's segment frames carry the
lower-body Plug-in Gait markers (ASIS, sacrum, thigh and shank wands, knee, ankle, heel,
toe), written to a C3D file as a capture system would; its subject is known exactly.
"""
import argparse
from pathlib import Path

import numpy as np

from mocap import io
from mocap.io.angles_csv import write_angles_csv
from mocap.plugingait.clinical import plugingait_angles, prepare_subject
from mocap.plugingait.events import cycles_figure, gait_events, normalise_cycles, write_cycles_csv
from mocap.plugingait.model import Subject
from mocap.rotations.frames import segment_frames
from mocap.markersets import load_markerset
from mocap.synthetic import synthesize_trial
from mocap.trial import Trial

# Plug-in Gait markers in the frames of the synthetic segments (x forward, y left, z up
# when standing; metres, left side: the right side mirrors y). Origins: joint centres.
PLACES = {"ASI": ("pelvis", "hips", [0.05, 0.12, 0.08]), "THI": ("thigh", None, [0, 0.08, -0.2]),
          "KNE": ("thigh", "shank", [0, 0.055, 0]), "TIB": ("shank", None, [0, 0.06, -0.2]),
          "ANK": ("shank", "foot", [0, 0.045, 0]), "HEE": ("foot", None, [-0.06, 0, -0.05]),
          "TOE": ("foot", None, [0.13, 0, -0.06])}


def generated_walk(path: Path) -> tuple[Path, Subject]:
    """Three gait cycles of a synthetic walker, as a Plug-in Gait C3D file."""
    trial, _truth = synthesize_trial(person=0, action="walk", seed=0, cycles=3)
    markerset = load_markerset("synthetic15")
    R, O = segment_frames(trial, markerset)             # (frames, segments, 3, 3), (…, 3)
    at = {name: i for i, name in enumerate(markerset.segment_names)}
    hips = (O[:, at["l_thigh"]] + O[:, at["r_thigh"]]) / 2
    labels, points = ["SACR"], [hips + R[:, at["pelvis"]] @ [-0.15, 0, 0.08]]
    for (side, s), sign in ((("L", "l"), 1), (("R", "r"), -1)):
        for marker, (frame, origin, offset) in PLACES.items():
            centre = hips if origin == "hips" else O[:, at[f"{s}_{origin or frame}"]]
            rotation = R[:, at["pelvis" if frame == "pelvis" else f"{s}_{frame}"]]
            labels.append(side + marker)
            points.append(centre + rotation @ (np.array(offset) * [1, sign, 1]))
    walk = Trial(labels, np.stack(points, axis=1), trial.rate, units="mm")
    io.write(walk, path)                                  # C3D in millimetres
    # What the lab measures (widths = 2 x (marker offset - marker radius), metres) and what
    # a static trial would calibrate: the toe marker 6 cm below and 13 cm ahead of the ankle.
    flexion = np.arctan2(0.06, 0.13)                       # plantar-flexion offset, rad
    return path, Subject(marker_diameter=0.014, knee_width={"l": 0.096, "r": 0.096},
                         ankle_width={"l": 0.076, "r": 0.076}, calibrated=True,
                         static_plantar_flexion={"l": flexion, "r": flexion},
                         static_rotation_offset={"l": 0.0, "r": 0.0})


parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("walk", nargs="?", type=Path, help="a Plug-in Gait walk (C3D)")
parser.add_argument("--static", type=Path, help="the subject's static trial (C3D)")
parser.add_argument("-o", "--out", type=Path, default=Path("gait_lab_out"))
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

walk_path, subject = args.walk, None                       # subject: the C3D's PROCESSING
if walk_path is None:
    walk_path, subject = generated_walk(args.out / "generated_walk.c3d")
trial = io.read(walk_path)                                 # points in metres, NaN = missing
static = io.read(args.static) if args.static else None
print(f"{walk_path}: {trial.frames} frames at {trial.rate:g} Hz, {len(trial.labels)} markers")

# Subject measurements, static calibration, then Plug-in Gait's angles (Vicon's axes/signs).
subject = prepare_subject(trial, subject, static=static, flat_foot="auto")
angles = plugingait_angles(trial, subject=subject)    # l_pelvis ... l_foot_progress, r_...
write_angles_csv(angles, args.out / "angles.csv")

# Foot strikes and offs (the file's events, else detected from heel and toe markers),
# every cycle resampled to 0-100 %, written tidy and plotted as mean +- SD.
cycles = normalise_cycles(angles, gait_events(trial))
write_cycles_csv(cycles, args.out / "cycles.csv")
cycles_figure(cycles, title=f"{walk_path.name}: clinical angles").savefig(args.out / "cycles.png")
knee = cycles.values[:, :, cycles.joints.index("knee"), 0].mean(axis=0)  # mean flexion, deg
print(f"{len(cycles.side)} cycles ({cycles.side.count('l')} left); knee flexion {knee.min():.0f}"
      f" to {knee.max():.0f} deg, peak at {knee.argmax():.0f} % of the cycle")
print(f"wrote {args.out / 'angles.csv'}, {args.out / 'cycles.csv'}, {args.out / 'cycles.png'}")
