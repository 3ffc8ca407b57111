"""Gap-filling accuracy on real Plug-in Gait walks (issue 12): a measurement, never asserts.

Every Plug-in Gait walk in ../shared/realdata with Vicon's angles and a static of the
same subject (the walks of tests/mocap/plugingait/test_clinical.py) has each model marker
blanked for ``--gap`` frames at each ``--at`` fraction of the trial, filled with
:func:`mocap.plugingait.clinical.fill_plugingait`, and its clinical angles compared with those of
the recorded data.  Prints, per marker, the median, 90th percentile and worst over walks
and positions of the worst joint-plane RMS inside the gap (degrees), the count over 1
degree, and whether any angle outside a gap changed (it must not).  ``--plain`` measures
the fill without the regression (the marker's coordinates about its two points
interpolated alone) and with the spline rehearsal.  ``--lowpass HZ`` prints a second
table, of the same gaps after the low-pass a gait lab applies before the model
(:func:`mocap.clean.filtering.lowpass`, order 4, after filling, to the recorded trial and to
the filled one alike); the raw table is still printed first.

    PYTHONPATH=$PWD python benchmarks/gapfill.py [--gap 20] [--at 0.3,0.5,0.7] [--plain]
                                                 [--lowpass 6]
"""
from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import mocap.clean.gapfill
from mocap.plugingait.clinical import fill_plugingait, plugingait_angles, plugingait_labels, prepare_subject
from mocap.clean.filtering import lowpass
from mocap.io import read
from mocap.trial import Trial
from tests.conftest import REALDATA
from tests.mocap.plugingait.test_clinical import plugingait_pairs


def model_markers(trial: Trial) -> Trial:
    used = plugingait_labels(trial)
    columns = [trial.labels.index(label) for label in used]
    return Trial(used, trial.points[:, columns], trial.rate, trial.units, trial.path,
                 trial.format, metadata=dict(trial.metadata))


def _worst_rms(angles: np.ndarray, truth: np.ndarray, inside: slice, gap: int) -> float:
    difference = (angles[inside] - truth[inside]).reshape(gap, -1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return float(np.nan_to_num(np.sqrt(np.nanmean(difference ** 2, axis=0))).max())


def measure(gap: int, at: tuple[float, ...], cutoff: float | None = None
            ) -> tuple[dict, int, dict]:
    """{marker: [worst joint-plane RMS inside each gap]}, the number of leaks, and the
    same as the first after a ``cutoff`` Hz low-pass of both trials (empty without)."""
    worst: dict[str, list[float]] = {}
    filtered: dict[str, list[float]] = {}
    leaks = 0
    for walk, static in plugingait_pairs(REALDATA):
        trial = model_markers(read(walk))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            subject = prepare_subject(trial, static=read(static), flat_foot="auto")
            truth = plugingait_angles(trial, subject=subject).values
            if cutoff is not None:
                smooth_truth = plugingait_angles(lowpass(trial, cutoff, short_runs="keep"),
                                                 subject=subject).values
        for fraction in at:
            start = int(trial.frames * fraction) - gap // 2
            inside = slice(start, start + gap)
            outside = np.r_[0:start, start + gap:trial.frames]
            for m, label in enumerate(trial.labels):
                if not np.isfinite(trial.points[start - 1:start + gap + 1, m]).all():
                    continue
                points = trial.points.copy()
                points[inside, m] = np.nan
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    filled, _ = fill_plugingait(trial.with_points(points), subject, gap)
                    angles = plugingait_angles(filled, subject=subject).values
                leaks += not np.array_equal(angles[outside], truth[outside], equal_nan=True)
                name = label.rpartition(":")[2]
                worst.setdefault(name, []).append(_worst_rms(angles, truth, inside, gap))
                if cutoff is not None:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        smooth = plugingait_angles(lowpass(filled, cutoff, short_runs="keep"),
                                                   subject=subject).values
                    filtered.setdefault(name, []).append(
                        _worst_rms(smooth, smooth_truth, inside, gap))
    return worst, leaks, filtered


def table(worst: dict) -> None:
    """Per marker: gaps, median, 90th percentile, worst and count over 1 degree."""
    print("marker  gaps  median   p90  worst  >1deg")
    for label in sorted(worst, key=lambda n: (n[1:], n[0])):
        v = np.array(worst[label])
        print(f"{label:6s} {len(v):5d} {np.median(v):7.2f} {np.percentile(v, 90):5.2f} "
              f"{v.max():6.2f} {int((v > 1).sum()):6d}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gap", type=int, default=20)
    parser.add_argument("--at", default="0.3,0.5,0.7")
    parser.add_argument("--plain", action="store_true")
    parser.add_argument("--lowpass", type=float, default=None, metavar="HZ")
    args = parser.parse_args()
    if args.plain:             # fill_plugingait looks fill_gaps up in mocap.clean.gapfill when called
        fill = mocap.clean.gapfill.fill_gaps

        def plain(*a, **k):
            k.update(correlate=False, rehearse=True)
            return fill(*a, **k)
        mocap.clean.gapfill.fill_gaps = plain
    t0 = time.perf_counter()
    worst, leaks, filtered = measure(args.gap, tuple(float(a) for a in args.at.split(",")),
                                     args.lowpass)
    every = np.concatenate([np.array(v) for v in worst.values()])
    print(f"{len(every)} gaps of {args.gap} frames: median {np.median(every):.2f}, worst "
          f"{every.max():.2f} degrees, {int((every > 1).sum())} over 1 degree, "
          f"{leaks} changed an angle outside the gap ({time.perf_counter() - t0:.0f} s)")
    table(worst)
    if filtered:
        every = np.concatenate([np.array(v) for v in filtered.values()])
        print(f"after a {args.lowpass:g} Hz low-pass of both trials: median "
              f"{np.median(every):.2f}, worst {every.max():.2f} degrees, "
              f"{int((every > 1).sum())} over 1 degree")
        table(filtered)


if __name__ == "__main__":
    main()
