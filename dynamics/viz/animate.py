"""Pictures of motions: stick-figure animations (with cloth and rope) and check plots.

Animations are drawn with matplotlib's 3-D axes: the motion's Y (up) goes on the plot's
vertical axis, the floor is a grid at y = 0. GIF through Pillow; MP4 through ffmpeg when it
is on the PATH (otherwise a clear error, never a half-written file).
"""
from __future__ import annotations

import os
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from dynamics.viz.render import check_animation_path, real_time_stride, save_animation
from mocap.atomic import atomic_path
from mocap.body.anthropometry import segment_kind
from mocap.errors import MocapError

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def _plot_axes(points: np.ndarray) -> np.ndarray:
    """Y-up world (x, y, z) → plot (x, z, y) so the figure stands upright."""
    return points[..., [0, 2, 1]]


def _grid_lines(shape: tuple[int, int]) -> np.ndarray:
    """Row and column neighbour pairs of a (rows, columns) particle grid, (lines, 2)."""
    rows, columns = shape
    index = np.arange(rows * columns).reshape(rows, columns)
    across = np.stack([index[:, :-1].ravel(), index[:, 1:].ravel()], axis=1)
    down = np.stack([index[:-1, :].ravel(), index[1:, :].ravel()], axis=1)
    return np.concatenate([across, down])


