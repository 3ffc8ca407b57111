"""Figures of motion synthesis, built without pyplot state.

Every function draws into a given :class:`matplotlib.axes.Axes` (``ax=``) or builds a
:class:`matplotlib.figure.Figure` directly and returns it: no ``pyplot``, no backend switch,
so a notebook user's matplotlib setup is left alone; the caller shows or saves the figure
(:func:`mocap.plot.save_figure`). matplotlib is imported inside the functions that build a
Figure (deferred: it costs ~0.3 s of start-up that commands without plots should not pay).

* :func:`plot_cycle`: one angle over the normalised cycle, captured vs synthesised vs the
  "mean of the other people" baseline, into ``ax``.
* :func:`synthesis_figure`: those panels for chosen angles of one synthesised cell.
* :func:`evaluation_figure`: those panels for the worst, median and best cells of a
  leave-one-out :class:`~synthesis.evaluate.Evaluation`.
"""
from __future__ import annotations

import os
from typing import Sequence

import numpy as np

from mocap.plot import save_figure
from synthesis.evaluate import Evaluation


def plot_cycle(ax, captured: np.ndarray, synthesised: np.ndarray, baseline: np.ndarray,
               title: str = "", ylabel: str = "degrees", captured_label: str = "captured"):
    """One angle over the cycle: captured (black), synthesised (red), baseline (dashed).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Drawn into; nothing else is touched.
    captured, synthesised, baseline : ndarray, shape (samples,), degrees
        The curves over one normalised cycle, plotted against 0–100 % of the cycle.
    title, ylabel : str
        Panel title and y-axis label.
    captured_label : str
        Legend label of the captured curve.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``.
    """
    phase = np.linspace(0, 100, np.asarray(captured).shape[0])
    ax.plot(phase, captured, color="black", lw=1.8, label=captured_label)
    ax.plot(phase, synthesised, color="tab:red", lw=1.4, label="synthesised")
    ax.plot(phase, baseline, color="tab:blue", ls="--", lw=1.1, label="mean of the others")
    if title:
        ax.set_title(title, fontsize=9)
    ax.set_ylabel(ylabel, fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)
    return ax


def synthesis_figure(columns: Sequence[str], captured: np.ndarray, synthesised: np.ndarray,
                     baseline: np.ndarray, shown: Sequence[str] | None = None,
                     title: str = ""):
    """Captured vs synthesised vs baseline curves of one cell, one panel per shown angle.

    Parameters
    ----------
    columns : sequence of str
        Angle column names ``<segment>.<axis>`` of the curves' last axis.
    captured, synthesised, baseline : ndarray, shape (samples, columns), degrees
    shown : sequence of str, optional
        Columns to draw (those not in ``columns`` are passed over); default the first six.
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        Panels in rows of three, x axis in % of the cycle.
    """
    from matplotlib.figure import Figure   # deferred: start-up time

    columns = list(columns)
    names = [c for c in (shown or ()) if c in columns] or columns[:6]
    count = len(names)
    across = max(1, min(3, count))
    rows = -(-count // across)
    figure = Figure(figsize=(11 * across / 3, 3 * rows))
    axes = figure.subplots(rows, across, sharex=True, squeeze=False)
    for k, column in enumerate(names):
        j = columns.index(column)
        plot_cycle(axes.flat[k], captured[:, j], synthesised[:, j], baseline[:, j], column,
                   captured_label="captured (held out)")
    for k in range(count, rows * across):
        axes.flat[k].set_visible(False)
    for ax in axes.flat:                    # cycle ticks and label on every panel
        ax.tick_params(labelbottom=True)
        ax.set_xlabel("% of cycle", fontsize=8)
    axes.flat[0].legend(fontsize=8)
    if title:
        figure.suptitle(title)
    figure.tight_layout()
    return figure


def evaluation_figure(evaluation: Evaluation, max_cells: int = 6, max_angles: int = 4):
    """Synthesised vs captured curves (and the baseline) of some leave-one-out cells.

    Parameters
    ----------
    evaluation : Evaluation
        From :func:`synthesis.evaluate.leave_one_out`; each cell's curves are
        (samples, columns) degrees.
    max_cells : int
        Rows: the worst, the median and the best cells by synthesis error, up to this many.
    max_angles : int
        Columns: the angles that vary most across the captured cells, up to this many.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure   # deferred: start-up time

    ordered = sorted(evaluation.cells, key=lambda c: c.synthesis_rms)
    if len(ordered) > max_cells:
        picks = np.unique(np.linspace(0, len(ordered) - 1, max_cells).round().astype(int))
        ordered = [ordered[i] for i in picks]
    captured = np.stack([c.captured for c in evaluation.cells])
    spread = captured.std(axis=(0, 1))
    angles = np.argsort(spread)[::-1][:max_angles]
    figure = Figure(figsize=(3.2 * len(angles), 2.2 * len(ordered)))
    axes = figure.subplots(len(ordered), len(angles), squeeze=False, sharex=True)
    for row, cell in enumerate(ordered):
        for col, angle in enumerate(angles):
            ylabel = (f"{cell.person} {cell.action}\nsynthesis {cell.synthesis_rms:.1f}°, "
                      f"baseline {cell.baseline_rms:.1f}°\ndegrees") if col == 0 else ""
            plot_cycle(axes[row, col], cell.captured[:, angle], cell.synthesised[:, angle],
                       cell.baseline[:, angle],
                       evaluation.columns[angle] if row == 0 else "", ylabel)
            axes[row, col].tick_params(labelbottom=True)   # ticks on every panel
            axes[row, col].set_xlabel("% of cycle", fontsize=8)
    axes[0, 0].legend(fontsize=7, loc="best")
    figure.suptitle(f"Leave-one-out synthesis: {evaluation.synthesis_rms:.2f}° RMS vs baseline "
                    f"{evaluation.baseline_rms:.2f}°, recognition "
                    f"{100 * evaluation.recognition_accuracy:.0f} %", fontsize=10)
    figure.tight_layout()
    return figure


def plot_evaluation(evaluation: Evaluation, path: str | os.PathLike, max_cells: int = 6,
                    max_angles: int = 4) -> None:
    """Draw :func:`evaluation_figure` to ``path`` (PNG, PDF or SVG by its suffix; written
    all-or-nothing)."""
    suffix = os.fspath(path).rsplit(".", 1)[-1].lower() if "." in os.fspath(path) else "png"
    save_figure(evaluation_figure(evaluation, max_cells, max_angles), path, dpi=110,
                format=suffix)
