"""Pictures of motions: stick-figure animations (with cloth and rope) and check plots.

Animations are drawn by :mod:`dynamics.viz.preview` (Pillow, no matplotlib): the motion's
Y (up) is the picture's vertical, the floor a grid at y = 0. GIF through Pillow; MP4 through
ffmpeg when it is on the PATH (otherwise a clear error, never a half-written file). Check
plots are matplotlib figures.
"""
from __future__ import annotations

import os
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from dynamics.viz.render import check_animation_path, gif_delay, real_time_stride
from mocap.atomic import atomic_path
from mocap.body.anthropometry import segment_kind
from mocap.errors import MocapError

if TYPE_CHECKING:
    from matplotlib.figure import Figure


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
        Drawn as lines from each joint to its parent and to its end site, framed and
        following the body (:mod:`dynamics.viz.preview`); a placeholder root (a still root
        joint with one child, as a BVH's root at the floor origin) is not drawn.
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
        The picture is ``size × dpi`` pixels.
    title : str

    Raises
    ------
    MocapError
        Unknown suffix, or MP4 without ffmpeg.
    """
    from dynamics.viz.preview import drawn_bones, render_frames, write_frames

    path = check_animation_path(path)
    world = motion.forward_kinematics()
    joints = world[1]
    end_index, ends = motion.end_site_positions(world)
    points = np.concatenate([joints, ends], axis=1)                    # (F, J+E, 3)
    bones, marked = drawn_bones(motion.skeleton)
    if fps:                     # the user's playback rate: frames evenly spaced
        chosen = np.unique(np.linspace(0, motion.frames - 1,
                                       min(max_frames, motion.frames)).astype(int))
        fps = float(fps)
        delay = gif_delay(fps)
    else:                       # real time: a stride whose frame delay is whole centiseconds
        stride, delay = real_time_stride(motion.rate, motion.frames, max_frames)
        chosen = np.arange(0, motion.frames, stride)
        fps = 100.0 / delay
    cape = rope = cloth_lines = None
    if secondary is not None:
        if secondary.cape is not None:
            cape = secondary.cape[chosen]
            cloth_lines = _grid_lines(secondary.cape_shape)
        if secondary.rope is not None:
            rope = secondary.rope[chosen]
    # the view follows the body (its first drawn joint) across the floor
    centres = points[chosen][:, marked[0] if marked.size else 0].copy()
    centres[:, 1] = 0.0
    size_px = (max(1, int(round(size[0] * dpi))), max(1, int(round(size[1] * dpi))))
    titles = [f"{title}  t = {frame / motion.rate:.2f} s".strip() for frame in chosen]
    frames = render_frames(points[chosen], bones, marked, centres, size_px, titles,
                           cape=cape, cape_lines=cloth_lines, rope=rope)
    write_frames(frames, int(chosen.size), path, delay, fps)
    return int(chosen.size)


def _headroom(axis, factor: float) -> None:
    """Raise an axis's top to ``factor`` × its data's top so a legend fits above the data."""
    low, high = axis.get_ylim()
    if np.isfinite(high) and high > 0:
        axis.set_ylim(low, low + factor * (high - low))


def _residual_panel(axis, t: np.ndarray, series: np.ndarray, judged: dict, unit: str,
                    name: str, colour: str) -> None:
    """One residual over time with the figure the check judges (its RMS) and that figure's
    limit: the verdict says RMS against limit, and so does the panel (a single frame above
    the RMS limit is no failure)."""
    axis.plot(t, series, color=colour, linewidth=0.9, label=f"{name} per frame")
    axis.axhline(judged["value"], color=colour, linewidth=1.6,
                 label=f"RMS {judged['value']:.3g} {unit} (the judged figure)")
    axis.axhline(judged["limit"], color="0.2", linestyle=":",
                 label=f"RMS limit {judged['limit']:.3g} {unit}")
    axis.set_ylabel(f"{name}\n({unit})")
    _headroom(axis, 1.35)
    axis.legend(fontsize=7, loc="upper center", ncol=3)


def plot_check(report, path: str | os.PathLike | None = None, dpi: int = 100,
               plates=None) -> Figure:
    """Plot a :class:`dynamics.humanoid.check.CheckReport`: the residual force and torque
    (each with its RMS and RMS limit), ground reactions (and the measured plates), joint
    torques and the floor penetration the text reports, over time.

    Parameters
    ----------
    report : dynamics.humanoid.check.CheckReport
    path : str or PathLike, optional
        Also write the figure here (PNG, PDF or SVG by suffix; all or nothing).
    dpi : int
        Resolution of the written file (the figure is 8 × 12 inches).
    plates : dynamics.humanoid.plates.MeasuredPlates, optional
        The force plates measured with the motion (``mocap check --forces plates``): each
        plate's vertical force is drawn beside the estimated reactions.

    Returns
    -------
    matplotlib.figure.Figure
        Five axes sharing the time axis; built without pyplot, so no global state changes
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
    figure = Figure(figsize=(8, 12))
    axes = figure.subplots(5, 1, sharex=True)
    verdict = f"{report.verdict}: " + ("; ".join(report.reasons + [
        f"not judged: {part}" for part in report.not_judged]) or "no problems")
    axes[0].set_title(textwrap.fill(verdict, 110), fontsize=8)
    _residual_panel(axes[0], t, 100.0 * np.linalg.norm(report.residual_force, axis=1) / weight,
                    report.limits["residual_force_rms_pct_bw"], "% BW", "residual force",
                    "tab:blue")
    _residual_panel(axes[1], t, np.linalg.norm(report.residual_torque, axis=1),
                    report.limits["residual_torque_rms_Nm"], "N·m",
                    "residual torque about the COM", "tab:red")
    feet = {}
    for k, name in enumerate(report.contact_names):
        feet.setdefault(name.split(".")[0], []).append(k)
    for foot, points in feet.items():
        axes[2].plot(t, report.contact_forces[:, points, 1].sum(axis=1) / weight,
                     label=f"{foot} vertical reaction (BW), estimated")
    if plates is not None:
        for name, force in zip(plates.names, plates.force):
            axes[2].plot(t, force[:, 1] / weight, linestyle="--", linewidth=1.0,
                         label=f"{name} vertical force (BW), measured")
    axes[2].set_ylabel("vertical reaction (BW)")
    _headroom(axes[2], 1.3)
    axes[2].legend(fontsize=7, ncol=2, loc="upper center")
    magnitude = np.linalg.norm(report.joint_torques, axis=2)
    # one colour per joint (hip, knee …), solid left and dashed right, named as the text
    # report names them: the segment the joint moves, the joint in brackets
    kinds = list(JOINT_OF_SEGMENT)
    for j, name in enumerate(report.joint_names):
        kind = segment_kind(name)
        joint = JOINT_OF_SEGMENT.get(kind)
        axes[3].plot(t, magnitude[:, j], linewidth=0.9,
                     label=f"{name} ({joint})" if joint else name,
                     color=f"C{kinds.index(kind) % 10}" if kind in kinds else None,
                     linestyle="--" if name.startswith("r_") else "-")
    axes[3].set_ylabel("joint torque (N·m)")
    _headroom(axes[3], 1.45)                 # the legend sits above the curves
    axes[3].legend(fontsize=6, ncol=4, loc="upper center")
    limit = report.thresholds.penetration_mm
    axes[4].plot(t, report.penetration_series_mm, color="tab:green",
                 label=f"penetration, deepest {report.penetration_mm:.1f} mm")
    axes[4].axhline(limit, color="0.2", linestyle=":", label=f"limit {limit:g} mm")
    axes[4].set_ylabel("floor penetration beyond\nthe tolerance (mm)")
    _headroom(axes[4], 1.3)
    axes[4].legend(fontsize=7, loc="upper center", ncol=2)
    for axis in axes:                       # time ticks and label on every panel
        axis.tick_params(labelbottom=True)
        axis.set_xlabel("time (s)", fontsize=8)
    figure.tight_layout()
    if path is not None:
        with atomic_path(path) as tmp:
            figure.savefig(tmp, dpi=dpi, format=path.suffix.lower()[1:])
    return figure
