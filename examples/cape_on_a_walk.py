"""Secondary motion: a cloth cape and a rope on a walking body, as a GIF and an npz.

    python examples/cape_on_a_walk.py [MOTION.bvh] [-o OUT_DIR]

Without a motion, a synthetic walk (two gait cycles of markers) is turned into a skeleton
motion. The cape is a mass-spring cloth pinned to the shoulders, the rope hangs from the
back of the head; both are simulated by the particle simulator (implicit Euler at the
motion's frame rate) while colliding with the moving body, then drawn with the figure.
"""
import argparse
from pathlib import Path

import numpy as np

from dynamics.secondary import simulate_secondary
from dynamics.viz.animate import animate_motion
from mocap.body.retarget import motion_from_trial
from mocap.io.motion import read_motion
from mocap.synthetic import synthesize_trial

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("motion", nargs="?", type=Path, help="a BVH (or ASF/AMC) motion")
parser.add_argument("-o", "--out", type=Path, default=Path("cape_out"))
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

if args.motion is not None:
    motion = read_motion(args.motion)            # units detected from the figure's height
else:
    trial, _truth = synthesize_trial(person=1, action="walk", seed=0, cycles=2)
    motion = motion_from_trial(trial, "synthetic15")   # metres, Y up, feet on y = 0
print(f"{motion.frames} frames at {motion.rate:g} Hz, {len(motion.names)} joints")

# 9 x 14 particles across the shoulders and down the back, 0.8 m long, 0.6 kg;
# a 10-particle rope. The cloth settles for half a second on the first pose.
secondary = simulate_secondary(motion, cape=True, rope=True, cape_resolution=(9, 14),
                               cape_length=0.8, cape_mass=0.6, settle=0.5)
cape, rope = secondary.cape, secondary.rope      # (frames, particles, 3), metres
travel = np.linalg.norm(cape[-1].mean(axis=0) - cape[0].mean(axis=0))
print(f"simulated {secondary.steps} steps: cape {cape.shape[1]} particles, "
      f"{len(secondary.cape_springs)} springs; its centre travelled {travel:.2f} m; "
      f"lowest point {cape[..., 1].min():.2f} m above the floor")

np.savez(args.out / "cape.npz", times=secondary.times, cape=cape, rope=rope,
         cape_springs=secondary.cape_springs, rope_springs=secondary.rope_springs)
frames = animate_motion(motion, args.out / "cape.gif", secondary=secondary, max_frames=40, dpi=60,
                        title="walk with a cape and a rope")
print(f"wrote {args.out / 'cape.npz'} and {args.out / 'cape.gif'} ({frames} frames)")
