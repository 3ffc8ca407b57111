"""Every command as people meet it (issue 11): one line and exit 2 for a user's mistake, no
output onto input, no leftovers, warnings shown, Ctrl-C one line, no blocking on a FIFO.

Each test is one class of problem, run through the real ``mocap`` command line.
"""
from __future__ import annotations

import contextlib
import os
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from mocap.cli import main
from mocap.io import write
from mocap.io.c3d.layout import inspect_c3d
from mocap.synthetic import synthesize_trial

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
SCENE = ROOT / "data" / "scenes" / "swinging-rope.toml"


def _mocap(*argv: str, **kwargs) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    return subprocess.Popen([sys.executable, "-m", "mocap", *argv], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs)


@pytest.fixture(scope="module")
def walk(tmp_path_factory) -> Path:
    """A synthetic full-body walk (synthetic15 markers) as C3D."""
    folder = tmp_path_factory.mktemp("robust")
    trial, _ = synthesize_trial(0, "walk", seed=3)
    path = folder / "ana_walk.c3d"
    write(trial, path)
    return path


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


# ---------------------------------------------------------------- numeric options

@pytest.mark.parametrize("argv, limit", [
    (["angles", "{walk}", "-m", "synthetic15", "-o", "{tmp}/a.csv", "--fill-gaps", "nan"], ">= 0"),
    (["angles", "{walk}", "-m", "synthetic15", "-o", "{tmp}/a.csv", "--order", "100000"], "1 to 20"),
    (["angles", "{walk}", "-m", "synthetic15", "-o", "{tmp}/a.csv", "--lowpass", "inf"], "> 0"),
    (["generate", "{tmp}/c", "--seed", "-1"], "0 to 4294967295"),
    (["generate", "{tmp}/c", "--people", "100000"], "1 to 200"),
    (["generate", "{tmp}/c", "--rate", "nan"], ">= 0.001"),
    (["simulate", "{scene}", "-o", "{tmp}/s.npz", "--dt", "inf"], "> 0"),
    (["check", "{data}/cmu_lambada.amc", "--rate", "0"], ">= 0.001"),
    (["check", "{data}/mocapbank_walk.bvh", "--mu", "nan"], ">= 0"),
    (["check", "{data}/mocapbank_walk.bvh", "--mu", "-1"], ">= 0"),
    (["animate", "{data}/mocapbank_walk.bvh", "-o", "{tmp}/a.gif", "--dpi", "0"], "10 to 600"),
    (["synthesize", "m.npz", "--person", "a", "--to", "b", "--weight", "nan", "--action",
      "walk", "-o", "{tmp}/s.csv"], "<= 1"),
    (["synthesize", "m.npz", "--person", "a", "--to", "b", "--weight", "7", "--action",
      "walk", "-o", "{tmp}/s.csv"], "<= 1"),
    (["demo", "-o", "{tmp}/d", "--people", "100000"], "1 to 200"),
    (["batch", "{walk}", "--jobs", "0"], "1 to 256"),
])
def test_every_numeric_option_is_checked_once_with_its_limit(argv, limit, walk, tmp_path, capsys):
    argv = [a.format(walk=walk, tmp=tmp_path, scene=SCENE, data=DATA) for a in argv]
    assert main(argv) == 2
    line = _one_error_line(capsys)
    assert "must be" in line and limit in line
    assert list(tmp_path.iterdir()) == []          # nothing written


# ---------------------------------------------------------------- outputs

@pytest.mark.parametrize("argv", [
    ["convert", "{csv}", "{csv}"],
    ["angles", "{csv}", "-m", "synthetic15", "-o", "{csv}"],
    ["angles", "{walk}", "-m", "synthetic15", "-o", "{tmp}/a.csv", "--plot", "{walk}"],
    ["angles", "{tmp}", "-m", "synthetic15", "-o", "{tmp}"],
    ["batch", "{tmp}", "-o", "{csv}"],
    ["export", "{bvh}", "--format", "bvh", "-o", "{bvh}"],
    ["simulate", "{scene}", "-o", "{scene}"],
])
def test_no_command_writes_onto_its_input(argv, walk, tmp_path, capsys):
    csv = tmp_path / "ana_run.csv"
    trial, _ = synthesize_trial(0, "walk", seed=3)
    write(trial, csv)
    bvh = tmp_path / "walk.bvh"
    bvh.write_bytes((DATA / "mocapbank_walk.bvh").read_bytes())
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE.read_text())
    before = {p: p.read_bytes() for p in tmp_path.iterdir()}
    argv = [a.format(csv=csv, walk=walk, tmp=tmp_path, bvh=bvh, scene=scene) for a in argv]
    assert main(argv) == 2
    assert "overwrite the input" in _one_error_line(capsys)
    assert {p: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_folder_or_unwritable_place_as_output_is_one_line(walk, tmp_path, capsys):
    folder = tmp_path / "folder.csv"
    folder.mkdir()
    assert main(["convert", str(walk), str(folder)]) == 2
    assert "is a folder" in _one_error_line(capsys)
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["convert", str(walk), str(blocker / "out.csv")]) == 2
    assert "in the way" in _one_error_line(capsys)
    if os.geteuid() != 0:                       # root writes anywhere (see the next test)
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        assert main(["convert", str(walk), str(locked / "out.csv")]) == 2
        assert "permission denied" in _one_error_line(capsys)


