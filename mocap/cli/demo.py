"""``mocap demo``: the whole toolkit on one corpus, ending in an HTML report.

Steps (each prints one line with its time):

1. generate a people × actions marker corpus (or use ``--data``);
2. extract joint angles from every trial (marker planes → segment frames → angles);
3. stack the cycles into a people × actions × features tensor;
4. hold out one person's walk and fit the N-mode SVD model on the rest;
5. synthesise that walk from the person's other actions; compare with the captured
   walk and with the baseline (mean walk of the other people); recognise the person;
6. give the synthesised walk a body (skeleton from the markers of one of the person's
   trials on flat ground, feet planted) and export it as BVH and angle CSV;
7. check it with the Pinocchio humanoid (residuals, contact, skating, torques), low-passed
   at 6 Hz like ``mocap check`` and the captured walks the limits are calibrated on;
8. animate it with a cloth cape and a rope from the core simulator (GIF);
9. write ``index.html`` with the figures and tables, and ``view.html``, the interactive
   3-D view (:mod:`mocap.view`) of the captured and the synthesised walk, with the check's
   estimated ground reaction and the synthesised joint angles, embedded in the report.
"""
from __future__ import annotations

import html
import json
import os
import time
from dataclasses import replace
from pathlib import Path
from typing import Callable

import numpy as np

from dynamics.humanoid.check import check_motion
from dynamics.humanoid.plant import motion_from_cycle
from dynamics.secondary import simulate_secondary
from dynamics.viz.animate import animate_motion, plot_check
from mocap import io
from mocap.atomic import atomic_folder
from mocap.body.retarget import motion_from_trial
from mocap.cli.batch_rows import find_trials
from mocap.cli.check import DEFAULT_LOWPASS, ground_reaction_series
from mocap.cli.humanoid import export_motion
from mocap.errors import MocapError
from mocap.io.angles_csv import write_angles_csv
from mocap.io.discovery import parse_trial_name
from mocap.markersets import load_markerset
from mocap.pipeline import Cleaning, marker_file_angles
from mocap.plot import plot_angles, save_figure
from mocap.progress import progress, progress_bar
from mocap.synthetic import ACTIONS, generate_corpus
from mocap.synthetic.people import make_people
from mocap.view import view_files
from synthesis.corpus import CorpusEntry, corpus_from_angles
from synthesis.model import MotionModel
from synthesis.model_file import save_model
from synthesis.imputation import TOO_FEW_CELLS, can_fit
from synthesis.plot import synthesis_figure

ACTION = "walk"
#: Joint angles the report's figure and its 3-D view's curves show.
SHOWN_ANGLES = ("r_thigh.Y", "r_shank.Y", "r_foot.Y", "r_upperarm.Y", "pelvis.Z", "thorax.Z")
#: Zero-lag low-pass of the markers before the angles, Hz (the usual gait-lab choice).
LOWPASS_HZ = 6.0


class _Steps:
    """Numbered progress lines: ``[3/9] stacking the tensor … 0.4 s``."""

    def __init__(self, total: int, echo: Callable[[str], None]):
        self.total, self.count, self.echo = total, 0, echo
        self.started = time.perf_counter()

    def __call__(self, text: str):
        self.count += 1
        self.echo(f"[{self.count}/{self.total}] {text} …")
        return _Timer(self.echo)


class _Timer:
    def __init__(self, echo):
        self.echo = echo

    def __enter__(self):
        self.start = time.perf_counter()
        return self

    def __exit__(self, kind, value, traceback):
        if kind is None:
            self.echo(f"      done in {time.perf_counter() - self.start:.1f} s")


def _rms(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.nanmean((a - b) ** 2)))


