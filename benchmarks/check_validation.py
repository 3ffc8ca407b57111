"""The dynamics check on the real captures: design half vs report half (issue 21).

Prints, for the visible Vicon Plug-in Gait walks with force plates (stored body mass,
the default 6 Hz low-pass), split by alternate subjects (design: HC002D, HC031A, HC033A,
HC038A and vicon_zerowire; report: HC030A, HC032A, HC036A, HC039A and the CGM2.4
lower-body walk), per walk and per half: the verdict, residual force and torque RMS over
their trial limits, and the published ``ground_reaction`` against the raw plate totals
(vertical, ezc3d's plates as measured) on the frames where the plates carry the whole
body (r, RMS % BW); then the bandai2 corpus's plausible count by content. Figures, not
timings; never asserts.

    python benchmarks/check_validation.py [--no-bandai]
"""
from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from dynamics.humanoid.check import check_motion  # noqa: E402
from dynamics.humanoid.plates import carried_frames, measured_plates, plate_stances  # noqa: E402
from mocap.body.retarget import motion_from_trial, reduce_to_segments  # noqa: E402
from mocap.io import read  # noqa: E402
from mocap.io.motion import read_motion  # noqa: E402
from tests.conftest import REALDATA  # noqa: E402
from tests.dynamics.test_dynamics_plates import LOWER_WALK, WALKS, _mass  # noqa: E402


def walk_row(local: str, preset: str) -> tuple:
    trial = read(REALDATA / local)
    body = reduce_to_segments(motion_from_trial(trial, preset), partial=True)
    report = check_motion(body, _mass(trial))
    limits = report.limits
    raw = measured_plates(trial, floor=report.floor_m)
    carried = carried_frames(report, plate_stances(report, raw)[0])
    estimated = report.contact_forces.sum(axis=1)[carried, 1]
    measured = raw.force.sum(axis=0)[carried, 1]
    r = float(np.corrcoef(estimated, measured)[0, 1])
    rms = 100.0 * float(np.sqrt(np.mean((estimated - measured) ** 2))) / report.weight
    return (report.verdict == "plausible", limits["residual_force_rms_pct_bw"]["ratio"],
            limits["residual_torque_rms_Nm"]["ratio"], r, rms,
            report.reasons + [f"not judged: {x}" for x in report.not_judged])


def toe_bound(paths: list[Path]) -> None:
    """The toe-joint sole bound (SOLE_BELOW_LOWEST) on bandai2, design half (styles
    active, exhausted, masculine, youthful) vs report half (elderly, feminine, normal):
    the highest still toe joint in leg lengths and the takes whose feet stand above the
    bound (they would float), with the bound and with the 0.07 it replaced."""
    from dynamics.humanoid.soles import SOLE_BELOW_LOWEST, still_foot_height
    from mocap.body.anthropometry import leg_length

    design = {"active", "exhausted", "masculine", "youthful"}
    halves: dict[str, list] = {"design": [], "report": []}
    for path in paths:
        body = reduce_to_segments(read_motion(path), partial=True)
        world_r, world_p = body.forward_kinematics()
        leg = leg_length(body.skeleton)
        highest = max(still_foot_height(world_r[:, f], world_p[:, f],
                                        body.skeleton.end_sites[f], body.rate) / leg
                      for f in (body.skeleton.index(n) for n in body.metadata["feet_at_joints"]))
        halves["design" if path.stem.split("_")[2] in design else "report"].append(highest)
    bound = SOLE_BELOW_LOWEST["toe joint"]
    for half, rows in halves.items():
        rows = np.array(rows)
        print(f"bandai2 {half}: highest still toe joint {rows.max():.4f} leg lengths; above "
              f"the bound {bound}: {int((rows > bound).sum())}/{rows.size} takes (above 0.07: "
              f"{int((rows > 0.07).sum())})")


def main() -> None:
    subjects = sorted({w.split("/")[1] for w in WALKS if w.startswith("biomechzoo")})
    design = set(subjects[0::2]) | {"sample_32"}
    halves: dict[str, list] = {"design": [], "report": []}
    for local, preset in [(w, "plugingait-full") for w in WALKS] + [(LOWER_WALK,
                                                                    "plugingait-lower")]:
        half = "design" if local.split("/")[1] in design else "report"
        row = walk_row(local, preset)
        halves[half].append(row)
        print(f"{half:6s} {Path(local).name:40s} {'plausible' if row[0] else 'implausible':11s}"
              f" force/limit {row[1]:.2f} torque/limit {row[2]:.2f} GRF r {row[3]:.3f} "
              f"RMS {row[4]:.1f} % BW {row[5]}")
    for half, rows in halves.items():
        a = np.array([row[:5] for row in rows], float)
        print(f"{half}: plausible {int(a[:, 0].sum())}/{len(a)}; largest force/limit "
              f"{a[:, 1].max():.2f}, torque/limit {a[:, 2].max():.2f}; ground_reaction vs raw "
              f"plates median r {np.median(a[:, 3]):.3f}, RMS {np.median(a[:, 4]):.1f} % BW")
    if "--no-bandai" in sys.argv:
        return
    toe_bound(sorted((REALDATA / "bandai2").glob("*.bvh")))
    counts, verdicts = Counter(), Counter()
    for path in sorted((REALDATA / "bandai2").glob("*.bvh")):
        content = path.stem.split("_")[1]
        body = reduce_to_segments(read_motion(path), partial=True)
        counts[content] += 1
        verdicts[content, check_motion(body).verdict] += 1
    for verdict in ("plausible", "not judged", "implausible"):
        print(f"bandai2: {verdict} " + ", ".join(
            f"{k} {verdicts[k, verdict]}/{n}" for k, n in sorted(counts.items()))
            + f"; total {sum(v for (_, w), v in verdicts.items() if w == verdict)}"
              f"/{sum(counts.values())}")


if __name__ == "__main__":
    main()