@pytest.mark.skipif(not Path("/sys/kernel").is_dir() or not Path("/proc/self").is_dir(),
                    reason="needs Linux /proc and /sys")
@pytest.mark.parametrize("place", ["/sys", "/sys/kernel", "/proc", "/proc/self"])
def test_a_place_the_system_refuses_even_to_root_is_one_line(place, walk, capsys):
    """sysfs and procfs refuse new files to every user, root included (the read-only
    folder of the test above, which root would bypass): one line, exit 2, nothing made."""
    target = Path(place) / f"mocap-test-{os.getpid()}.csv"
    assert main(["convert", str(walk), str(target)]) == 2
    line = _one_error_line(capsys)
    assert str(target) in line and "cannot write" in line
    # nothing of ours there (not a listing before/after: /proc gains every new process)
    assert [name for name in os.listdir(place) if target.name in name] == []


def test_an_existing_pipe_or_device_as_output_is_refused_not_replaced(walk, tmp_path, capsys):
    """Renaming the finished file onto a FIFO or a device node would replace the node
    itself (as root, -o /dev/null would turn /dev/null into a CSV)."""
    nodes = [tmp_path / "fifo.csv"]
    os.mkfifo(nodes[0])
    if os.geteuid() == 0:                        # a private copy of /dev/full (1, 7)
        nodes.append(tmp_path / "full.trc")
        os.mknod(nodes[1], 0o666 | stat.S_IFCHR, os.makedev(1, 7))
    for node in nodes:
        assert main(["convert", str(walk), str(node)]) == 2
        line = _one_error_line(capsys)
        assert str(node) in line and "not a regular file" in line
    assert stat.S_ISFIFO(os.lstat(nodes[0]).st_mode)
    if len(nodes) == 2:
        assert stat.S_ISCHR(os.lstat(nodes[1]).st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in nodes)


def test_a_command_that_fails_after_writing_one_output_leaves_none(walk, tmp_path, capsys):
    """angles writes its CSV, then cannot write the plot: the CSV goes too (a new one is
    removed, a replaced one gets its previous content back)."""
    (tmp_path / "blocker").write_text("x")
    argv = ["angles", str(walk), "-m", "synthetic15", "-o", str(tmp_path / "a.csv"),
            "--plot", str(tmp_path / "blocker" / "a.png")]
    assert main(argv) == 2
    assert "in the way" in _one_error_line(capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["blocker"]
    (tmp_path / "a.csv").write_text("the user's old angles")
    assert main(argv) == 2
    assert (tmp_path / "a.csv").read_text() == "the user's old angles"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "blocker"]


