"""synthesis.plot: figures drawn from the curves given, without pyplot or backend changes."""
from __future__ import annotations

import matplotlib
import numpy as np
from matplotlib.figure import Figure

from synthesis.evaluate import CellResult, Evaluation
from synthesis.plot import evaluation_figure, plot_cycle, plot_evaluation, synthesis_figure

COLUMNS = ["pelvis.Z", "pelvis.X", "pelvis.Y", "r_thigh.Z", "r_thigh.X", "r_thigh.Y"]


def curves(seed, samples=30):
    rng = np.random.default_rng(seed)
    u = np.linspace(0, 1, samples)[:, None]
    amplitude = np.array([1.0, 2.0, 3.0, 5.0, 8.0, 40.0])      # r_thigh.Y varies most
    return amplitude * np.sin(2 * np.pi * u + rng.uniform(0, 6, len(COLUMNS)))


def evaluation(cells=8):
    results = []
    for k in range(cells):
        captured = curves(k)
        synthesised, baseline = captured + 0.1 * (k + 1), captured + 2.0
        results.append(CellResult(f"p{k}", "walk", 0.1 * (k + 1), 2.0, 1.0, 1.0, f"p{k}",
                                  captured, synthesised, baseline))
    return Evaluation(results, [], list(COLUMNS))


def test_plot_cycle_draws_the_three_curves_into_the_given_axes():
    figure = Figure()
    ax = figure.subplots()
    captured, synthesised, baseline = curves(0).T[:3]
    assert plot_cycle(ax, captured, synthesised, baseline, "pelvis.Z") is ax
    lines = ax.get_lines()
    assert [line.get_label() for line in lines] == ["captured", "synthesised",
                                                    "mean of the others"]
    for line, curve in zip(lines, (captured, synthesised, baseline)):
        assert np.array_equal(line.get_ydata(), curve)
        assert line.get_xdata()[0] == 0 and line.get_xdata()[-1] == 100
    assert ax.get_title() == "pelvis.Z"


def test_synthesis_figure_shows_the_chosen_columns():
    captured = curves(1)
    figure = synthesis_figure(COLUMNS, captured, captured + 1, captured - 1,
                              shown=("r_thigh.Y", "nope.X", "pelvis.Z"), title="t")
    assert isinstance(figure, Figure)
    visible = [ax for ax in figure.axes if ax.get_visible()]
    assert [ax.get_title() for ax in visible] == ["r_thigh.Y", "pelvis.Z"]
    assert np.array_equal(visible[0].get_lines()[0].get_ydata(), captured[:, 5])
    assert np.array_equal(visible[1].get_lines()[1].get_ydata(), captured[:, 0] + 1)
    full = synthesis_figure(COLUMNS, captured, captured + 1, captured - 1)   # two rows
    for ax in full.axes:                       # % of cycle ticks on every panel (issue 11)
        assert ax.get_xlabel() == "% of cycle" and ax.xaxis.get_tick_params()["labelbottom"]


def test_evaluation_figure_picks_worst_median_best_and_the_most_varying_angles(tmp_path):
    backend = matplotlib.get_backend()
    result = evaluation(8)
    figure = evaluation_figure(result, max_cells=3, max_angles=2)
    assert len(figure.axes) == 3 * 2
    rows = [figure.axes[2 * r] for r in range(3)]
    assert [ax.get_ylabel().split("\n")[0] for ax in rows] == ["p0 walk", "p4 walk", "p7 walk"]
    # which error is which, in words (it read '0.1° vs 2.0°')
    assert rows[0].get_ylabel().split("\n")[1] == "synthesis 0.1°, baseline 2.0°"
    assert [ax.get_title() for ax in figure.axes[:2]] == ["r_thigh.Y", "r_thigh.X"]
    for ax in figure.axes:
        assert ax.get_xlabel() == "% of cycle" and ax.xaxis.get_tick_params()["labelbottom"]
    plot_evaluation(result, tmp_path / "loo.svg")
    assert (tmp_path / "loo.svg").read_text().lstrip().startswith("<?xml")
    assert matplotlib.get_backend() == backend
    import matplotlib.pyplot as plt
    assert plt.get_fignums() == []             # nothing registered with pyplot
