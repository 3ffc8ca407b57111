"""Animations of simulation runs (matplotlib): GIF through Pillow, MP4 through ffmpeg.

The scene convention is Y up; the plot puts the scene's Y on matplotlib's vertical axis.
Particles are drawn as points (coloured by temperature when the run has heat), springs
as lines (bend springs and melted springs are left out), rigid boxes as wireframes.
"""
from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np

from mocap.atomic import atomic_path
from mocap.progress import progress_bar
from mocap.errors import MocapError

from dynamics.sim.springs import BEND

#: The 12 edges of a box whose 8 corners are ordered as in dynamics.sim.rigid.box_mesh.
BOX_EDGES = np.array([[0, 1], [0, 2], [0, 4], [1, 3], [1, 5], [2, 3], [2, 6], [3, 7],
                      [4, 5], [4, 6], [5, 7], [6, 7]])
#: Most springs drawn per frame (more makes the GIF slow to render and to view).
MAX_DRAWN_SPRINGS = 4000


def _to_plot(points: np.ndarray) -> np.ndarray:
    """Scene (x, y up, z) -> plot (x, z, y up)."""
    return points[..., [0, 2, 1]]


def _draw_colliders(axes, result: dict) -> None:
    """Static wireframes of sphere and box colliders (planes are left to the axes)."""
    for sphere in np.asarray(result.get("spheres", np.zeros((0, 4)))).reshape(-1, 4):
        u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 16), np.linspace(0, np.pi, 9))
        points = sphere[:3] + sphere[3] * np.stack(
            [np.cos(u) * np.sin(v), np.cos(v), np.sin(u) * np.sin(v)], axis=-1)
        p = _to_plot(points)
        axes.plot_wireframe(p[..., 0], p[..., 1], p[..., 2], color="tab:green", linewidth=0.4)
    for box in np.asarray(result.get("boxes", np.zeros((0, 6)))).reshape(-1, 6):
        corners = np.array([[x, y, z] for x in (box[0], box[3]) for y in (box[1], box[4])
                            for z in (box[2], box[5])])
        for a, b in BOX_EDGES:
            p = _to_plot(corners[[a, b]])
            axes.plot(p[:, 0], p[:, 1], p[:, 2], color="tab:green", linewidth=0.6)


def render_animation(result: dict, path: str | os.PathLike, fps: float | None = None,
                     max_frames: int = 300, dpi: int = 80, title: str = "") -> int:
    """Write an animation of a saved run to ``path`` (.gif or .mp4); returns frames drawn.

    Parameters
    ----------
    result : dict of arrays, as saved (``SimulationResult.arrays()`` or ``load_result``)
    path : output file; ``.gif`` uses Pillow, ``.mp4`` needs ffmpeg on the PATH
    fps : frames per second of the animation, or None (default) for real time: the saved
        frames' own rate, every stride-th frame with a whole-centisecond delay
        (:func:`real_time_stride`), as ``mocap animate`` plays motions
    max_frames : at most this many frames are drawn (evenly spaced with ``fps``)
    dpi : resolution (the figure is 6.4 × 4.8 inches)
    """
    # deferred: matplotlib is slow to import and only drawing needs it
    import matplotlib
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    path = check_animation_path(path)

    times = np.asarray(result["times"])
    positions = np.asarray(result["positions"])
    rigid_vertices = np.asarray(result.get("rigid_vertices", np.zeros((len(times), 0, 0, 3))))
    step = np.diff(times)
    rate = 1.0 / float(np.median(step)) if len(step) and np.median(step) > 0 else 0.0
    if fps is None and np.isfinite(rate) and rate > 0:   # real time, like mocap animate
        stride, delay = real_time_stride(rate, len(times), max_frames)
        frames = np.arange(0, len(times), stride)
        fps = 100.0 / delay
    else:
        frames = np.unique(np.linspace(0, len(times) - 1,
                                       min(max_frames, len(times))).astype(int))
        fps = 30.0 if fps is None else float(fps)
    springs = np.asarray(result.get("springs", np.zeros((0, 2), int)))
    kind = np.asarray(result.get("spring_kind", np.zeros(len(springs), np.int8)))
    broken_at = np.asarray(result.get("spring_broken_at", np.full(len(springs), np.inf)))
    drawn = np.flatnonzero(kind != BEND)
    if len(drawn) > MAX_DRAWN_SPRINGS:
        drawn = drawn[np.linspace(0, len(drawn) - 1, MAX_DRAWN_SPRINGS).astype(int)]
    temperature = result.get("temperature")
    colour = np.asarray(result.get("colour", np.tile([0.2, 0.4, 0.8], (positions.shape[1], 1))))

    everything = [positions.reshape(-1, 3)]
    if rigid_vertices.size:
        everything.append(rigid_vertices.reshape(-1, 3))
    cloud = np.concatenate(everything)
    cloud = cloud[np.all(np.isfinite(cloud), axis=1)]
    lo, hi = (cloud.min(axis=0), cloud.max(axis=0)) if len(cloud) else (-np.ones(3), np.ones(3))
    centre, half = 0.5 * (lo + hi), 0.5 * max(float((hi - lo).max()), 1e-3) * 1.05

    figure = Figure(figsize=(6.4, 4.8), dpi=dpi)       # no pyplot: no global state
    axes = figure.add_subplot(projection="3d")
    c = _to_plot(centre)
    axes.set_xlim(c[0] - half, c[0] + half)
    axes.set_ylim(c[1] - half, c[1] + half)
    axes.set_zlim(c[2] - half, c[2] + half)
    axes.set_xlabel("x (m)")
    axes.set_ylabel("z (m)")
    axes.set_zlabel("y (m)")
    n = positions.shape[1]
    size = float(np.clip(2000.0 / max(n, 1), 1.0, 30.0))
    start = _to_plot(positions[0]) if n else np.zeros((0, 3))
    scatter = axes.scatter(start[:, 0], start[:, 1], start[:, 2], s=size, depthshade=False)
    lines = Line3DCollection([], colors="0.35", linewidths=0.5)
    axes.add_collection3d(lines, autolim=False)
    boxes = Line3DCollection([], colors="tab:red", linewidths=1.2)
    axes.add_collection3d(boxes, autolim=False)
    _draw_colliders(axes, result)
    label = axes.set_title(title)
    if temperature is not None:
        temperature = np.asarray(temperature)
        t_lo, t_hi = float(np.min(temperature)), float(np.max(temperature))
        cmap = matplotlib.colormaps["inferno"]
        mappable = matplotlib.cm.ScalarMappable(cmap=cmap,
                                                norm=Normalize(t_lo, max(t_hi, t_lo + 1e-9)))
        figure.colorbar(mappable, ax=axes, shrink=0.6, label="temperature (K)")

    def draw(frame: int):
        x = _to_plot(positions[frame])
        scatter._offsets3d = (x[:, 0], x[:, 1], x[:, 2])
        if temperature is not None:
            scatter.set_color(mappable.to_rgba(temperature[frame]))
        else:
            scatter.set_color(colour)
        if len(drawn):
            keep = drawn[broken_at[drawn] > times[frame]]
            lines.set_segments(x[springs[keep]])
        if rigid_vertices.size:
            corners = _to_plot(rigid_vertices[frame])
            segments = [corners[b][BOX_EDGES] for b in range(corners.shape[0])
                        if corners.shape[1] == 8]
            boxes.set_segments(np.concatenate(segments) if segments else [])
        label.set_text(f"{title}  t = {times[frame]:.2f} s".strip())
        return scatter, lines, boxes, label

    save_animation(figure, draw, frames, path, fps, dpi)
    return len(frames)