def animate_motion(motion, path: str | os.PathLike, secondary=None, fps: float | None = None,
                   max_frames: int = 200, dpi: int = 80, size: tuple[float, float] = (5.0, 5.0),
                   title: str = "") -> int:
    """Write a stick-figure animation of a motion (GIF or MP4); returns frames drawn.

    Parameters
    ----------
    motion : mocap.skeleton.Motion
        Drawn as lines from each joint to its parent and to its end site.
    path : str or PathLike
        ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg on the PATH).
    secondary : dynamics.secondary.SecondaryMotion, optional
        Cape (grid lines) and rope (polyline) drawn with the figure.
    fps : float, optional
        Playback frame rate; default real time (a frame stride whose duration is a whole
        number of centiseconds, the GIF delay unit).
    max_frames : int
        Frames are subsampled evenly down to at most this many.
    dpi : int
    size : (width, height) inches
    title : str

    Raises
    ------
    MocapError
        Unknown suffix, or MP4 without ffmpeg.
    """
    # deferred: matplotlib is slow to import and only drawing needs it
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    path = check_animation_path(path)
    world = motion.forward_kinematics()
    joints = world[1]
    end_index, ends = motion.end_site_positions(world)
    points = np.concatenate([joints, ends], axis=1)                    # (F, J+E, 3)
    sk = motion.skeleton
    bones = [(i, p) for i, p in enumerate(sk.parents) if p >= 0]
    bones += [(sk.count + k, j) for k, j in enumerate(end_index)]
    bones = np.array(bones, dtype=int).reshape(-1, 2)
    if fps:                     # the user's playback rate: frames evenly spaced
        chosen = np.unique(np.linspace(0, motion.frames - 1,
                                       min(max_frames, motion.frames)).astype(int))
        fps = float(fps)
    else:                       # real time: a stride whose frame delay is whole centiseconds
        stride, delay = real_time_stride(motion.rate, motion.frames, max_frames)
        chosen = np.arange(0, motion.frames, stride)
        fps = 100.0 / delay

    cloth_lines = rope = cape = None
    if secondary is not None:
        if secondary.cape is not None:
            cape = secondary.cape
            cloth_lines = _grid_lines(secondary.cape_shape)
        rope = secondary.rope

    # View box: a cube that follows the figure across the floor (so a walk across a lab
    # stays large in the picture), tall enough for the highest point drawn.
    parts = [points[chosen].reshape(-1, 3)]
    if cape is not None:
        parts.append(cape[chosen].reshape(-1, 3))
    if rope is not None:
        parts.append(rope[chosen].reshape(-1, 3))
    every = np.concatenate(parts)
    every = every[np.isfinite(every).all(axis=1)]
    top = max(float(every[:, 1].max()) * 1.05, 1.0)
    per_frame = points[chosen]
    reach = np.nanmax(np.ptp(per_frame[..., [0, 2]], axis=1)) if per_frame.size else 1.0
    half = max(top / 2, float(reach) / 2 * 1.2, 0.5)
    root_path = points[:, 0, :]
    spacing = 0.25

    figure = Figure(figsize=size, dpi=dpi)             # no pyplot: no global state
    axes = figure.add_subplot(projection="3d")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("z (m)")
    axes.set_zlabel("y up (m)")
    axes.set_zlim(0.0, 2 * half)
    try:
        axes.set_box_aspect((1, 1, 1))
    except AttributeError:          # matplotlib < 3.3
        pass
    axes.view_init(elev=15, azim=-60)
    floor_artist = Line3DCollection([], colors="0.55", linewidths=0.5)
    axes.add_collection3d(floor_artist, autolim=False)

    def floor_lines(cx: float, cz: float) -> list:
        """World-fixed grid lines (every 25 cm) inside the current view square."""
        xs = np.arange(np.ceil((cx - half) / spacing), np.floor((cx + half) / spacing) + 1)
        zs = np.arange(np.ceil((cz - half) / spacing), np.floor((cz + half) / spacing) + 1)
        lines = [[(x * spacing, cz - half, 0), (x * spacing, cz + half, 0)] for x in xs]
        lines += [[(cx - half, z * spacing, 0), (cx + half, z * spacing, 0)] for z in zs]
        return lines

    skeleton_lines = Line3DCollection([], colors="tab:blue", linewidths=2.0)
    axes.add_collection3d(skeleton_lines, autolim=False)
    cloth_artist = Line3DCollection([], colors="tab:red", linewidths=0.6)
    axes.add_collection3d(cloth_artist, autolim=False)
    (rope_artist,) = axes.plot([], [], [], color="tab:brown", linewidth=1.5)
    (joint_artist,) = axes.plot([], [], [], "o", color="navy", markersize=2)
    label = axes.set_title(title)

    def draw(frame: int):
        cx, cz = root_path[frame, 0], root_path[frame, 2]
        axes.set_xlim(cx - half, cx + half)
        axes.set_ylim(cz - half, cz + half)
        floor_artist.set_segments(floor_lines(cx, cz))
        p = _plot_axes(points[frame])
        skeleton_lines.set_segments(p[bones])
        joint_artist.set_data_3d(p[: sk.count, 0], p[: sk.count, 1], p[: sk.count, 2])
        if cape is not None:
            cloth_artist.set_segments(_plot_axes(cape[frame])[cloth_lines])
        if rope is not None:
            r = _plot_axes(rope[frame])
            rope_artist.set_data_3d(r[:, 0], r[:, 1], r[:, 2])
        label.set_text(f"{title}  t = {frame / motion.rate:.2f} s".strip())
        return skeleton_lines, joint_artist, cloth_artist, rope_artist, floor_artist

    save_animation(figure, draw, chosen, path, fps, dpi)
    return int(chosen.size)


def _headroom(axis, factor: float) -> None:
    """Raise an axis's top to ``factor`` × its data's top so a legend fits above the data."""
    low, high = axis.get_ylim()
    if np.isfinite(high) and high > 0:
        axis.set_ylim(low, low + factor * (high - low))


