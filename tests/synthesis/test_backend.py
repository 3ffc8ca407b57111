"""Importing and using synthesis leaves the user's tensorly backend alone."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

# A fresh interpreter, so the imports really happen after the user chose a backend: the
# user's backend is tensorly's numpy backend registered under another name (the only backend
# installed here), so any tl.set_backend by synthesis shows as a changed name.
SCRIPT = """
import numpy as np
import tensorly as tl
from tensorly.backend.numpy_backend import NumpyBackend

class UserBackend(NumpyBackend, backend_name="user_choice"):
    pass

tl.set_backend(UserBackend())
import synthesis
from synthesis import MotionModel, leave_one_out, nmode_svd
import synthesis.corpus, synthesis.cycles, synthesis.evaluate, synthesis.regression
import synthesis.signature
assert tl.get_backend() == "user_choice", ("after import", tl.get_backend())

from tests.synthesis.test_model import multilinear_corpus
corpus = multilinear_corpus(people=4, actions=("run", "walk"), samples=20)
result = nmode_svd(np.random.default_rng(0).normal(size=(4, 3, 50)))
assert isinstance(result.core, np.ndarray)
model = MotionModel().fit(corpus)
curve, seconds = model.synthesize("p0", "run")
assert isinstance(curve, np.ndarray) and curve.shape == (20, corpus.angles.shape[-1])
leave_one_out(corpus)
assert tl.get_backend() == "user_choice", ("after use", tl.get_backend())
print("backend kept")
"""


def test_user_tensorly_backend_survives_importing_and_using_synthesis():
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
    completed = subprocess.run([sys.executable, "-c", SCRIPT], cwd=ROOT, env=env,
                               capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stderr[-2000:]
    assert completed.stdout.strip().endswith("backend kept")
