"""Humanoid throughput: inverse dynamics, contact solve, whole check, cloth, physics.

Prints, for the 15-segment body (free flyer + 14 spherical joints, nq 63, nv 48):

* RNEA frames per second through ``pin.rneaInParallel`` on a whole batch (1 and 2
  threads), beside a plain per-frame Python loop calling ``pin.rnea`` with row slicing;
* manifold kinematics (q, v, a for every frame, vectorised) frames per second;
* the friction-pyramid contact solve (one NNLS per frame with contact) frames per second;
* the whole ``check_motion`` frames per second;
* secondary cloth (cape 9 × 14 + rope 10, implicit Euler, 4 substeps a frame) frames/s;
* physical animation (computed torques + ABA at 1 kHz) frames per second of a 100 Hz motion;
* on a real trial (``--trial``, default the 556-frame Vicon Plug-in Gait walk HC030A22 of
  the corpus, full-body marker set): ``check_motion`` in process beside a plain Pinocchio
  reference (per-frame ``pin.rnea`` for the same q, v, a, no contacts), and the whole
  ``mocap check`` process beside ``python -c "import pinocchio"`` + the C3D read, and that
  floor plus ``import scipy.spatial.transform`` (what scipy's Rotation costs to import).

Timings are noisy on a shared machine: compare ratios in the same run. Never asserts.

    python benchmarks/humanoid.py [--frames 20000] [--trial PATH.c3d] [--real-only]
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from scipy.spatial.transform import Rotation
from timing import best_of   # benchmarks/timing.py


def _walkish(frames: int, rate: float = 100.0):
    from mocap.body.segments import default_skeleton
    from mocap.skeleton import Motion

    skeleton = default_skeleton(1.75)
    t = np.arange(frames) / rate
    rng = np.random.default_rng(0)
    amplitude = rng.uniform(0.05, 0.4, (15, 3))
    frequency = rng.uniform(0.5, 2.0, (15, 3))
    rotvec = amplitude * np.sin(2 * np.pi * frequency * t[:, None, None])
    rotations = Rotation.from_rotvec(rotvec.reshape(-1, 3)).as_matrix().reshape(frames, 15, 3, 3)
    root = np.stack([np.zeros(frames), 0.02 * np.sin(2 * np.pi * t), 1.2 * t], axis=1)
    return Motion(skeleton, root, rotations, rate)


def _scipy_contact_reference(wrench: np.ndarray, levers: np.ndarray) -> np.ndarray:
    """The plain way: build each frame's matrix in Python and call scipy's NNLS on the
    ridge-augmented problem (the same objective as the batched solver)."""
    from scipy.optimize import nnls

    from dynamics.humanoid.contact_forces import pyramid_edges

    edges = pyramid_edges(0.8)
    out = []
    for f in range(wrench.shape[0]):        # the reference loops over frames on purpose
        columns = [np.concatenate([d, np.cross(r, d)]) for r in levers[f] for d in edges]
        matrix = np.array(columns).T
        ridge = 1e-3 * np.eye(matrix.shape[1])
        out.append(nnls(np.vstack([matrix, ridge]),
                        np.concatenate([wrench[f], np.zeros(matrix.shape[1])]))[0])
    return np.array(out)


def main() -> None:
    import pinocchio as pin

    from dynamics.humanoid.check import check_motion
    from dynamics.humanoid.contact_forces import solve_contact_forces
    from dynamics.humanoid.inverse import rnea_batch
    from dynamics.humanoid.kinematics import motion_kinematics
    from dynamics.humanoid.model import build_humanoid
    from dynamics.secondary import simulate_secondary
    from dynamics.humanoid.tracking import simulate_tracking

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--frames", type=int, default=20000, help="frames of the batch")
    parser.add_argument("--reference-frames", type=int, default=2000,
                        help="frames of the per-frame Python reference")
    parser.add_argument("--trial", help="real C3D trial with Plug-in Gait markers (default: "
                        "biomechzoo HC030A22 of ../shared/realdata)")
    parser.add_argument("--real-only", action="store_true",
                        help="only the real trial's timings (issue 13's two targets)")
    args = parser.parse_args()
    real_trial(args.trial)
    if args.real_only:
        return

    motion = _walkish(args.frames)
    body = build_humanoid(motion.skeleton, 75.0)
    print(f"model: nq {body.nq}, nv {body.nv}, {len(body.skeleton.names)} segments, "
          f"{len(body.contact_names)} contact points; pinocchio {pin.__version__}")

    kin_time = best_of(lambda: motion_kinematics(motion))
    kin = motion_kinematics(motion)
    print(f"kinematics (q, v, a on the manifold): {args.frames / kin_time:12,.0f} frames/s")

    rnea_batch(body, kin.q[:10], kin.v[:10], kin.a[:10])          # warm the model pool
    batch1 = best_of(lambda: rnea_batch(body, kin.q, kin.v, kin.a, threads=1))
    batch2 = best_of(lambda: rnea_batch(body, kin.q, kin.v, kin.a, threads=2))
    data = body.model.createData()
    n = min(args.reference_frames, args.frames)

    def loop():
        out = np.empty((n, body.nv))
        for k in range(n):          # the plain reference: one call per frame
            out[k] = pin.rnea(body.model, data, kin.q[k], kin.v[k], kin.a[k])
        return out

    reference = best_of(loop)
    fps_loop = n / reference
    print(f"RNEA rneaInParallel, 1 thread:        {args.frames / batch1:12,.0f} frames/s "
          f"({batch1 / args.frames * 1e6:.2f} µs/frame, {args.frames / batch1 / fps_loop:.1f}× "
          "the loop)")
    print(f"RNEA rneaInParallel, 2 threads:       {args.frames / batch2:12,.0f} frames/s "
          f"({args.frames / batch2 / fps_loop:.1f}× the loop)")
    print(f"RNEA per-frame Python loop:           {fps_loop:12,.0f} frames/s "
          f"({reference / n * 1e6:.2f} µs/frame)")

    # Contact solve on a standing-like load: both feet down, weight plus a sway.
    frames = min(args.frames, 5000)
    rng = np.random.default_rng(1)
    levers = np.broadcast_to(np.concatenate([body.contact_points + [0.09, -0.9, 0.0],
                                             body.contact_points - [0.09, 0.9, 0.0]])[:12],
                             (frames, 12, 3)).copy()
    wrench = np.zeros((frames, 6))
    wrench[:, 1] = 736.0
    wrench[:, [0, 2]] = rng.normal(scale=40.0, size=(frames, 2))
    wrench[:, 3:] = rng.normal(scale=10.0, size=(frames, 3))
    active = np.ones((frames, 12), bool)
    solve_contact_forces(wrench[:2], levers[:2], active[:2])
    solve = best_of(lambda: solve_contact_forces(wrench, levers, active), repeats=2)
    print(f"contact solve (batched ridge + Newton NNLS, 12 points × 4 edges): "
          f"{frames / solve:8,.0f} frames/s ({solve / frames * 1e6:.1f} µs/frame)")
    few = min(frames, 500)
    reference = best_of(lambda: _scipy_contact_reference(wrench[:few], levers[:few]), repeats=1)
    print(f"contact solve, per-frame scipy.optimize.nnls reference: {few / reference:8,.0f} "
          f"frames/s ({reference / few * 1e6:.1f} µs/frame; batched is "
          f"{reference / few / (solve / frames):.1f}× faster)")

    check_frames = min(args.frames, 2000)
    small = motion.slice(0, check_frames)
    check = best_of(lambda: check_motion(small, humanoid=body), repeats=2)
    print(f"whole check (kinematics, RNEA, contacts, report): {check_frames / check:8,.0f} "
          "frames/s")

    cloth_frames = 100
    cloth = best_of(lambda: simulate_secondary(motion.slice(0, cloth_frames), cape=True,
                                               rope=True, settle=0.0), repeats=2)
    print(f"secondary cloth (126-particle cape + 10-particle rope, implicit Euler, 4 "
          f"substeps): {cloth_frames / cloth:8,.1f} frames/s")

    physics_frames = 50
    physics = best_of(lambda: simulate_tracking(motion.slice(0, physics_frames),
                                                humanoid=body), repeats=1)
    print(f"physical animation (1 kHz ABA, 100 Hz motion): {physics_frames / physics:8,.1f} "
          "frames/s")


def real_trial(path: str | None) -> None:
    """In-process and whole-process timings of the check on a real trial."""
    import subprocess
    import sys
    from pathlib import Path

    import pinocchio as pin

    from dynamics.humanoid.check import check_motion
    from dynamics.humanoid.kinematics import motion_kinematics
    from dynamics.humanoid.model import build_humanoid
    from mocap.body.retarget import motion_from_trial, reduce_to_segments
    from mocap.io import read

    here = Path(__file__).resolve().parents[1]
    path = path or str(here.parent / "shared" / "realdata" / "biomechzoo_sample_study" /
                       "HC030A" / "Turn" / "HC030A22.c3d")
    if not Path(path).exists():
        print(f"real trial not found ({path}): skipped")
        return
    trial = read(path)
    body = reduce_to_segments(motion_from_trial(trial, "plugingait-full"), partial=True)
    humanoid = build_humanoid(body.skeleton, 60.0)
    check_motion(body, 60.0, humanoid=humanoid, lowpass=6.0)
    check = best_of(lambda: check_motion(body, 60.0, humanoid=humanoid, lowpass=6.0), 5)
    cpu = []
    for _ in range(15):          # CPU time of this thread: what other load does not change
        start = time.thread_time()
        check_motion(body, 60.0, humanoid=humanoid, lowpass=6.0)
        cpu.append(time.thread_time() - start)
    cpu = statistics.median(cpu)
    kin = motion_kinematics(body, 0.1, 6.0)
    data = humanoid.model.createData()

    def plain():
        for k in range(body.frames):        # the plain Pinocchio reference, frame by frame
            pin.rnea(humanoid.model, data, kin.q[k], kin.v[k], kin.a[k])

    reference = best_of(plain, 5)
    print(f"real trial {Path(path).name}: {body.frames} frames")
    print(f"  check_motion in process:            {body.frames / check:10,.0f} frames/s "
          f"({check * 1000:.1f} ms, best wall of 5); by CPU time {body.frames / cpu:,.0f} "
          f"frames/s ({cpu * 1000:.1f} ms, median of 15)")
    print(f"  plain Pinocchio rnea loop (no contacts, same q v a): "
          f"{body.frames / reference:10,.0f} frames/s ({reference * 1000:.1f} ms)")
    env = {"PYTHONPATH": str(here), "MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"}

    def run(argv: list[str]) -> tuple[float, float]:
        """Wall and CPU (user + system) seconds of one fresh process."""
        import os

        start = time.perf_counter()
        child = subprocess.Popen(argv, env=env, stdout=subprocess.DEVNULL)
        _, status, usage = os.wait4(child.pid, 0)
        if status:
            raise subprocess.CalledProcessError(status, argv)
        return time.perf_counter() - start, usage.ru_utime + usage.ru_stime

    def median(argv: list[str]) -> tuple[float, float]:
        """Median wall and median CPU seconds of 5 fresh processes."""
        runs = [run(argv) for _ in range(5)]
        return statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)

    read_it = f"from mocap.io import read; read({path!r})"
    whole = median([sys.executable, "-m", "mocap", "check", path, "-m", "plugingait-full"])
    floor = median([sys.executable, "-c", f"import pinocchio; {read_it}"])
    ezc3d = median([sys.executable, "-c", f"import pinocchio, ezc3d; ezc3d.c3d({path!r})"])
    rotation = median([sys.executable, "-c",
                       f"import pinocchio; import scipy.spatial.transform; {read_it}"])
    print("  fresh processes, medians of 5 (wall; CPU = user + system):")
    print(f"  whole process `mocap check`:        {whole[0]:6.2f} s (CPU {whole[1]:.2f} s)")
    print(f"  `import pinocchio` + C3D read:      {floor[0]:6.2f} s (CPU {floor[1]:.2f} s; "
          f"check is {whole[0] / floor[0]:.2f}× that, CPU {whole[1] / floor[1]:.2f}×)")
    print(f"  `import pinocchio` + ezc3d read:    {ezc3d[0]:6.2f} s (CPU {ezc3d[1]:.2f} s; "
          f"check is {whole[0] / ezc3d[0]:.2f}× that, CPU {whole[1] / ezc3d[1]:.2f}×)")
    print(f"  the same + scipy.spatial.transform: {rotation[0]:6.2f} s (CPU {rotation[1]:.2f} s"
          f"; {rotation[0] / floor[0]:.1f}× the floor: the import of scipy's Rotation alone)")
    import os
    print(f"  load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