def plot_check(report, path: str | os.PathLike | None = None, dpi: int = 100) -> Figure:
    """Plot a :class:`dynamics.humanoid.check.CheckReport`: residuals, ground reactions, joint
    torques and the lowest body point over time.

    Parameters
    ----------
    report : dynamics.humanoid.check.CheckReport
    path : str or PathLike, optional
        Also write the figure here (PNG, PDF or SVG by suffix; all or nothing).
    dpi : int
        Resolution of the written file (the figure is 8 × 10 inches).

    Returns
    -------
    matplotlib.figure.Figure
        Four axes sharing the time axis; built without pyplot, so no global state changes
        and nothing needs closing.
    """
    # deferred: matplotlib is slow to import and only drawing needs it
    from matplotlib.figure import Figure

    from dynamics.humanoid.model import JOINT_OF_SEGMENT

    if path is not None:
        path = Path(path)
        if path.suffix.lower() not in (".png", ".pdf", ".svg"):
            raise MocapError("the plot must be a .png, .pdf or .svg file", path)
    t = report.times
    weight = report.weight
    figure = Figure(figsize=(8, 10))
    axes = figure.subplots(4, 1, sharex=True)
    force = 100.0 * np.linalg.norm(report.residual_force, axis=1) / weight
    # force in % BW on the left axis, torque in N·m on its own right axis and colour
    axes[0].plot(t, force, color="tab:blue", label="residual force (% BW)")
    axes[0].axhline(report.limits["residual_force_rms_pct_bw"]["limit"], color="tab:blue",
                    alpha=0.5, linestyle=":", label="RMS limit (% BW)")
    axes[0].set_ylabel("residual force (% BW)", color="tab:blue")
    torque_axis = axes[0].twinx()
    torque_axis.plot(t, np.linalg.norm(report.residual_torque, axis=1), color="tab:red",
                     label="residual torque about the COM (N·m)")
    torque_axis.set_ylabel("residual torque (N·m)", color="tab:red")
    verdict = f"{report.verdict}: " + ("; ".join(report.reasons + [
        f"not judged: {part}" for part in report.not_judged]) or "no problems")
    axes[0].set_title(textwrap.fill(verdict, 110), fontsize=8)
    lines = axes[0].get_lines() + torque_axis.get_lines()
    _headroom(axes[0], 1.35)
    _headroom(torque_axis, 1.35)
    axes[0].legend(lines, [line.get_label() for line in lines], fontsize=7, loc="upper center",
                   ncol=3)
    feet = {}
    for k, name in enumerate(report.contact_names):
        feet.setdefault(name.split(".")[0], []).append(k)
    for foot, points in feet.items():
        axes[1].plot(t, report.contact_forces[:, points, 1].sum(axis=1) / weight,
                     label=f"{foot} vertical reaction (BW)")
    axes[1].set_ylabel("vertical reaction (BW)")
    axes[1].legend(fontsize=7)
    magnitude = np.linalg.norm(report.joint_torques, axis=2)
    # one colour per joint (hip, knee …), solid left and dashed right, named as the text
    # report names them: the segment the joint moves, the joint in brackets
    kinds = list(JOINT_OF_SEGMENT)
    for j, name in enumerate(report.joint_names):
        kind = segment_kind(name)
        joint = JOINT_OF_SEGMENT.get(kind)
        axes[2].plot(t, magnitude[:, j], linewidth=0.9,
                     label=f"{name} ({joint})" if joint else name,
                     color=f"C{kinds.index(kind) % 10}" if kind in kinds else None,
                     linestyle="--" if name.startswith("r_") else "-")
    axes[2].set_ylabel("joint torque (N·m)")
    _headroom(axes[2], 1.45)                 # the legend sits above the curves
    axes[2].legend(fontsize=6, ncol=4, loc="upper center")
    axes[3].plot(t, report.lowest_point_mm, color="tab:green")
    axes[3].axhline(0.0, color="0.3", linewidth=0.8)
    axes[3].set_ylabel("lowest body point\nabove the floor (mm)")
    for axis in axes:                       # time ticks and label on every panel
        axis.tick_params(labelbottom=True)
        axis.set_xlabel("time (s)", fontsize=8)
    figure.tight_layout()
    if path is not None:
        with atomic_path(path) as tmp:
            figure.savefig(tmp, dpi=dpi, format=path.suffix.lower()[1:])
    return figure
