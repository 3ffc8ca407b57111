"""A per-subject gait report: one self-contained HTML page.

The page holds, inline (it fetches nothing, so it opens from disk or an e-mail): the
provenance (toolkit version, date, command line, normative set and its licence), the
walks and their cycles, the subject's measurements and where each came from, the notes
(every warning of the model), the gait-cycle parameters against the normative values, the
Gait Profile Score with its Gait Variable Scores (table and Movement Analysis Profile
chart), and the cycle plots: each side's mean ± SD over its cycles over the normative band
(mean ± 1 SD, grey), with each side's mean foot off as a dotted line, for every angle,
moment and power the walks have. Figures are SVG drawn by matplotlib.
"""
from __future__ import annotations

import datetime
import html
import io
import os
import re
import warnings

import numpy as np

from mocap.plugingait.events import SIDE_COLOURS
from mocap.plugingait.normative import VARIABLES, Normative
from mocap.plugingait.scores import GaitScores

SIDE_NAMES = {"l": "left", "r": "right"}
#: The figure groups of the page: (id, title, kinds or names of the variables in it).
GROUPS = (("angles-lower", "Pelvis and lower-limb angles",
           ("PelvisAngles", "HipAngles", "KneeAngles", "AnkleAngles", "FootProgressAngles")),
          ("angles-upper", "Trunk, head and upper-limb angles",
           ("ThoraxAngles", "SpineAngles", "NeckAngles", "HeadAngles", "ShoulderAngles",
            "ElbowAngles", "WristAngles")),
          ("moments", "Joint moments", ("HipMoment", "KneeMoment", "AnkleMoment")),
          ("powers", "Joint powers", ("HipPower", "KneePower", "AnklePower")))
_UNITS = {"deg": "degrees", "N.m/kg": "N·m/kg", "W/kg": "W/kg"}

STYLE = """
body{font-family:system-ui,-apple-system,"Segoe UI",sans-serif;margin:0 auto;max-width:1180px;
padding:0 18px 40px;color:#222}
h1{font-size:1.5em;margin:18px 0 4px}h2{font-size:1.2em;border-bottom:1px solid #ccc;
margin-top:28px}.provenance{color:#555;font-size:.85em}.provenance code{word-break:break-all}
table{border-collapse:collapse;margin:8px 0;font-size:.9em}th,td{border:1px solid #ccc;
padding:3px 8px;text-align:right}th:first-child,td:first-child{text-align:left}
thead th{background:#f2f2f2}td.out{background:#fde3d9;font-weight:600}
figure{margin:10px 0}figure svg{max-width:100%;height:auto;display:block}
figcaption{font-size:.85em;color:#555}.notes li{font-size:.85em;color:#444}
.legend span{display:inline-block;margin-right:14px}.swatch{display:inline-block;width:22px;
height:4px;vertical-align:middle;margin-right:4px}
@media print{body{max-width:none;padding:0}figure,table{break-inside:avoid}
h2,h3{break-after:avoid}.swatch{print-color-adjust:exact;-webkit-print-color-adjust:exact}}
"""


def _pool(curves_list, side: str) -> tuple[dict, float]:
    """Every cycle of one side over the walks: variable -> (cycles, samples, 3); mean foot off."""
    pooled: dict[str, list] = {}
    offs = []
    for curves in curves_list:
        for name, values in curves.of_side(side).items():
            pooled.setdefault(name, []).append(values)
        offs += [f for s, f in zip(curves.side, curves.foot_off) if s == side]
    offs = np.array(offs, dtype=float)
    off = float(np.nanmean(offs)) if np.isfinite(offs).any() else float("nan")
    return {k: np.concatenate(v) for k, v in pooled.items()}, off


def _panels(names, pooled: dict) -> list[tuple[str, int, str, str]]:
    """(variable, component, title, unit) of every panel some cycle has data for."""
    out = []
    for variable in VARIABLES:
        if variable.name not in names:
            continue
        for k, title in enumerate(variable.titles):
            if title is None:
                continue
            if any(variable.name in p and np.isfinite(p[variable.name][:, :, k]).any()
                   for p in pooled.values()):
                out.append((variable.name, k, title, variable.unit))
    return out


def _svg(figure) -> str:
    """The figure as inline SVG markup (no XML prolog), text kept as text."""
    import matplotlib

    buffer = io.StringIO()
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": "mocap-report"}):
        figure.savefig(buffer, format="svg", metadata={"Date": None})
    text = buffer.getvalue()
    return text[text.index("<svg"):]


