"""A BVH corpus -> a motion model -> a synthesised walk as BVH.

    python examples/bvh_corpus_to_walk.py [CORPUS] [-o OUT_DIR]

CORPUS is a folder of ``<person>_<action>.bvh`` files or one with a ``manifest.csv``
(columns path,person,action), such as ../shared/realdata/bandai2. Without it, a small
corpus is generated: four synthetic people walking and going up and down stairs, their
markers turned into BVH skeleton motions. The walk of the first person is held out, the
model is fitted on every other cell and synthesises that walk from the person's other
actions; the script prints how close it is to the captured walk, beside the baseline
(the mean walk of the other people), and writes the synthesised walk as BVH.
"""
import argparse
import json
from pathlib import Path

import numpy as np

from mocap.body.retarget import motion_from_trial
from mocap.io.bvh import write_bvh
from mocap.synthetic import synthesize_trial
from mocap.synthetic.people import make_people
from synthesis.corpus import load_corpus
from synthesis.model import MotionModel

ACTION = "walk"


def generate_bvh_corpus(folder: Path, people: int = 4, actions=("walk", "ascend", "descend")):
    """Synthetic marker trials -> one BVH per (person, action), named <person>_<action>.bvh."""
    folder.mkdir(parents=True, exist_ok=True)
    for index, person in enumerate(make_people(people, seed=0)):
        for action in actions:
            trial, _truth = synthesize_trial(index, action, seed=0, people=people)
            motion = motion_from_trial(trial, "synthetic15")    # segment frames -> skeleton
            write_bvh(motion, folder / f"{person.name}_{action}.bvh")
    return folder


parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("corpus", nargs="?", type=Path, help="folder of BVH files (default: generated)")
parser.add_argument("-o", "--out", type=Path, default=Path("bvh_corpus_out"))
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

folder = args.corpus or generate_bvh_corpus(args.out / "corpus")
manifest = folder / "manifest.csv"
# Skeleton corpora become rotation vectors per joint. A generated trial is one gait cycle;
# the trials of a real corpus are cut into cycles, registered and averaged (cycles=True).
if manifest.is_file():
    corpus = load_corpus(manifest=manifest, cycles=True)
else:
    corpus = load_corpus(folder, cycles=args.corpus is not None)
person = corpus.people[0]
print(f"{len(corpus.people)} people x {len(corpus.actions)} actions, "
      f"{len(corpus.segments)} joints ({corpus.representation}); holding out {person}'s {ACTION}")

# Fit without the held-out cell, then synthesise it from the person's other actions.
model = MotionModel().fit(corpus.without_cell(person, ACTION))
curve, duration = model.synthesize(person, ACTION)

p, a = corpus.people.index(person), corpus.actions.index(ACTION)
captured = corpus.angles[p, a]                                  # (samples, features), degrees
others = [i for i in range(len(corpus.people)) if i != p]
baseline = np.nanmean(corpus.angles[others, a], axis=0)         # knowing nothing of the person
rms = lambda x: float(np.sqrt(np.nanmean((x - captured) ** 2)))
result = {"person": person, "action": ACTION, "synthesis_rms_deg": rms(curve),
          "baseline_rms_deg": rms(baseline), "predicted_duration_s": duration,
          "captured_duration_s": float(corpus.durations[p, a])}
print(f"synthesised {person}'s {ACTION}: {result['synthesis_rms_deg']:.2f} deg RMS from the "
      f"capture, baseline {result['baseline_rms_deg']:.2f} deg; cycle {duration:.3f} s "
      f"(captured {result['captured_duration_s']:.3f} s)")

# Back on the corpus' rig: rotations from the features, root path from the root motion.
motion = model.synthesize_motion(person, ACTION, cycles=3)
bvh = args.out / f"{person}_{ACTION}_synthesised.bvh"
write_bvh(motion, bvh)
(args.out / "summary.json").write_text(json.dumps(result, indent=1) + "\n")
print(f"wrote {bvh} ({motion.frames} frames) and {args.out / 'summary.json'}")