def check_animation_path(path: str | os.PathLike) -> Path:
    """``path`` as a Path if it names a .gif, or an .mp4 with ffmpeg on the PATH.

    Raises
    ------
    MocapError
        Another suffix, or MP4 without ffmpeg.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise MocapError("the animation must be a .gif or .mp4 file", path)
    if suffix == ".mp4" and shutil.which("ffmpeg") is None:
        raise MocapError("writing MP4 needs ffmpeg on the PATH; install it or write a .gif", path)
    return path


#: Longest frame delay a GIF can store (a 16-bit count of centiseconds: 655.35 s).
GIF_MAX_DELAY = 65535


def gif_delay(fps: float) -> int:
    """The GIF frame delay, whole centiseconds (the format's unit), closest to ``1/fps``:
    at least 2, because browsers replay shorter delays at 10 cs (several times slower), and
    at most :data:`GIF_MAX_DELAY` (a longer one cannot be written)."""
    return min(GIF_MAX_DELAY, max(2, int(round(100.0 / fps))))


def real_time_stride(rate: float, frames: int, max_frames: int) -> tuple[int, int]:
    """Frame stride and GIF delay (cs) that replay ``frames`` at ``rate`` Hz in real time:
    at most ``max_frames`` frames drawn, and the stride whose real-time delay is closest to
    a whole number of centiseconds (``stride / rate`` seconds per drawn frame): the smallest
    stride within 5 % of real time, else the closest of up to four times the least."""
    least = max(1, int(np.ceil(rate / 50.0)), int(np.ceil(frames / max(max_frames, 1))))

    def error(stride: int) -> float:
        centiseconds = 100.0 * stride / rate
        return abs(max(2, round(centiseconds)) - centiseconds) / centiseconds

    candidates = range(least, 4 * least + 1)
    best = next((s for s in candidates if error(s) <= 0.05 + 1e-9), None)
    if best is None:
        best = min(candidates, key=error)
    return best, min(GIF_MAX_DELAY, max(2, int(round(100.0 * best / rate))))


def save_animation(figure, draw, frames, path: Path, fps: float, dpi: int,
                   show_progress: bool | None = None) -> None:
    """Render ``draw(frame)`` for each of ``frames`` of ``figure`` (a
    ``matplotlib.figure.Figure``) into ``path`` (GIF by Pillow, MP4 by ffmpeg), all or
    nothing, with a progress bar on a terminal. A GIF's frames last ``gif_delay(fps)``
    centiseconds each (the delays Pillow writes are exactly that)."""
    # deferred: matplotlib is slow to import and only drawing needs it
    from matplotlib import animation

    frames = list(frames)

    class GifWriter(animation.PillowWriter):
        def finish(self):
            self._frames[0].save(self.outfile, save_all=True, append_images=self._frames[1:],
                                 duration=10 * gif_delay(fps), loop=0)

    movie = animation.FuncAnimation(figure, draw, frames=frames, blit=False)
    writer = (GifWriter(fps=100.0 / gif_delay(fps)) if path.suffix.lower() == ".gif"
              else animation.FFMpegWriter(fps=fps))
    with progress_bar(len(frames), f"drawing {path.name}", enabled=show_progress) as bar:
        with atomic_path(path) as tmp:
            movie.save(str(tmp), writer=writer, dpi=dpi,
                       progress_callback=lambda i, n: bar.update(1))