def test_a_failed_command_takes_back_the_folders_it_made(walk, tmp_path, capsys):
    """Found by the hostile re-run: angles -o new/deep/a.csv that then failed (or was
    interrupted) left new/deep/ behind, empty. Folders the command made go with its
    outputs; a folder that was there before, or that got other files meanwhile, stays."""
    (tmp_path / "blocker").write_text("x")
    argv = ["angles", str(walk), "-m", "synthetic15", "-o", str(tmp_path / "new" / "deep" /
            "a.csv"), "--plot", str(tmp_path / "blocker" / "a.png")]
    assert main(argv) == 2
    assert "in the way" in _one_error_line(capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["blocker"]
    from mocap.atomic import all_or_nothing, atomic_path
    (tmp_path / "kept").mkdir()
    with pytest.raises(KeyboardInterrupt):
        with all_or_nothing():
            with atomic_path(tmp_path / "kept" / "made" / "a.csv") as tmp:
                tmp.write_text("a")
            with atomic_path(tmp_path / "other" / "b.csv") as tmp:
                tmp.write_text("b")
            (tmp_path / "other" / "the user's file").write_text("c")
            raise KeyboardInterrupt
    assert sorted(p.name for p in tmp_path.rglob("*")) == [
        "blocker", "kept", "other", "the user's file"]


def test_ctrl_c_after_some_outputs_takes_them_back(tmp_path):
    from mocap.atomic import all_or_nothing, atomic_folder, atomic_path
    (tmp_path / "old.csv").write_text("old")
    with pytest.raises(KeyboardInterrupt):
        with all_or_nothing():
            with atomic_path(tmp_path / "new.csv") as tmp:
                tmp.write_text("new")
            with atomic_path(tmp_path / "old.csv") as tmp:
                tmp.write_text("replaced")
            with atomic_folder(tmp_path / "corpus") as staging:
                (staging / "a.c3d").write_text("a")
            assert (tmp_path / "old.csv").read_text() == "replaced"
            raise KeyboardInterrupt
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.csv"]
    assert (tmp_path / "old.csv").read_text() == "old"
    with all_or_nothing():                       # success: the outputs stay, no backups
        with atomic_path(tmp_path / "old.csv") as tmp:
            tmp.write_text("kept")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.csv"]
    assert (tmp_path / "old.csv").read_text() == "kept"


def test_generate_refuses_an_existing_corpus_and_a_failure_leaves_nothing(tmp_path, capsys):
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    (corpus / "mine.txt").write_text("the user's file")
    assert main(["generate", str(corpus), "--people", "1", "--actions", "walk"]) == 2
    assert "--force" in _one_error_line(capsys)
    assert [p.name for p in corpus.iterdir()] == ["mine.txt"]
    # a failure part-way (an unknown action) leaves no half corpus, no staging folder
    assert main(["generate", str(tmp_path / "new"), "--people", "1",
                 "--actions", "walk,nosuch"]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["corpus"]
    assert main(["generate", str(corpus), "--people", "1", "--actions", "walk", "--force"]) == 0
    assert sorted(p.name for p in corpus.iterdir()) == ["ana_walk.c3d", "truth"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["corpus"]
    # one folder rule: the corpus's trials, never its ground truth in truth/
    capsys.readouterr()
    assert main(["info", str(corpus), "--json"]) == 0
    assert len(capsys.readouterr().out.strip().splitlines()) == 1


def test_a_killed_write_leaves_a_part_file_the_next_write_removes(tmp_path):
    target = tmp_path / "out.csv"
    code = ("import sys, time\nfrom mocap.atomic import atomic_path\n"
            f"with atomic_path({str(target)!r}) as tmp:\n"
            "    tmp.write_text('half'); print('ready', flush=True); time.sleep(60)\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    writer = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                              env=env)
    assert writer.stdout.readline().strip() == "ready"
    writer.send_signal(signal.SIGKILL)
    writer.wait()
    leftovers = [p for p in tmp_path.iterdir() if p.name.endswith(".part.csv")]
    assert len(leftovers) == 1 and not target.exists()
    trial, _ = synthesize_trial(0, "walk", seed=3)
    write(trial, target)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]


# ---------------------------------------------------------------- inputs

def test_a_fifo_as_input_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "walk.c3d"
    os.mkfifo(fifo)
    for argv in (["info", str(fifo)], ["convert", str(fifo), str(tmp_path / "o.csv")],
                 ["check", str(fifo), "-m", "synthetic15"]):
        process = _mocap(*argv)
        try:
            _, err = process.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            process.kill()
            pytest.fail(f"mocap {argv[0]} blocked on a FIFO")
        assert process.returncode == 2
        assert err.strip().count("\n") == 0 and "not a regular file" in err


def _cut_at_frame(source: Path, target: Path, keep: int) -> None:
    layout = inspect_c3d(source)
    words = layout.point_count * 4 + layout.analog_samples_per_frame
    frame_bytes = words * (4 if layout.is_float else 2)
    start = (layout.data_block - 1) * 512
    target.write_bytes(source.read_bytes()[:start + keep * frame_bytes])


@pytest.mark.parametrize("command", ["convert", "angles", "batch", "check"])
def test_a_c3d_cut_at_a_frame_boundary_warns_on_every_command(command, walk, tmp_path, capsys):
    cut = tmp_path / "ana_walk.c3d"
    _cut_at_frame(walk, cut, 40)
    out = tmp_path / "out.csv"
    argv = {"convert": ["convert", str(cut), str(out)],
            "angles": ["angles", str(cut), "-m", "synthetic15", "-o", str(out)],
            "batch": ["batch", str(cut), "-o", str(out)],
            "check": ["check", str(cut), "-m", "synthetic15", "--json"]}[command]
    assert main(argv) == 0
    warnings = [line for line in capsys.readouterr().err.splitlines() if "warning:" in line]
    assert len(warnings) == 1 and "40" in warnings[0] and str(cut) in warnings[0]


@pytest.mark.parametrize("rate", ["0", "-100", "nan", "inf", "1e-30"])
def test_implausible_rates_are_refused_by_the_readers(rate, tmp_path, capsys):
    path = tmp_path / "vicon.csv"
    path.write_text(f"Trajectories\n{rate}\n,,A,,\nFrame,Sub Frame,X,Y,Z\n,,mm,mm,mm\n"
                    "1,0,1,2,3\n2,0,1,2,3\n3,0,1,2,3\n")
    assert main(["convert", str(path), str(tmp_path / "out.trc")]) == 2
    assert "not plausible" in _one_error_line(capsys)
    assert not (tmp_path / "out.trc").exists()


def test_batch_with_a_bad_marker_set_says_so_once(walk, capsys):
    assert main(["batch", str(walk.parent), "-m", "nosuch"]) == 2
    assert "nosuch" in _one_error_line(capsys)


# ---------------------------------------------------------------- Ctrl-C

@pytest.mark.parametrize("delay", [0.5, 1.0, 2.0])
def test_ctrl_c_at_any_moment_is_one_line_and_130_and_leaves_nothing(delay, tmp_path):
    """A long ``generate`` (60 people × 4 actions) interrupted during start-up imports or
    while writing: one line, status 130, no half corpus and no staging folder."""
    process = _mocap("generate", str(tmp_path / "corpus"), "--people", "60",
                     preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(delay)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert err.strip().splitlines() == ["mocap generate: interrupted"] or \
        err.strip().splitlines() == ["mocap: interrupted"], err
    assert list(tmp_path.iterdir()) == []


def _console_script() -> str:
    """What pip writes for the ``mocap`` console script of pyproject.toml, as ``-c`` code."""
    import tomllib
    entry = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]["mocap"]
    module, function = entry.split(":")
    return f"import sys\nfrom {module} import {function}\nsys.exit({function}())\n"


@pytest.mark.parametrize("how", ["console script", "python -m mocap"])
def test_ctrl_c_while_the_shell_is_imported_is_one_line(how, tmp_path):
    """Ctrl-C while ``mocap`` imports its shell: the first module it imports (argparse) is
    replaced, through PYTHONPATH, by one that says it is loading and then waits, so the
    interrupt lands inside that import every time. The console script printed a
    KeyboardInterrupt traceback (its import of the shell was outside every handler)."""
    hooks = tmp_path / "hooks"
    hooks.mkdir()
    ready = tmp_path / "importing"
    (hooks / "argparse.py").write_text(
        f"import time\nopen({str(ready)!r}, 'w').close()\ntime.sleep(120)\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(hooks), str(ROOT)])}
    start = ([sys.executable, "-c", _console_script(), "info", str(DATA / "mocapbank_walk.bvh")]
             if how == "console script" else
             [sys.executable, "-m", "mocap", "info", str(DATA / "mocapbank_walk.bvh")])
    process = subprocess.Popen(start, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True,
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        while process.poll() is None and not ready.exists():
            time.sleep(0.01)
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
    assert ready.exists(), err
    assert (process.returncode, err) == (130, "mocap: interrupted\n")


# ---------------------------------------------------------------- animations

def _gif_delays(path: Path) -> list[int]:
    from PIL import Image
    delays = []
    with Image.open(path) as image:
        for index in range(image.n_frames):
            image.seek(index)
            delays.append(image.info["duration"])
    return delays


def test_gifs_play_at_their_real_speed_or_the_asked_fps(tmp_path, capsys):
    bvh = DATA / "mocapbank_walk.bvh"              # 10 frames at 30 Hz: 0.3 s of motion
    assert main(["animate", str(bvh), "-o", str(tmp_path / "real.gif")]) == 0
    delays = _gif_delays(tmp_path / "real.gif")
    assert all(d >= 20 and d % 10 == 0 for d in delays)
    assert abs(sum(delays) / 1000 - 10 / 30) <= 0.1 * 10 / 30 + 0.07    # real time ± a frame
    assert main(["animate", str(bvh), "-o", str(tmp_path / "fps.gif"), "--fps", "5"]) == 0
    assert set(_gif_delays(tmp_path / "fps.gif")) == {200}


def test_check_names_torques_the_same_way_in_text_and_json(capsys):
    import json
    bvh = str(DATA / "mocapbank_walk.bvh")
    assert main(["check", bvh, "--json"]) == 0
    names = json.loads(capsys.readouterr().out)["peak_joint_torque_Nm"]
    assert main(["check", bvh]) == 0
    line = next(l for l in capsys.readouterr().out.splitlines() if "peak joint torques" in l)
    shown = [item.strip().split(" ")[0] for item in line.split(":", 1)[1].split(",")]
    assert shown == list(names)


def test_angle_plots_have_time_ticks_on_every_panel():
    from mocap.rotations.angles import JointAngles
    from mocap.plot import angles_figure
    angles = JointAngles(times=np.arange(20) / 10.0, values=np.zeros((20, 4, 3)),
                         segments=["a", "b", "c", "d"], sequence="ZXY", parents=[-1, 0, 1, 2])
    figure = angles_figure(angles)
    shown = [axis for axis in figure.axes if axis.get_visible()]
    assert len(shown) == 4
    for axis in shown:
        assert axis.get_xlabel() == "time (s)" and axis.xaxis.get_tick_params()["labelbottom"]


def test_angles_with_a_marker_set_the_trial_lacks_is_one_line(walk, tmp_path, capsys):
    """synthetic15 markers read with the Plug-in Gait set: no LASI to estimate the subject
    from (a KeyError traceback before), one line naming what is missing."""
    assert main(["angles", str(walk), "-m", "plugingait-lower", "-o", str(tmp_path / "a.csv")]) == 2
    line = _one_error_line(capsys)
    assert str(walk) in line and "LASI" in line
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- found by the hostile re-run

def test_an_empty_path_is_one_line_not_the_current_folder(walk, tmp_path, capsys, monkeypatch):
    """``--output ''`` named the current folder: demo tried to replace '.' (OSError
    traceback, EBUSY) and left its staging folder."""
    monkeypatch.chdir(tmp_path)
    for argv in (["convert", str(walk), ""], ["generate", "--output", "", "--people", "1"],
                 ["info", ""]):
        assert main(argv) == 2
        assert "empty name" in _one_error_line(capsys)
    assert list(tmp_path.iterdir()) == []


def test_amc_and_asf_values_must_be_finite(tmp_path, capsys):
    """An AMC value of -inf reached the SVD of the body mapping (LinAlgError traceback)."""
    asf = (DATA / "cmu_lambada.asf").read_text()
    amc = (DATA / "cmu_lambada.amc").read_text()
    lines = amc.splitlines()
    row = next(i for i, line in enumerate(lines) if line.startswith("lfemur "))
    words = lines[row].split()
    words[1] = "-inf"
    lines[row] = " ".join(words)
    (tmp_path / "m.asf").write_text(asf)
    (tmp_path / "m.amc").write_text("\n".join(lines) + "\n")
    out = tmp_path / "m.bvh"
    assert main(["export", str(tmp_path / "m.amc"), "--asf", str(tmp_path / "m.asf"),
                 "-f", "bvh", "-o", str(out)]) == 2
    line = _one_error_line(capsys)
    assert "m.amc" in line and f"line {row + 1}" in line and "finite" in line
    (tmp_path / "m.amc").write_text(amc)
    (tmp_path / "m.asf").write_text(asf.replace("length ", "length nan #", 1))
    assert main(["export", str(tmp_path / "m.amc"), "--asf", str(tmp_path / "m.asf"),
                 "-f", "bvh", "-o", str(out)]) == 2
    assert "finite" in _one_error_line(capsys)
    assert not out.exists()


def test_batch_with_a_scheduler_that_is_no_address_is_one_line(walk, capsys):
    pytest.importorskip("dask.distributed")
    assert main(["batch", str(walk), "--scheduler", "nosuch"]) == 2
    line = _one_error_line(capsys)
    assert "nosuch" in line and "Dask scheduler" in line


def test_batch_on_dask_leaves_nothing_in_the_temporary_folder(walk, tmp_path):
    """A LocalCluster left dask-scratch-space/ in TMPDIR after every run."""
    pytest.importorskip("dask.distributed")
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = {**os.environ, "PYTHONPATH": str(ROOT), "TMPDIR": str(scratch)}
    done = subprocess.run([sys.executable, "-m", "mocap", "batch", str(walk), "--dask", "-j",
                           "1", "-o", str(tmp_path / "t.csv")], env=env, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "t.csv").exists()
    assert list(scratch.iterdir()) == []


def test_ctrl_c_on_dask_at_any_moment_leaves_nothing_and_is_one_line(walk, tmp_path):
    """Ctrl-C typed at the terminal (SIGINT to the whole process group, workers included)
    again and again from the moment the scratch folder exists: the cluster's start, the
    run and the clean-up are all interrupted.  The clean-up used to be cut short, leaving
    mocap-dask-*/dask-scratch-space/ behind, and a Ctrl-C while the cluster started was
    ignored altogether."""
    pytest.importorskip("dask.distributed")
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = {**os.environ, "PYTHONPATH": str(ROOT), "TMPDIR": str(scratch)}
    process = subprocess.Popen(
        [sys.executable, "-m", "mocap", "batch", str(walk), "--dask", "-j", "1", "-o",
         str(tmp_path / "t.csv")], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True, start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))  # even if ignored here
    try:
        while process.poll() is None and not any(scratch.iterdir()):
            time.sleep(0.01)
        while process.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGINT)
            time.sleep(0.05)
        _, err = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
    assert process.returncode == 130, err
    assert err.strip().splitlines() == ["mocap batch: interrupted"], err
    assert list(scratch.iterdir()) == [] and not (tmp_path / "t.csv").exists()


def test_batch_on_dask_keeps_dask_s_own_warnings_to_itself(walk, tmp_path):
    """With port 8787 taken (another cluster's dashboard), distributed warned in three lines
    'Port 8787 is already in use …', printed as a mocap warning."""
    pytest.importorskip("dask.distributed")
    import socket
    with socket.socket() as holder:
        holder.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        with contextlib.suppress(OSError):      # already taken by someone: just as good
            holder.bind(("", 8787))
            holder.listen(1)
        env = {**os.environ, "PYTHONPATH": str(ROOT)}
        done = subprocess.run([sys.executable, "-m", "mocap", "batch", str(walk), "--dask",
                               "-j", "1"], env=env, capture_output=True, text=True,
                              timeout=300)
    assert done.returncode == 0 and done.stderr == "1 of 1 trial analysed\n", done.stderr


def test_segment_names_that_would_corrupt_the_angle_csv_are_refused(walk, tmp_path, capsys):
    """A marker set whose segment is named 'pel,vis' (or holds a line break) wrote an angle
    CSV whose header had more columns than its rows."""
    from mocap.markersets import parse
    text = parse.PRESETS / "synthetic15.toml"
    for bad in ("pel,vis", "pel\\nvis"):
        toml = tmp_path / "set.toml"
        toml.write_text(Path(text).read_text().replace('"pelvis"', f'"{bad}"'))
        out = tmp_path / "a.csv"
        assert main(["angles", str(walk), "-m", str(toml), "-o", str(out)]) == 2
        line = _one_error_line(capsys)
        assert "segment label" in line and str(out) in line
        assert not out.exists()


def test_a_csv_of_a_trial_without_markers_has_one_column_per_cell(tmp_path):
    from mocap.io import read
    from mocap.trial import Trial
    trial = Trial(labels=[], points=np.zeros((3, 0, 3)), rate=100.0)
    write(trial, tmp_path / "none.csv")
    lines = (tmp_path / "none.csv").read_text().splitlines()
    assert lines[0] == "time" and all("," not in line for line in lines)
    assert read(tmp_path / "none.csv").frames == 3


# ---------------------------------------------------------------- one rule per idea (issue 11)

def test_ctrl_c_that_python_cannot_raise_is_still_one_line(tmp_path):
    """A Ctrl-C that lands where CPython cannot raise it (a garbage-collection or weakref
    callback, a destructor) printed "Exception ignored in …" and a KeyboardInterrupt
    traceback before the one line. Here the interrupt is sent from inside the first garbage
    collection of the command, so it lands there every time."""
    code = (
        "import gc, os, signal, sys, time\n"
        "from mocap.cli import main\n"
        "sent = []\n"
        "def interrupt(phase, info):\n"
        "    handler = signal.getsignal(signal.SIGINT)\n"
        "    if phase == 'start' and not sent and getattr(handler, '__name__', '') == '_raise':\n"
        "        sent.append(1)\n"
        "        os.kill(os.getpid(), signal.SIGINT)\n"
        "        for _ in range(100):\n"
        "            time.sleep(0.001)\n"
        "gc.callbacks.append(interrupt)\n"
        f"sys.exit(main(['info', {str(DATA / 'mocapbank_walk.bvh')!r}]))\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, timeout=120,
                          preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert (done.returncode, done.stderr) == (130, "mocap info: interrupted\n")


def test_an_error_echoing_a_line_break_stays_one_line(tmp_path, capsys):
    """A file name holding a line break made a two-line error (and a warning likewise)."""
    name = tmp_path / "walk\nrun.c3d"
    assert main(["info", str(name)]) == 2
    line = _one_error_line(capsys)
    assert "walk\\nrun.c3d" in line and "no such file" in line
    assert main(["batch", str(DATA / "mocapbank_walk.bvh"), "-m", "no\r\nsuch"]) == 2
    assert "no\\r\\nsuch" in _one_error_line(capsys)


def test_batch_of_one_unreadable_file_is_an_error(walk, tmp_path, capsys):
    """One trial that fails is the user's mistake, told in one line with status 2 (it was a
    table of one failure and status 1); a corpus with some failures keeps its table."""
    broken = tmp_path / "zed_walk.c3d"
    broken.write_bytes(walk.read_bytes()[:1500])
    assert main(["batch", str(broken), "-o", str(tmp_path / "t.csv")]) == 2
    line = _one_error_line(capsys)
    assert line.startswith("mocap batch: error: ") and str(broken) in line
    assert not (tmp_path / "t.csv").exists()
    assert main(["batch", str(walk), str(broken)]) == 1


def test_an_output_suffix_must_agree_with_the_format_asked_for(walk, tmp_path, capsys):
    """One rule for every command: the suffix names the format, a flag asking for another is
    refused (``batch --json -o t.csv`` wrote JSON into t.csv, ``export --format bvh -o
    m.csv`` a BVH)."""
    import json
    assert main(["batch", str(walk), "--json", "-o", str(tmp_path / "t.csv")]) == 2
    line = _one_error_line(capsys)
    assert "--json" in line and ".json" in line and "t.csv" in line
    assert main(["batch", str(walk), "-o", str(tmp_path / "t.json")]) == 0
    assert json.loads((tmp_path / "t.json").read_text())[0]["status"] == "ok"
    capsys.readouterr()
    assert main(["batch", str(walk), "-o", str(tmp_path / "t.txt")]) == 2
    assert ".csv or .json" in _one_error_line(capsys)
    bvh = str(DATA / "mocapbank_walk.bvh")
    assert main(["export", bvh, "--format", "bvh", "-o", str(tmp_path / "m.csv")]) == 2
    assert "--format" in _one_error_line(capsys)
    assert main(["export", bvh, "--format", "mot", "-o", str(tmp_path / "m.sto")]) == 0
    assert not (tmp_path / "t.csv").exists() and not (tmp_path / "m.csv").exists()


def test_an_unloaded_plate_has_an_empty_centre_of_pressure_cell(tmp_path, capsys):
    """Like every CSV of the project (angles, markers), a value that does not exist is an
    empty cell, which Excel and pandas read as missing; it was the text 'nan'."""
    import csv as csv_module
    from tests.conftest import realdata_path
    trial = str(realdata_path("biomechzoo_sample_study/HC030A/Turn/HC030A22.c3d"))
    out = tmp_path / "grf.csv"
    assert main(["forces", trial, "-o", str(out), "--rate", "marker"]) == 0
    text = out.read_text()
    assert "nan" not in text.lower()
    rows = list(csv_module.DictReader(text.splitlines()))
    unloaded = [r for r in rows if abs(float(r["plate1_Fz_N"])) < 20]
    loaded = [r for r in rows if abs(float(r["plate1_Fz_N"])) > 100]
    assert unloaded and loaded
    assert all(r["plate1_COPx_m"] == "" for r in unloaded)
    assert all(-5 < float(r["plate1_COPx_m"]) < 5 for r in loaded)
