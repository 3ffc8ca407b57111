"""N-mode SVD speed and accuracy: our Gram-matrix HOSVD vs ``tensorly.decomposition.tucker``.

Decomposes people × actions × (angles · frames) tensors of the sizes a motion corpus reaches
(8×4×4500, 50×10×12000, 200×20×12000) with full people and action ranks and a truncated
feature rank — the model's configuration — by

* ``synthesis.nmode.nmode_svd``: each mode matrix from the eigen-decomposition of the smaller
  Gram matrix of its unfolding, only the leading eigenpairs when the rank is a count;
* ``tensorly.decomposition.tucker`` with its defaults (HOSVD initialisation + HOOI sweeps).

Data: ``X = S + E`` with ``S`` of exact multilinear rank (P, A, K) — smooth periodic
feature bases (4 harmonics) — and white noise ``‖E‖ = 0.01 ‖S‖``. Printed per case: median
wall time, relative reconstruction error ``‖X − X̂‖/‖X‖``, error against the clean tensor,
the difference between the two reconstructions, and the speed-up. One BLAS thread (set
before numpy is imported) so the comparison is not decided by thread scheduling on a shared
machine; each method runs once untimed first (memory first touch, caches). Never asserts.

    /tmp/venv/bin/python benchmarks/nmode.py [--cases a,b,c] [--repeats a=20,b=5,c=1]
"""
from __future__ import annotations

import os

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
import tensorly as tl  # noqa: E402
from tensorly.decomposition import tucker  # noqa: E402

from synthesis.nmode import nmode_svd, reconstruct, relative_error  # noqa: E402

#: name → (people, actions, angles, frames, feature rank)
CASES = {
    "a": (8, 4, 45, 100, 16),
    "b": (50, 10, 60, 200, 40),
    "c": (200, 20, 60, 200, 60),
}


def make_tensor(people: int, actions: int, angles: int, frames: int, rank: int,
                noise: float = 0.01, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``(X, S)``: noisy and clean people × actions × (frames·angles) tensors, float64."""
    rng = np.random.default_rng(seed)
    phase = np.arange(frames) / frames
    harmonics = np.arange(1, 5)
    # rank smooth periodic feature vectors (frames × angles each), orthonormalised.
    coefficients = rng.normal(size=(rank, angles, 2, len(harmonics))) / harmonics
    waves = (coefficients[..., 0, :, None] * np.cos(2 * np.pi * harmonics[:, None] * phase)
             + coefficients[..., 1, :, None] * np.sin(2 * np.pi * harmonics[:, None] * phase))
    features = np.moveaxis(waves.sum(axis=2), 1, 2).reshape(rank, frames * angles).T
    features, _ = np.linalg.qr(features)
    core = rng.normal(size=(people, actions, rank))
    people_factor, _ = np.linalg.qr(rng.normal(size=(people, people)))
    action_factor, _ = np.linalg.qr(rng.normal(size=(actions, actions)))
    clean = reconstruct(core, [people_factor, action_factor, features])
    error = rng.normal(size=clean.shape)
    noisy = clean + noise * np.linalg.norm(clean) / np.linalg.norm(error) * error
    return noisy, clean


#: label → (decompose(tensor, ranks), result → reconstructed tensor)
METHODS = {
    "Gram HOSVD (synthesis)": (lambda tensor, ranks: nmode_svd(tensor, ranks),
                               lambda result: result.reconstruct()),
    "tensorly tucker default": (lambda tensor, ranks: tucker(tensor, rank=ranks),
                                tl.tucker_to_tensor),
}


def time_decomposition(label: str, tensor: np.ndarray, ranks: list[int], repeats: int
                       ) -> tuple[float, float, np.ndarray]:
    """(median s, min s, reconstruction) over ``repeats`` timed runs after one untimed run.

    Only the decomposition is timed; the reconstruction for the error is made afterwards.
    """
    decompose, to_tensor = METHODS[label]
    decompose(tensor, ranks)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = decompose(tensor, ranks)
        times.append(time.perf_counter() - start)
    return float(np.median(times)), float(np.min(times)), to_tensor(result)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="a,b,c",
                        help="comma-separated cases to run: a (8×4×4500), b (50×10×12000), "
                             "c (200×20×12000)")
    parser.add_argument("--repeats", default="a=20,b=5,c=1",
                        help="timed runs per method and case, median reported (default "
                             "a=20,b=5,c=1: tensorly takes minutes on case c)")
    args = parser.parse_args()

    print(f"numpy {np.__version__}, tensorly {tl.__version__}, BLAS threads "
          f"{os.environ.get('OPENBLAS_NUM_THREADS')}; times in seconds (median of timed runs "
          "after one untimed run)")
    header = (f"{'case':<4} {'shape P×A×F':<18} {'ranks':<14} {'method':<26} {'median s':>9} "
              f"{'min s':>9} {'rel. err':>10} {'vs clean':>10}")
    print(header)
    print("-" * len(header))
    summary = []
    for name in args.cases.split(","):
        people, actions, angles, frames, rank = CASES[name.strip()]
        tensor, clean = make_tensor(people, actions, angles, frames, rank)
        ranks = [people, actions, rank]
        repeats = dict(item.split("=") for item in args.repeats.split(","))
        repeats = int(repeats.get(name.strip(), 1))
        shape = f"{people}×{actions}×{angles * frames}"
        results = {}
        for label in METHODS:
            median, fastest, approximation = time_decomposition(label, tensor, ranks, repeats)
            results[label] = (median, approximation)
            print(f"{name:<4} {shape:<18} {str(ranks):<14} {label:<26} {median:9.3f} "
                  f"{fastest:9.3f} {relative_error(tensor, approximation):10.6f} "
                  f"{relative_error(clean, approximation):10.6f}", flush=True)
        (our_time, our_fit), (their_time, their_fit) = results.values()
        summary.append((name, shape, their_time / our_time, relative_error(tensor, our_fit),
                        relative_error(tensor, their_fit), relative_error(their_fit, our_fit)))
        del tensor, clean, results, our_fit, their_fit
    print()
    print(f"{'case':<4} {'shape':<18} {'speed-up':>9} {'our err':>10} {'tensorly err':>13} "
          f"{'‖X̂ours − X̂tl‖/‖X̂tl‖':>22}")
    for name, shape, ratio, our_error, their_error, difference in summary:
        print(f"{name:<4} {shape:<18} {ratio:8.1f}× {our_error:10.6f} {their_error:13.6f} "
              f"{difference:22.1e}")
    print("target: at least 20× faster at equal or lower error")


if __name__ == "__main__":
    main()
