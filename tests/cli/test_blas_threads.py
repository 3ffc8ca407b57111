"""The synthesis commands run with one BLAS thread unless the user chose a count."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from mocap.__main__ import BLAS_THREAD_VARIABLES, one_blas_thread


@pytest.mark.parametrize("command", ["decompose", "evaluate", "recognize", "synthesize"])
def test_synthesis_commands_get_one_thread_and_a_users_count_wins(command):
    environment = {"OMP_NUM_THREADS": "3"}
    one_blas_thread(["mocap", command, "--help"], environment)
    assert environment == {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "3",
                           "MKL_NUM_THREADS": "1"}


@pytest.mark.parametrize("argv", [["mocap"], ["mocap", "angles", "x.c3d"], ["mocap", "batch"],
                                  ["mocap", "--version"]])
def test_other_commands_keep_the_environment(argv):
    environment = {}
    one_blas_thread(argv, environment)
    assert environment == {}


def test_the_entry_point_sets_it_before_numpy_is_imported(tmp_path):
    # The real entry point in a fresh process: the variables are in place when the shell (and
    # numpy with it) starts, and the command still runs.
    script = ("import os, sys\n"
              "sys.argv = ['mocap', 'decompose', '--help']\n"
              "import mocap.__main__ as entry\n"
              "assert 'numpy' not in sys.modules\n"
              "try:\n"
              "    entry.run()\n"
              "except SystemExit as done:\n"
              "    print(done.code, *[os.environ.get(n) for n in entry.BLAS_THREAD_VARIABLES])\n")
    environment = {k: v for k, v in os.environ.items() if k not in BLAS_THREAD_VARIABLES}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          env=environment, cwd=tmp_path, timeout=120)
    assert done.stdout.split()[-4:] == ["0", "1", "1", "1"], done.stderr