def curves_figure(panels, pooled: dict, foot_off: dict, normative: Normative | None):
    """Mean ± SD per side over the normative band, three panels a row.

    Parameters
    ----------
    panels : list of (variable, component, title, unit)
    pooled : dict side -> dict variable -> ndarray (cycles, samples, 3)
    foot_off : dict side -> float, % of the cycle
    normative : Normative, optional

    Returns
    -------
    matplotlib Figure (no pyplot state).
    """
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    columns = 3
    rows = -(-len(panels) // columns)
    figure = Figure(figsize=(3.5 * columns, 2.25 * rows))
    axes = figure.subplots(rows, columns, squeeze=False)
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    for ax, (variable, k, title, unit) in zip(axes.flat, panels):
        band = normative.band(variable, k) if normative is not None else None
        if band is not None:
            mean, sd = band
            x = normative.percent
            ax.fill_between(x, mean - sd, mean + sd, color="0.82", linewidth=0)
            ax.plot(x, mean, color="0.55", linewidth=0.8)
        for side, colour in SIDE_COLOURS.items():
            values = pooled.get(side, {}).get(variable)
            if values is None or not np.isfinite(values[:, :, k]).any():
                continue
            x = np.linspace(0.0, 100.0, values.shape[1])
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)     # all-NaN samples
                m = np.nanmean(values[:, :, k], axis=0)
                s = np.nanstd(values[:, :, k], axis=0)
            ax.fill_between(x, m - s, m + s, color=colour, alpha=0.18, linewidth=0)
            ax.plot(x, m, color=colour, linewidth=1.4)
            if np.isfinite(foot_off.get(side, np.nan)):
                ax.axvline(foot_off[side], color=colour, linestyle=":", linewidth=1)
        ax.set_title(title, fontsize=9)
        ax.axhline(0.0, color="0.6", linewidth=0.5)
        ax.set_xlim(0, 100)
        ax.set_xticks((0, 20, 40, 60, 80, 100))        # few fixed ticks: drawing ticks is
        ax.yaxis.set_major_locator(MaxNLocator(5))     # most of a figure's time
        ax.tick_params(labelsize=7)
        ax.set_ylabel(_UNITS.get(unit, unit), fontsize=7)
        ax.set_xlabel("% gait cycle", fontsize=7)
        ax.grid(alpha=0.25)
    height = 2.25 * rows            # fixed margins in inches (tight_layout costs 0.8 s)
    figure.subplots_adjust(left=0.07, right=0.99, top=1 - 0.3 / height,
                           bottom=0.45 / height, wspace=0.3, hspace=0.62)
    return figure


def profile_figure(scores: GaitScores, normal: np.ndarray | None = None):
    """The Movement Analysis Profile: GVS per variable and the GPS, left and right bars;
    ``normal`` (10,), the normal walker's GVS and GPS, as grey ticks."""
    from matplotlib.figure import Figure

    labels = list(scores.titles) + ["GPS"]
    figure = Figure(figsize=(9.0, 3.0))
    ax = figure.subplots()
    x = np.arange(len(labels))
    for offset, side in ((-0.2, "l"), (0.2, "r")):
        values = np.append(scores.gvs[side], scores.gps[side])
        ax.bar(x + offset, np.nan_to_num(values), width=0.4, color=SIDE_COLOURS[side],
               label=SIDE_NAMES[side])
    if normal is not None:
        ax.scatter(x, normal, marker="_", s=600, color="0.35", linewidths=2,
                   label="normal walker", zorder=3)
    ax.set_xticks(x, labels, rotation=30, ha="right", fontsize=8)
    ax.set_ylabel("degrees", fontsize=8)
    ax.legend(fontsize=8)
    ax.grid(axis="y", alpha=0.3)
    figure.subplots_adjust(left=0.08, right=0.99, top=0.96, bottom=0.33)
    return figure


def _fmt(value: float, unit: str) -> str:
    if not np.isfinite(value):
        return "—"
    digits = {"m": 3, "s": 3, "m/s": 2}.get(unit, 1)
    return f"{value:.{digits}f}"


