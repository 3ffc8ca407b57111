"""Plug-in Gait kinetics against Vicon's stored moments and powers, and its CPU cost.

Every biomechzoo walk with Vicon's kinetics and its subject's static, plus pyCGM's
Movement_trial: per trial × side × joint × component, r and RMS against Vicon's stored
``<Side><Joint>Moment`` (N·mm/kg -> N·m/kg) and ``<Side><Joint>Power`` (W/kg, Z) on the
frames where both exist. Design subjects (the constants in
``data/bodies/plugingait-dempster.toml`` and ``mocap.plugingait.kinetics`` were chosen
on them): HC002D, HC031A, HC033A, HC038A and pyCGM's trial (a staircase: its four
stances are refused, toes over the tread edges, so only its swing counts); report
(held-out): HC030A, HC032A, HC036A, HC039A. Then CPU seconds of ``plugingait_kinetics``
beside ``plugingait_angles`` on one walk, and of the whole ``mocap plugingait`` process
beside ``mocap angles -m plugingait-lower`` on the same file (the reference run),
medians of 5 runs, and the heavy packages that process imported. Issue 22's target is
<= 1 s CPU; on 2026-12-05 (HC030A05, 1.97 s walk, bytecode compiled) it went from
1.13-1.18 s (0.27 s for ``mocap angles``) to 0.33-0.34 s (0.24-0.25 s) when event
detection stopped importing scipy.signal for ``find_peaks`` (now
:func:`mocap.plugingait.events.find_peaks`, the same peaks in numpy). Without ``.pyc``
files (a fresh checkout under ``PYTHONDONTWRITEBYTECODE=1``) both commands take
0.05-0.1 s more: run ``python -m compileall mocap`` first to compare like with like.

Run: ``python benchmarks/plugingait.py``
"""
from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np

from mocap.io import read
from mocap.plugingait.clinical import plugingait_angles, prepare_subject
from mocap.plugingait.kinetics import plugingait_kinetics

ROOT = Path(__file__).resolve().parents[2] / "shared" / "realdata"
STUDY = ROOT / "biomechzoo_sample_study"
DESIGN = ("HC002D", "HC031A", "HC033A", "HC038A")
REPORT = ("HC030A", "HC032A", "HC036A", "HC039A")


def trials(subjects):
    for subject in subjects:
        static = next((STUDY / subject / "Static").glob("*.c3d"))
        for walk in sorted((STUDY / subject).glob("[ST]*/*.c3d")):
            if "Static" not in walk.parts:
                yield walk, static


def scores(walk: Path, static: Path):
    trial, standing = read(walk), read(static)
    m = trial.modelled
    vicon = {label.rpartition(":")[2]: m["values"][:, k] for k, label in enumerate(m["labels"])}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        kin = plugingait_kinetics(trial, static=standing)
    moments, powers, forces = [], [], []
    for k, name in enumerate(kin.segments):
        side, joint = name.split("_")
        label = f"{side.upper()}{joint.capitalize()}"
        if label + "Moment" not in vicon:
            continue
        theirs = vicon[label + "Moment"]
        for c in range(3):
            ok = np.isfinite(theirs[:, c]) & np.isfinite(kin.moments[:, k, c])
            if ok.sum() > 10:
                a, b = kin.moments[ok, k, c] / 1000, theirs[ok, c] / 1000
                moments.append((np.corrcoef(a, b)[0, 1], np.sqrt(np.mean((a - b) ** 2))))
        theirs = vicon.get(label + "Force")
        for c in range(3 if theirs is not None else 0):
            ok = np.isfinite(theirs[:, c]) & np.isfinite(kin.forces[:, k, c])
            if ok.sum() > 10:
                a, b = kin.forces[ok, k, c], theirs[ok, c]
                forces.append((np.corrcoef(a, b)[0, 1], np.sqrt(np.mean((a - b) ** 2))))
        theirs = vicon[label + "Power"][:, 2]
        ok = np.isfinite(theirs) & np.isfinite(kin.powers[:, k])
        if ok.sum() > 10:
            a, b = kin.powers[ok, k], theirs[ok]
            powers.append((np.corrcoef(a, b)[0, 1], np.sqrt(np.mean((a - b) ** 2))))
    return moments, powers, forces