def run_demo(out_dir: str | os.PathLike = "mocap-demo", data: str | None = None,
             markerset: str = "synthetic15", people: int = 6, seed: int = 0,
             hold_out: str | None = None, animation: bool = True,
             echo: Callable[[str], None] = print, force: bool = False,
             command: str | None = None) -> dict:
    """Run the whole pipeline and write its outputs under ``out_dir``.

    Parameters
    ----------
    out_dir : path
        Output folder (created).
    data : path, optional
        Corpus folder of ``<person>_<action>`` marker files to use instead of generating
        one; it must hold walks and at least one other action per person.
    markerset : str
        Marker set of the corpus (preset or TOML).
    people, seed : int
        Size and seed of the generated corpus.
    hold_out : str, optional
        Person whose walk is held out (default: the first person).
    animation : bool
        Simulate the cape and write the GIF.
    echo : callable
        Where progress lines go.
    force : bool
        Replace ``out_dir`` when it holds files other than a previous demo's.
    command : str, optional
        The command line that ran the demo, shown in the report (default: the call's
        Python equivalent).

    Returns
    -------
    dict
        The summary written to ``summary.json``: paths and figures.
    """

    final = Path(out_dir)
    chosen = load_markerset(markerset)
    person = _check_inputs(data, hold_out, people, seed)          # before anything is written
    if data is not None and Path(data).resolve().is_relative_to(final.resolve()):
        raise MocapError(f"data= {data} is inside the output folder, which the demo "
                         "replaces; choose another output", final)
    replace = force or (final / "index.html").is_file()          # a previous demo's output
    with atomic_folder(final, replace=replace) as out:
        command = command or (
            f"mocap.cli.demo.run_demo(out_dir={str(out_dir)!r}, data={data!r}, "
            f"markerset={markerset!r}, people={people}, seed={seed}, hold_out={hold_out!r}, "
            f"animation={animation})")
        return _run(out, final, data, chosen, people, seed, person, animation, echo, command)


def _check_inputs(data: str | None, hold_out: str | None, people: int, seed: int) -> str:
    """The held-out person, once ``data`` and ``hold_out`` are known to be usable."""
    if data is None:
        names = [p.name for p in make_people(people, seed)]
        person = hold_out or names[0]
        if person not in names:
            raise MocapError(f"hold_out= {person!r} is not one of the generated people "
                             f"({', '.join(names)})")
        if not _fits_without(person, {(name, action) for name in names for action in ACTIONS}):
            raise MocapError(f"people= {people} is too few: {person}'s {ACTION} is predicted "
                             "from the other people's actions, which needs at least 3 people")
        return person
    if not Path(data).is_dir():
        raise MocapError("data= must be a folder of <person>_<action> marker files", data)
    cells = {parse_trial_name(path) for path in find_trials(data)}
    person = hold_out or sorted(p for p, _ in cells)[0]
    if (person, ACTION) not in cells:
        raise MocapError(f"the corpus has no {ACTION} of {person!r} to hold out "
                         f"(trials must be named <person>_<action>.c3d)", data)
    people_found, actions_found = {p for p, _ in cells}, {a for _, a in cells}
    if len(people_found) < 2 or len(actions_found) < 2:
        raise MocapError(f"need at least 2 people and 2 actions to separate people from "
                         f"actions, found {len(people_found)} people and "
                         f"{len(actions_found)} action(s)", data)
    if not _fits_without(person, cells):
        raise MocapError(f"too few trials to fit a model without {person}'s {ACTION}: "
                         f"{TOO_FEW_CELLS}", data)
    return person


def _fits_without(person: str, cells: set[tuple[str, str]]) -> bool:
    """Whether a model can be fitted to ``cells`` less the held-out (person, walk) cell."""
    names = sorted({p for p, _ in cells})
    actions = sorted({a for _, a in cells})
    observed = np.array([[(p, a) in cells and (p, a) != (person, ACTION) for a in actions]
                         for p in names])
    return can_fit(observed)


