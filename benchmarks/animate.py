"""``mocap animate``: how fast a preview is drawn, and how well it frames the figure.

Prints

- the wall and CPU time of :func:`dynamics.viz.animate.animate_motion` (Pillow frames) on a
  real bandai2 walk, beside a plain reference in the same run: the same frames drawn with
  matplotlib's 3-D axes and written by its Pillow writer (how previews were drawn before);
- the framing of every take listed: the figure's height as a percentage of the picture
  (median, smallest and largest over the frames drawn), and the points drawn outside the
  picture (clipped). The margins (:data:`dynamics.viz.preview.MARGIN`, ``TITLE_BAND``) were
  looked at on the design take only; the other takes report.

Never asserts; run ``python benchmarks/animate.py`` (``--quick`` skips the reference).
"""
from __future__ import annotations

import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from dynamics.viz.animate import animate_motion                          # noqa: E402
from dynamics.viz.preview import Framing, drawn_bones, figure_screens    # noqa: E402
from dynamics.viz.render import real_time_stride                        # noqa: E402
from mocap.io.motion import read_motion                                 # noqa: E402

BANDAI = ROOT.parent / "shared" / "realdata" / "bandai2"
DESIGN = "dataset-2_walk_active_001.bvh"
REPORT = ["dataset-2_run_active_001.bvh", "dataset-2_walk_elderly_002.bvh",
          "dataset-2_walk-turn-left_exhausted_003.bvh",
          "dataset-2_raise-up-both-hands_elderly_001.bvh",
          "dataset-2_wave-both-hands_active_002.bvh", "dataset-2_run_exhausted_003.bvh"]
SIZE_PX = (400, 400)          # animate's default: 5 × 5 inches at 80 dpi
MAX_FRAMES = 200


def _frames(motion):
    stride, _ = real_time_stride(motion.rate, motion.frames, MAX_FRAMES)
    return np.arange(0, motion.frames, stride)


def framing(motion) -> tuple[float, float, float, int]:
    """(median, smallest, largest figure height in % of the picture, points clipped)."""
    world = motion.forward_kinematics()
    end_index, ends = motion.end_site_positions(world)
    chosen = _frames(motion)
    points = np.concatenate([world[1], ends], axis=1)[chosen]
    bones, marked = drawn_bones(motion.skeleton)
    centres = points[:, marked[0]].copy()
    centres[:, 1] = 0.0
    screens = figure_screens(points, bones, centres)
    pixels = Framing(screens, SIZE_PX).pixels(screens[0])          # (frames, n, 2)
    heights = 100.0 * np.ptp(pixels[..., 1], axis=1) / SIZE_PX[1]
    outside = ((pixels < 0) | (pixels > np.array(SIZE_PX) - 1)).any(axis=-1).sum()
    return (float(np.median(heights)), float(heights.min()), float(heights.max()),
            int(outside))


def reference_matplotlib(motion, path: Path) -> None:
    """The same frames drawn with matplotlib's 3-D axes (bones only, a fixed box)."""
    from matplotlib import animation
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    world = motion.forward_kinematics()
    end_index, ends = motion.end_site_positions(world)
    points = np.concatenate([world[1], ends], axis=1)[..., [0, 2, 1]]
    bones, _ = drawn_bones(motion.skeleton)
    chosen = _frames(motion)
    figure = Figure(figsize=(5, 5), dpi=80)
    axes = figure.add_subplot(projection="3d")
    lines = Line3DCollection([], colors="tab:blue", linewidths=2.0)
    axes.add_collection3d(lines, autolim=False)
    axes.set_zlim(0, 2)

    def draw(frame):
        centre = points[frame, bones[0, 0]]
        axes.set_xlim(centre[0] - 1, centre[0] + 1)
        axes.set_ylim(centre[1] - 1, centre[1] + 1)
        lines.set_segments(points[frame][bones])
        return (lines,)

    movie = animation.FuncAnimation(figure, draw, frames=list(chosen), blit=False)
    movie.save(str(path), writer=animation.PillowWriter(fps=15), dpi=80)


def timed(function) -> tuple[float, float]:
    wall, cpu = time.perf_counter(), time.process_time()
    function()
    return time.perf_counter() - wall, time.process_time() - cpu


def main() -> None:
    if not BANDAI.is_dir():
        print(f"bandai2 not found at {BANDAI}")
        return
    warnings.simplefilter("ignore")
    walk = read_motion(BANDAI / DESIGN)
    with tempfile.TemporaryDirectory() as folder:
        ours = timed(lambda: animate_motion(walk, Path(folder) / "walk.gif", title="walk"))
        print(f"{DESIGN}: {len(_frames(walk))} frames, preview {ours[0]:.2f} s wall "
              f"({ours[1]:.2f} s CPU)")
        if "--quick" not in sys.argv:
            reference = timed(lambda: reference_matplotlib(walk, Path(folder) / "ref.gif"))
            print(f"  matplotlib 3-D reference, same frames: {reference[0]:.2f} s wall "
                  f"({reference[1]:.2f} s CPU); ratio {reference[0] / ours[0]:.1f}x wall, "
                  f"{reference[1] / ours[1]:.1f}x CPU")
    print("\nfigure height, % of the picture (median, min, max) and points clipped:")
    for role, names in (("design", [DESIGN]), ("report", REPORT)):
        medians = []
        for name in names:
            median, low, high, clipped = framing(read_motion(BANDAI / name))
            medians.append(median)
            print(f"  {role:<6} {name:<45} {median:5.1f} %  {low:5.1f}-{high:5.1f} %  "
                  f"clipped {clipped}")
        print(f"  {role} median of medians: {np.median(medians):.1f} %")


if __name__ == "__main__":
    main()
