"""The tutorial's commands print what the tutorial says they print.

Every ``$ command`` of a ``console`` block in ``docs/tutorial.md`` runs, in order, in a
fresh folder beside ``../shared`` (as the page assumes), through a ``mocap`` on the PATH;
its output (standard error, then standard output) must match the lines the page shows
below it, with every number masked (numbers move with the data; words, units, labels,
file names and the order of lines may not). A line ``…`` stands for any number of lines,
and ``…`` inside a line for any text. Skipped: the demo (tests/cli/test_demo.py runs it),
the evaluation of the whole bandai2 corpus (tests/synthesis/test_bandai2.py) and a batch
on a Dask cluster that is not there.
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

from tests.conftest import realdata_path

ROOT = Path(__file__).resolve().parents[1]
TUTORIAL = ROOT / "docs" / "tutorial.md"
SKIPPED = ("mocap demo", "--manifest ../shared/realdata/bandai2", "--dask", "--scheduler")
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def console_steps(text: str) -> list[tuple[str, list[str]]]:
    """(command, the lines shown after it) for every ``$`` line of the console blocks."""
    steps = []
    for block in re.findall(r"^```console\n(.*?)^```", text, flags=re.S | re.M):
        lines = block.splitlines()
        k = 0
        while k < len(lines):
            if not lines[k].startswith("$ "):
                k += 1
                continue
            command = lines[k][2:]
            while command.endswith("\\"):
                k += 1
                command = command[:-1].rstrip() + " " + lines[k].strip()
            k += 1
            shown = []
            while k < len(lines) and not lines[k].startswith("$ "):
                shown.append(lines[k])
                k += 1
            steps.append((command, shown))
    return steps


def _pattern(line: str) -> re.Pattern:
    """A shown line as a pattern: numbers masked, ``…`` inside a line matching anything."""
    parts = [re.escape(NUMBER.sub("#", part)) for part in line.rstrip().split("…")]
    return re.compile(".*".join(parts))


def mismatch(shown: list[str], printed: list[str]) -> str | None:
    """Why ``printed`` does not read as ``shown``; None when it does."""
    printed = [NUMBER.sub("#", line.rstrip()) for line in printed if line.strip()]
    shown = [line for line in shown if line.strip()]

    def match(i: int, j: int) -> bool:                    # shown[i:] against printed[j:]
        if i == len(shown):
            return j == len(printed)
        if shown[i].strip() == "…":
            return any(match(i + 1, k) for k in range(j, len(printed) + 1))
        return j < len(printed) and _pattern(shown[i]).fullmatch(printed[j]) is not None \
            and match(i + 1, j + 1)

    if match(0, 0):
        return None
    return "shown:\n  " + "\n  ".join(shown) + "\nprinted (numbers masked):\n  " + \
        "\n  ".join(printed)


def test_the_matching_masks_numbers_and_honours_ellipses():
    assert mismatch(["wrote a.csv (110 frames)"], ["wrote a.csv (97 frames)"]) is None
    assert mismatch(["wrote a.csv (110 frames)"], ["wrote a.csv (97 rows)"]) is not None
    assert mismatch(["head", "…", "tail 1"], ["head", "x", "y", "tail 2"]) is None
    assert mismatch(["…/scenes/a.toml: 3 steps"], ["/x/y/scenes/a.toml: 4 steps"]) is None
    assert mismatch(["a", "b"], ["a"]) is not None


def test_every_tutorial_command_prints_what_the_tutorial_shows(tmp_path):
    shared = realdata_path().parent
    work = tmp_path / "work"
    work.mkdir()
    (tmp_path / "shared").symlink_to(shared, target_is_directory=True)
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (bin_dir / "mocap").write_text(f'#!/bin/sh\nexec "{sys.executable}" -m mocap "$@"\n')
    (bin_dir / "mocap").chmod(0o755)
    env = {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}",
           "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    steps = console_steps(TUTORIAL.read_text(encoding="utf-8"))
    assert len(steps) >= 20
    problems = []
    for command, shown in steps:
        if any(word in command for word in SKIPPED):
            continue
        done = subprocess.run(["bash", "-c", command], cwd=work, env=env,
                              capture_output=True, text=True, timeout=600)
        printed = done.stderr.splitlines() + done.stdout.splitlines()
        expected_error = any(re.match(r"mocap \w+: error: ", line) for line in shown)
        if (done.returncode != 0) != expected_error:
            problems.append(f"$ {command}\nexit {done.returncode}:\n{done.stderr[-2000:]}")
            continue
        why = mismatch(shown, printed)
        if why:
            problems.append(f"$ {command}\n{why}")
    assert not problems, "\n\n".join(problems)