def _parameters_table(analyses, normative: Normative | None) -> str:
    from dataclasses import asdict

    from mocap.plugingait.parameters import VICON_NAMES

    norms = normative.parameters if normative is not None else {}
    head = "<tr><th>parameter</th><th>left</th><th>right</th>" + \
        ("<th>normative mean ± SD</th>" if norms else "") + "</tr>"
    rows = []
    for key, (name, unit) in VICON_NAMES.items():
        cells = []
        for side in ("l", "r"):
            entries = [(asdict(p)[key], p.cycles) for a in analyses for p in a.parameters
                       if p.side == side and p.cycles]
            values = np.array([v for v, _ in entries], float)
            weights = np.array([c for _, c in entries], float)
            keep = np.isfinite(values)
            value = float(np.average(values[keep], weights=weights[keep])) \
                if keep.any() else float("nan")
            out = ""
            if key in norms and np.isfinite(value):
                mean, sd = norms[key]
                out = ' class="out"' if abs(value - mean) > 2 * sd else ""
            cells.append(f"<td{out}>{_fmt(value, unit)}</td>")
        if norms:
            mean, sd = norms.get(key, (np.nan, np.nan))
            cells.append(f"<td>{_fmt(mean, unit)} ± {_fmt(sd, unit)}</td>"
                         if np.isfinite(mean) else "<td>—</td>")
        rows.append(f"<tr><td>{html.escape(name)} ({html.escape(unit)})</td>{''.join(cells)}</tr>")
    note = ("" if norms else "<p>The normative set has no gait-parameter values (a lab "
            "reference built with <code>mocap normative</code> has them).</p>")
    if norms and normative.meta.get("parameters_source"):
        note = ("<p>Normative parameters: "
                f"{html.escape(str(normative.meta['parameters_source']))}.</p>")
    return (f'<table id="parameters-table"><thead>{head}</thead><tbody>{"".join(rows)}'
            f"</tbody></table>{note}" + ('<p>Shaded: more than 2 SD from the normative mean.'
                                        '</p>' if norms else ""))


def _scores_table(scores: GaitScores, normative: Normative | None) -> str:
    from mocap.plugingait.scores import normal_scores

    normal, normal_gps = normal_scores(normative) if normative is not None else \
        (np.full(len(scores.titles), np.nan), float("nan"))
    rows = []
    for k, title in enumerate(scores.titles):
        rows.append(f"<tr><td>{html.escape(title)}</td><td>{_fmt(scores.gvs['l'][k], 'deg')}"
                    f"</td><td>{_fmt(scores.gvs['r'][k], 'deg')}</td>"
                    f"<td>{_fmt(normal[k], 'deg')}</td></tr>")
    rows.append(f"<tr><th>GPS</th><th>{_fmt(scores.gps['l'], 'deg')}</th>"
                f"<th>{_fmt(scores.gps['r'], 'deg')}</th><th>{_fmt(normal_gps, 'deg')}</th></tr>")
    rows.append(f'<tr><th>overall GPS</th><th colspan="2">{_fmt(scores.overall, "deg")}'
                f"</th><th>{_fmt(normal_gps, 'deg')}</th></tr>")
    cycles = {s: len(scores.gvs_cycles[s]) for s in "lr"}
    missing = (f"<p>No data for {html.escape(', '.join(scores.missing))}: the GPS is over "
               f"the other variables (Baker's is over all nine).</p>" if scores.missing else "")
    return ('<table id="scores-table"><thead><tr><th>Gait Variable Score (deg)</th>'
            f"<th>left ({cycles['l']} cycles)</th><th>right ({cycles['r']} cycles)</th>"
            f"<th>normal walker</th></tr></thead><tbody>{''.join(rows)}</tbody></table>"
            f"{missing}<p>Normal walker: what a walker of the normative population scores "
            f"(the RMS over the cycle of the normative SD).</p>")


def _table(rows, header) -> str:
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    return ("<table><thead><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header)
            + f"</tr></thead><tbody>{body}</tbody></table>")


def _walk_gps(analysis, normative: Normative) -> float:
    """One walk's overall GPS (NaN when the normative set cannot score it)."""
    from mocap.errors import MocapError
    from mocap.plugingait.scores import gait_scores

    try:
        return gait_scores(analysis.curves, normative).overall
    except MocapError:
        return float("nan")