def _run(out: Path, final: Path, data: str | None, chosen, people: int, seed: int,
         person: str, animation: bool, echo: Callable[[str], None], command: str) -> dict:
    """The steps, writing into the staging folder ``out`` that becomes ``final``."""
    def shown(path) -> str:                  # where a file will be once the demo is done
        path = Path(path)
        return str(final / path.relative_to(out)) if path.is_relative_to(out) else str(path)

    figures = out / "figures"
    steps = _Steps(9 if animation else 8, echo)
    summary: dict = {"output": str(final)}

    with steps("generating the synthetic corpus" if data is None else f"reading the corpus {data}"):
        if data is None:
            corpus_dir = out / "corpus"
            generate_corpus(corpus_dir, people=people, seed=seed, noise_mm=0.5)
        else:
            corpus_dir = Path(data)
        trials = find_trials(corpus_dir)
        cells = {parse_trial_name(path): path for path in trials}
        summary["corpus"] = shown(corpus_dir)
        summary["trials"] = len(trials)

    for folder in (out, figures, out / "angles", out / "synthesis"):
        folder.mkdir(parents=True, exist_ok=True)
    with steps(f"extracting joint angles from {len(trials)} trials "
               f"(markers low-passed at {LOWPASS_HZ:g} Hz)"):
        names = {}
        cleaning = Cleaning(lowpass_hz=LOWPASS_HZ, short_runs="keep")
        for cell, path in progress(cells.items(), "joint angles"):
            angles = marker_file_angles(path, chosen, cleaning=cleaning).angles
            write_angles_csv(angles, out / "angles" / f"{path.stem}_angles.csv")
            names[cell] = (path, angles)
    captured = names[(person, ACTION)][1]
    plot_angles(captured, figures / "captured_angles.png",
                title=f"{person} {ACTION}: joint angles from marker planes")

    with steps("stacking cycles into a people × actions × features tensor"):
        # the angles in memory, as computed: the CSV files are for the user, not read back
        corpus = corpus_from_angles([(CorpusEntry(path, *cell), angles)
                                     for cell, (path, angles) in names.items()],
                                    markerset=chosen.name,
                                    cleaning={"lowpass_hz": LOWPASS_HZ, "max_gap_seconds": None})
        summary["tensor_shape"] = [len(corpus.people), len(corpus.actions),
                                   corpus.samples * len(corpus.columns)]

    with steps(f"fitting the N-mode SVD model without {person}'s {ACTION}"):
        training = corpus.without_cell(person, ACTION)
        # the model records its sources where they will be once the staging folder is renamed
        training = replace(training, sources={key: [shown(path) for path in paths]
                                              for key, paths in training.sources.items()})
        model = MotionModel().fit(training)
        save_model(model, out / "model.npz")

    with steps(f"synthesising {person}'s {ACTION} from their other actions"), \
            progress_bar(3, "synthesis") as bar:
        p, a = corpus.people.index(person), corpus.actions.index(ACTION)
        truth = corpus.angles[p, a]
        synthesised = model.synthesize_angles(person, ACTION)
        others = [i for i in range(len(corpus.people)) if i != p]
        baseline = np.nanmean(corpus.angles[others, a], axis=0)
        curve = synthesised.values.reshape(truth.shape)
        bar.update(1)
        recognition = model.recognize(truth, action=ACTION)
        bar.update(1)
        summary["synthesis"] = {
            "person": person, "action": ACTION,
            "synthesis_rms_deg": round(_rms(curve, truth), 3),
            "baseline_rms_deg": round(_rms(baseline, truth), 3),
            "captured_duration_s": round(float(corpus.durations[p, a]), 3),
            "predicted_duration_s": round(float(synthesised.times[-1]), 3),
            "recognised_person": recognition.person,
            "recognition_score": round(float(recognition.scores[recognition.person]), 3),
        }
        _plot_synthesis(corpus, truth, curve, baseline, figures / "synthesis.png", person)
        write_angles_csv(synthesised, out / "synthesis" / f"{person}_{ACTION}_synthesised.csv")
        bar.update(1)

    with steps("giving the walk a body: skeleton from markers, feet planted, BVH export"):
        motion = _body_motion(synthesised, names, person, chosen)

        bvh = out / "synthesis" / f"{person}_{ACTION}_synthesised.bvh"
        export_motion(motion, bvh, "bvh")
        summary["bvh"] = shown(bvh)

    with steps(f"checking the motion with the Pinocchio humanoid (low-passed at "
               f"{DEFAULT_LOWPASS:g} Hz, as mocap check)"), progress_bar(2, "check") as bar:
        # The check's limits are calibrated on captured walks low-passed at 6 Hz, and
        # ``mocap check`` of the exported BVH filters so too: the same band here.
        report = check_motion(motion, lowpass=DEFAULT_LOWPASS)
        bar.update(1)
        check = report.summary()
        (out / "check.json").write_text(json.dumps(check, indent=1) + "\n")
        plot_check(report, figures / "check.png")
        bar.update(1)
        summary["check"] = {key: check[key] for key in (
            "verdict", "reasons", "residual_force_rms_pct_bw", "foot_skate_mm",
            "penetration_mm", "floating_mm")}

    if animation:
        with steps("simulating a cloth cape and a rope on the moving body, drawing the GIF"):

            secondary = simulate_secondary(motion, cape=True, rope=True)
            animate_motion(motion, out / "animation.gif", secondary=secondary, max_frames=120,
                           title=f"{person}: synthesised {ACTION} with cape")
            summary["animation"] = shown(out / "animation.gif")

    with steps("writing the HTML report"):
        summary["report"] = shown(out / "index.html")
        # captured markers and synthesised skeleton overlaid, the check's ground reaction
        view_files([names[(person, ACTION)][0], bvh],
                   angles=out / "synthesis" / f"{person}_{ACTION}_synthesised.csv",
                   curves=list(SHOWN_ANGLES), markerset=chosen,
                   check={**check, "ground_reaction": ground_reaction_series(report)},
                   title=f"{person}'s {ACTION}: captured (markers) and synthesised "
                         "(skeleton)").write(out / "view.html")
        summary["view"] = shown(out / "view.html")
        (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
        _write_report(out, final, summary, corpus, command)

    synthesis = summary["synthesis"]
    echo("")
    echo(f"Synthesised {person}'s {ACTION} (never seen by the model): "
         f"{synthesis['synthesis_rms_deg']:.2f}° RMS from the captured walk, baseline "
         f"(mean of the others) {synthesis['baseline_rms_deg']:.2f}°; recognised as "
         f"{synthesis['recognised_person']}; dynamics check: {summary['check']['verdict']}"
         + (f" ({'; '.join(summary['check']['reasons'])})" if summary['check']['reasons'] else "")
         + ".")
    echo(f"Report: {final / 'index.html'}   angles: {final / 'angles'}   BVH: {summary['bvh']}"
         + (f"   animation: {summary['animation']}" if animation else ""))
    return summary


def _body_motion(synthesised, trials: dict, person: str, markerset):
    """Three cycles of the synthesised joint angles on the person's own skeleton (from
    their markers), feet planted (:func:`dynamics.humanoid.plant.motion_from_cycle`)."""

    skeleton = _flat_ground_skeleton(
        [path for (who, _), (path, _) in sorted(trials.items()) if who == person], markerset)
    return motion_from_cycle(synthesised, skeleton, cycles=3)


def _flat_ground_skeleton(paths: list, markerset):
    """The person's skeleton from the first of their trials whose feet stood on one level.

    The soles are put where the feet stand still, on the floor y = 0
    (:func:`mocap.body.retarget.motion_from_trial`); in a stair trial a foot stands a step
    up or down, and its sole would come out a stair's rise off (emil's ascent of the seed-0
    corpus: the left sole 0.17 m low, which planted the walk on a 0.17 m longer left leg,
    148 % body weight of residual). Two soles calibrated more than 3 cm apart (a foot
    without still frames keeps its estimate: 0) mark such a trial; if every trial does,
    the first one is used.
    """
    skeletons = []
    for path in paths:
        motion = motion_from_trial(io.read(path), markerset)
        shifts = motion.metadata.get("sole_calibration_m", {})
        levels = list(shifts.values()) + [0.0] * (2 - len(shifts))   # 0: estimate kept
        if max(levels) - min(levels) <= 0.03:
            return motion.skeleton
        skeletons.append(motion.skeleton)
    return skeletons[0]


def _plot_synthesis(corpus, truth, curve, baseline, path: Path, person: str) -> None:
    figure = synthesis_figure(corpus.columns, truth, curve, baseline,
                              shown=SHOWN_ANGLES,
                              title=f"{person}'s {ACTION}, synthesised from the person's "
                                    "other actions")
    save_figure(figure, path, dpi=90)


#: Words for the summary's keys in the report's table.
_LABELS = {
    "person": "held-out person", "action": "action",
    "synthesis_rms_deg": "synthesis error (RMS over all joint angles, °)",
    "baseline_rms_deg": "baseline error: mean walk of the other people (RMS, °)",
    "captured_duration_s": "captured cycle duration (s)",
    "predicted_duration_s": "predicted cycle duration (s)",
    "recognised_person": "captured walk recognised as",
    "recognition_score": "recognition score (0-1)",
    "verdict": "dynamics verdict", "reasons": "reasons",
    "residual_force_rms_pct_bw": "residual root force (RMS, % body weight)",
    "foot_skate_mm": "foot skating (mm per frame in contact)",
    "penetration_mm": "deepest floor penetration (mm)",
    "floating_mm": "highest unsupported float (mm)",
}


def _explain(synthesis: dict, check: dict, people: int) -> tuple[str, str]:
    """The synthesis and the dynamics verdict in words (HTML-escaped)."""
    s, b = synthesis["synthesis_rms_deg"], synthesis["baseline_rms_deg"]
    person = html.escape(synthesis["person"])
    comparison = (f"{b / s:.1f} times closer than the baseline" if s > 0 and s < b
                  else "no closer than the baseline: the model learnt little about this person")
    synthesis_text = (
        f"The synthesised walk is {s:.2f}° RMS from {person}'s captured walk. The baseline "
        f"is what one would predict knowing nothing about {person}: the mean walk of the other "
        f"{people - 1} people, {b:.2f}° RMS away. The synthesis is {comparison}. It predicts a "
        f"cycle of {synthesis['predicted_duration_s']:.3f} s against the captured "
        f"{synthesis['captured_duration_s']:.3f} s, and the captured walk is recognised as "
        f"{html.escape(str(synthesis['recognised_person']))}.")
    verdict = html.escape(str(check["verdict"]))
    reasons = "; ".join(html.escape(r) for r in check["reasons"]) or "none"
    check_text = (
        f"Verdict: <b>{verdict}</b>. Inverse dynamics asks which forces would make the body "
        f"move like this: the ground may push only where a foot is down and inside its "
        f"friction cone, and whatever it cannot supply is a residual force on the pelvis "
        f"(a motion a real body could not perform) — here "
        f"{check['residual_force_rms_pct_bw']:.1f} % of body weight RMS. Feet in contact "
        f"slide {check['foot_skate_mm']:.1f} mm per frame, sink at most "
        f"{check['penetration_mm']:.1f} mm into the floor and float up to "
        f"{check['floating_mm']:.1f} mm when nothing supports the body. Reasons: {reasons}.")
    return synthesis_text, check_text


def _write_report(out: Path, final: Path, summary: dict, corpus, command: str) -> None:
    """index.html beside the outputs (written in ``out``, read in ``final``), with
    relative links only, saying which version wrote it, when, and from which command."""
    from datetime import datetime, timezone

    from mocap.cli import package_version

    made = (f"Written by mocap {html.escape(package_version())} on "
            f"{datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC from "
            f"<code>{html.escape(command)}</code>.")
    def link(path: str) -> str:
        path = final / Path(path).relative_to(out) if Path(path).is_relative_to(out) else path
        relative = os.path.relpath(path, final)
        return f'<a href="{html.escape(relative)}">{html.escape(relative)}</a>'

    synthesis, check = summary["synthesis"], summary["check"]
    def cell(value) -> str:
        return html.escape("; ".join(value) or "none" if isinstance(value, list) else str(value))

    synthesis_text, check_text = _explain(synthesis, check, len(corpus.people))
    rows = "".join(f"<tr><th>{html.escape(_LABELS.get(k, k))}</th><td>{cell(v)}</td></tr>"
                   for k, v in {**synthesis, **check}.items())
    cells = "".join(
        f"<tr><th>{html.escape(person)}</th>" + "".join(
            f"<td>{'✓' if corpus.cycle_counts[i, j] else '—'}</td>"
            for j in range(len(corpus.actions))) + "</tr>"
        for i, person in enumerate(corpus.people))
    animation = ('<h2>Animation</h2><img src="animation.gif" alt="animation">'
                 if "animation" in summary else "")
    page = f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>mocap demo</title>
<style>body{{font-family:sans-serif;max-width:1100px;margin:2em auto;}}
table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:3px 8px;text-align:left}}
img{{max-width:100%}}</style></head><body>
<h1>mocap demo</h1>
<p>{made}</p>
<p>Corpus: {link(summary['corpus'])} ({summary['trials']} trials). Tensor
people × actions × features = {' × '.join(map(str, summary['tensor_shape']))}.</p>
<table><tr><th></th>{''.join(f'<th>{html.escape(a)}</th>' for a in corpus.actions)}</tr>{cells}</table>
<h2>Joint angles from marker planes</h2>
<p>Each segment's frame comes from its three markers: X anterior, Y to the body's left, Z
up along the segment. An angle <code>segment.Z</code>, <code>.X</code>, <code>.Y</code> is
the segment's rotation relative to its parent's frame (the pelvis's: the lab's) as
intrinsic Euler angles in the order Z, X, Y, degrees: <code>.Z</code> about the long axis
(axial rotation), <code>.X</code> about the anterior axis (ab/adduction, side bending),
<code>.Y</code> about the left axis (flexion/extension; <code>r_thigh.Y</code> is hip
flexion, <code>r_shank.Y</code> knee flexion, both with the sign of the right-hand rule
about the left axis).</p>
<img src="figures/captured_angles.png" alt="angles">
<h2>Synthesis of a held-out walk</h2>
<p>The model never saw this walk: it was synthesised from the person's signature,
estimated from their other actions.</p>
<p>{synthesis_text}</p>
<img src="figures/synthesis.png" alt="synthesis">
<h2>Dynamics check</h2><p>{check_text}</p><img src="figures/check.png" alt="check">
<h2>3-D view</h2><p>The captured walk's markers and the synthesised walk's skeleton, the
check's estimated ground reaction (purple arrows, one per foot) and the synthesised joint angles: drag to
turn, play, scrub ({link(summary['view'])}, one file that opens on its own).</p>
<iframe src="view.html" title="3-D view" style="width:100%;height:720px;border:1px solid #ccc"></iframe>
<h3>All figures</h3><table>{rows}</table>
{animation}
<h2>Files</h2><ul>
<li>Synthesised BVH: {link(summary['bvh'])}</li>
<li>Model: {link(str(out / 'model.npz'))}</li>
<li>Dynamics check: {link(str(out / 'check.json'))}</li>
<li>Joint angles of every trial: {link(str(out / 'angles'))}</li>
<li>Summary: {link(str(out / 'summary.json'))}</li></ul>
</body></html>
"""
    (out / "index.html").write_text(page, encoding="utf-8")
