"""Figures of the analysis layer, built without pyplot state.

Every function builds a :class:`matplotlib.figure.Figure` directly (no ``pyplot``, no
backend switch), so it is safe in a notebook, a GUI or a worker process alike; the caller
shows or saves it.  matplotlib is imported inside the functions, because it costs ~0.3 s
of start-up that commands without plots should not pay.
"""
from __future__ import annotations

import os

from mocap.rotations.angles import JointAngles, axis_names
from mocap.atomic import atomic_path


def angles_figure(angles: JointAngles, title: str = ""):
    """The angle curves, one panel per segment, three lines (one per Euler axis) each.

    Parameters
    ----------
    angles : JointAngles
        ``values`` (frames, segments, 3) degrees against ``times`` (frames,) seconds.
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure   # deferred: start-up time

    count = len(angles.segments)
    columns = max(1, min(3, count))
    rows = max(1, -(-count // columns))
    figure = Figure(figsize=(4.2 * columns, 2.6 * rows))
    axes = figure.subplots(rows, columns, sharex=True, squeeze=False)
    names = angles.axes or axis_names(angles.sequence)
    for k, segment in enumerate(angles.segments):
        axis = axes[k // columns][k % columns]
        for j, name in enumerate(names):
            axis.plot(angles.times, angles.values[:, k, j], label=name, linewidth=1.2)
        axis.set_title(segment, fontsize=10)
        axis.set_ylabel("degrees")
        axis.grid(alpha=0.3)
        axis.legend(fontsize=7, loc="best")
    for k in range(count, rows * columns):
        axes[k // columns][k % columns].set_visible(False)
    for k in range(count):                  # time ticks and label on every panel
        axis = axes[k // columns][k % columns]
        axis.tick_params(labelbottom=True)
        axis.set_xlabel("time (s)", fontsize=8)
    if title:
        figure.suptitle(title, fontsize=11)
    figure.tight_layout()
    return figure


def save_figure(figure, path: str | os.PathLike, dpi: int = 100, format: str = "png") -> None:
    """Write ``figure`` to ``path`` all-or-nothing (temporary name, then rename).

    ``format`` is matplotlib's (``"png"``, ``"pdf"``, ``"svg"``): the temporary name has no
    telling suffix.
    """
    with atomic_path(path) as tmp:
        figure.savefig(tmp, dpi=dpi, format=format)


def plot_angles(angles: JointAngles, path: str | os.PathLike, title: str = "") -> None:
    """Draw :func:`angles_figure` to a PNG file (written all-or-nothing)."""
    save_figure(angles_figure(angles, title), path)