def report(name, pairs):
    moments, powers, forces, count = [], [], [], 0
    for walk, static in pairs:
        try:
            m, p, f = scores(walk, static)
        except Exception as error:          # a trial without plates or outputs: say so
            print(f"  {walk.name}: skipped ({error})")
            continue
        count += 1
        moments += m
        powers += p
        forces += f
    m, p, f = np.array(moments), np.array(powers), np.array(forces)
    print(f"{name}: {count} trials; moments ({len(m)} curves) median r {np.median(m[:, 0]):.3f}, "
          f"median RMS {np.median(m[:, 1]):.3f} N·m/kg; powers ({len(p)}) median r "
          f"{np.median(p[:, 0]):.3f}, median RMS {np.median(p[:, 1]):.3f} W/kg; joint forces "
          f"({len(f)}) median r {np.median(f[:, 0]):.3f}, median RMS {np.median(f[:, 1]):.3f} N/kg")


def cpu(walk: Path, static: Path, repeat: int = 5):
    trial, standing = read(walk), read(static)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        subject = prepare_subject(trial, static=standing)
        runs = {}
        for name, fn in (("angles", lambda: plugingait_angles(trial, subject)),
                         ("kinetics", lambda: plugingait_kinetics(trial, subject,
                                                                  static=standing))):
            fn()
            start = time.process_time()
            for _ in range(repeat):
                fn()
            runs[name] = (time.process_time() - start) / repeat
    print(f"CPU on {walk.name} ({trial.frames} frames): angles {runs['angles'] * 1e3:.1f} ms, "
          f"kinetics {runs['kinetics'] * 1e3:.1f} ms ({runs['kinetics'] / runs['angles']:.1f}x)")


def _children_cpu(argv: list[str]) -> float:
    """CPU seconds (user + system) of one child process running ``argv``."""
    import resource
    import subprocess

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(argv, check=True, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime


def whole_process(walk: Path, static: Path, repeat: int = 5):
    """Children's CPU seconds of each command, median over ``repeat`` runs; then which
    heavy packages the ``mocap plugingait`` process imported, and what importing
    scipy.signal alone (as event detection did before 2026-12-05) would add."""
    import statistics
    import subprocess
    import sys
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        commands = {
            "mocap angles": ["angles", str(walk), "-m", "plugingait-lower", "--static",
                             str(static), "-o", f"{folder}/a.csv"],
            "mocap plugingait": ["plugingait", str(walk), "--static", str(static), "-o",
                                 f"{folder}/p.c3d", "--csv", f"{folder}/p.csv"]}
        seconds = {}
        for name, argv in commands.items():
            runs = []
            for k in range(repeat):
                for old in Path(folder).iterdir():
                    old.unlink()
                runs.append(_children_cpu([sys.executable, "-m", "mocap", *argv]))
            seconds[name] = statistics.median(runs)
        for old in Path(folder).iterdir():
            old.unlink()
        traced = subprocess.run([sys.executable, "-X", "importtime", "-m", "mocap",
                                 *commands["mocap plugingait"]], check=True,
                                capture_output=True, text=True).stderr
    imported = {line.rpartition("|")[2].strip().split(".")[0]
                for line in traced.splitlines() if line.startswith("import time:")}
    heavy = sorted(imported & {"scipy", "pandas", "matplotlib", "pinocchio", "numba"})
    scipy_signal = statistics.median(
        _children_cpu([sys.executable, "-c", "import numpy, scipy.signal"])
        - _children_cpu([sys.executable, "-c", "import numpy"]) for _ in range(repeat))
    trial = read(walk)
    print(f"whole process on {walk.name} ({trial.frames / trial.rate:.2f} s walk), CPU s, "
          f"median of {repeat}: "
          + ", ".join(f"{name} {s:.2f}" for name, s in seconds.items())
          + f" ({seconds['mocap plugingait'] / seconds['mocap angles']:.2f}x; issue 22's "
          f"target <= 1 s: {'met' if seconds['mocap plugingait'] <= 1 else 'NOT met'})")
    print(f"  heavy packages imported by mocap plugingait: {', '.join(heavy) or 'none'}; "
          f"importing scipy.signal (find_peaks, before 2026-12-05) would add "
          f"{scipy_signal:.2f} s")


if __name__ == "__main__":
    movement = ROOT / "pycgm" / "Test_Files"
    report("design", list(trials(DESIGN)) + [(movement / "Movement_trial.c3d",
                                              movement / "Static_trial.c3d")])
    report("report (held out)", list(trials(REPORT)))
    walk = STUDY / "HC030A" / "Straight" / "HC030A05.c3d"
    static = STUDY / "HC030A" / "Static" / "HC030A01.c3d"
    cpu(walk, static)
    whole_process(walk, static)