def report_html(analyses: list, normative: Normative | None, scores: GaitScores | None, *,
                title: str = "", command: str = "", version: str = "",
                date: str | None = None) -> str:
    """The whole report page as a string (see the module docstring).

    Parameters
    ----------
    analyses : list of WalkAnalysis
        The subject's walks (:func:`mocap.plugingait.walks.analyse_walk`).
    normative : Normative, optional
        The band of the plots, the parameters' reference and the scores' mean.
    scores : GaitScores, optional
        (:func:`mocap.plugingait.scores.gait_scores` of the walks' curves).
    title, command, version, date : str
        Shown at the top; ``date`` defaults to now (UTC, ISO 8601).
    """
    date = date or datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    subject = analyses[0].subject_name if analyses else ""
    title = title or f"Gait report: {subject}"
    curves = [a.curves for a in analyses]
    pooled, offs = {}, {}
    for side in ("l", "r"):
        pooled[side], offs[side] = _pool(curves, side)
    origin = {a.origin for a in analyses}
    origin_text = ("Plug-in Gait outputs stored in the files by Vicon" if origin == {"stored"}
                   else "Plug-in Gait computed by mocap")
    walk_rows = [(os.path.basename(a.path), a.curves.side.count("l"),
                  a.curves.side.count("r"), a.events, a.origin,
                  _fmt(_walk_gps(a, normative) if scores is not None else np.nan, "deg"))
                 for a in analyses]
    parts = [f"<h1>{html.escape(title)}</h1>",
             '<p class="provenance">mocap ' + html.escape(version or "") + " · "
             + html.escape(date) + " · " + html.escape(origin_text)
             + (f"<br>command: <code>{html.escape(command)}</code>" if command else "")
             + "</p>",
             '<section id="walks"><h2>Walks</h2>',
             _table(walk_rows, ("walk", "left cycles", "right cycles", "events", "outputs",
                                "overall GPS (deg)")),
             "</section>"]
    subject_rows = analyses[0].subject if analyses else []
    notes = [n for a in analyses for n in a.notes]
    parts += ['<section id="subject"><h2>Subject</h2>',
              _table(subject_rows, ("measurement", "value", "from")) if subject_rows
              else "<p>No measurements recorded.</p>"]
    if notes:
        parts.append('<ul class="notes">' + "".join(f"<li>{html.escape(n)}</li>"
                                                    for n in dict.fromkeys(notes)) + "</ul>")
    parts.append("</section>")
    parts += ['<section id="parameters"><h2>Gait-cycle parameters</h2>',
              _parameters_table(analyses, normative), "</section>"]
    if scores is not None:
        from mocap.plugingait.scores import normal_scores

        normal = (np.append(*normal_scores(normative)) if normative is not None else None)
        parts += ['<section id="scores"><h2>Gait Profile Score</h2>',
                  _scores_table(scores, normative), '<figure class="plot" id="figure-profile">',
                  _svg(profile_figure(scores, normal)),
                  "<figcaption>Movement Analysis Profile (Baker et al. 2009): each variable's "
                  "GVS and the GPS, degrees.</figcaption></figure></section>"]
    legend = ('<p class="legend">' + "".join(
        f'<span><i class="swatch" style="background:{c}"></i>{SIDE_NAMES[s]} mean ± SD '
        f"(dotted: foot off)</span>" for s, c in SIDE_COLOURS.items())
        + ('<span><i class="swatch" style="background:#bbb"></i>normative mean ± 1 SD'
           "</span>" if normative is not None else "") + "</p>")
    parts.append('<section id="curves"><h2>Gait cycles</h2>' + legend)
    if not any(n.endswith(("Moment", "Power")) for p in pooled.values() for n in p):
        parts.append("<p>No joint moments or powers (see the notes).</p>")
    shown = 0
    for ident, heading, names in GROUPS:
        panels = _panels(names, pooled)
        if not panels:
            continue
        shown += 1
        parts += [f'<h3>{html.escape(heading)}</h3><figure class="plot" id="figure-{ident}">',
                  _svg(curves_figure(panels, pooled, offs, normative)),
                  f"<figcaption>{html.escape(heading)} over the gait cycle.</figcaption>"
                  "</figure>"]
    if not shown:
        parts.append("<p>No curves.</p>")
    parts.append("</section>")
    if normative is not None:
        meta = normative.meta
        source = meta.get("source")
        source = (", ".join(source) if isinstance(source, list) else source) or \
            ", ".join(meta.get("walks", [])[:6])
        parts.append('<footer><h2>Normative data</h2><p>' + html.escape(normative.name)
                     + (f" — {html.escape(str(meta['attribution']))}"
                        if meta.get("attribution") else "")
                     + (f"<br>source: {html.escape(str(source))}" if source else "")
                     + (f"<br>licence: {html.escape(str(meta['licence']))}"
                        if meta.get("licence") else "") + "</p></footer>")
    body = "\n".join(parts)
    return ('<!doctype html>\n<html lang="en"><head><meta charset="utf-8">\n'
            '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
            f'<meta name="generator" content="mocap report">'
            f"<title>{html.escape(title)}</title>\n<style>{STYLE}</style></head>\n"
            f"<body>\n{body}\n</body></html>\n")


def write_report(text: str, path: str | os.PathLike) -> int:
    """Write the page (all or nothing); its size in bytes."""
    from mocap.atomic import atomic_path

    data = text.encode("utf-8")
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            handle.write(data)
    return len(data)


def figure_ids(text: str) -> list[str]:
    """The ids of the report's figures, in page order."""
    return re.findall(r'<figure class="plot" id="([^"]+)"', text)


__all__ = ["GROUPS", "SIDE_COLOURS", "curves_figure", "figure_ids", "profile_figure", "report_html",
           "write_report"]
