"""``mocap view``: time and size to write the page of a trial, and time to open it.

Prints, for

- a 10 s, 40-marker, 100 Hz trial (the generator's walk, first 40 markers, no segments),
- the same walk with all 45 markers and its synthetic15 segments, and its joint angles
  as curves (six columns),
- a real Plug-in Gait walk with force plates (../shared/realdata, when present),

the size of the HTML file (three.js r187 is 0.57 MB of it), the time of
:meth:`mocap.view.View.write` (reading excluded, best of 3), the time of the whole command
in a fresh interpreter (``python -m mocap view``: start-up, imports, reading, writing), and,
when chromium is installed, the time until the page has drawn its first frame from disk.
Never asserts; run ``python benchmarks/view.py``.
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mocap.io import write                                     # noqa: E402
from mocap.io.angles_csv import write_angles_csv               # noqa: E402
from mocap.markersets import load_markerset                    # noqa: E402
from mocap.pipeline import marker_file_angles                  # noqa: E402
from mocap.synthetic.corpus import synthesize_trial            # noqa: E402
from mocap.synthetic.people import cycle_seconds, make_people  # noqa: E402
from mocap.view import view_files                              # noqa: E402
from timing import best_of                                     # noqa: E402  benchmarks/timing.py

REALDATA = ROOT.parent / "shared" / "realdata"
PLATES = REALDATA / "biomechzoo_sample_study" / "HC030A" / "Turn" / "HC030A22.c3d"


def ten_second_walk(folder: Path) -> tuple[Path, Path]:
    """A generated 10 s walk at 100 Hz: all 45 markers, and the first 40 only."""
    person = make_people(1, 0)[0]
    cycles = 10.0 / cycle_seconds(person, "walk", 0)
    trial, _ = synthesize_trial(person, "walk", seed=0, cycles=cycles, rate=100.0)
    trial = trial.with_points(trial.points[:1000])
    full, forty = folder / "walk45.c3d", folder / "walk40.c3d"
    write(trial, full)
    write(type(trial)(trial.labels[:40], trial.points[:, :40], trial.rate), forty)
    return full, forty


def open_time(page: Path) -> float | None:
    """Seconds from navigation to the first drawn frame in headless chromium (None without)."""
    from tests.view.chromium import Chromium, file_url, find_chromium
    executable = find_chromium()
    if executable is None:
        return None
    with Chromium(executable) as browser:
        browser.open("about:blank")
        start = time.perf_counter()
        browser.open(file_url(page))
        browser.wait_for("window.mocapView && new Promise(r => requestAnimationFrame(() => r(true)))")
        return time.perf_counter() - start


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        full, forty = ten_second_walk(folder)
        angles = folder / "walk45_angles.csv"
        write_angles_csv(marker_file_angles(full, load_markerset("synthetic15")).angles, angles)
        cases = [("10 s, 40 markers, 100 Hz", [forty], ["--markerset", "none"], {"markerset": "none"}),
                 ("10 s, 45 markers + segments + 6 angle curves", [full],
                  ["--angles", str(angles)], {"angles": angles})]
        if PLATES.exists():
            cases.append((f"real C3D with plates ({PLATES.name})", [PLATES], [], {}))
        print(f"{'trial':48s} {'size MB':>8s} {'write s':>8s} {'command s':>10s} {'open s':>7s}")
        for name, files, flags, options in cases:
            view = view_files(files, **options)
            page = folder / "page.html"
            write_time = best_of(lambda: view.write(page))
            size = page.stat().st_size
            start = time.perf_counter()
            subprocess.run([sys.executable, "-m", "mocap", "view", *map(str, files), *flags,
                            "-o", str(folder / "cli.html")], check=True, cwd=ROOT,
                           capture_output=True)
            command = time.perf_counter() - start
            opened = open_time(page)
            print(f"{name:48s} {size / 1e6:8.2f} {write_time:8.3f} {command:10.2f} "
                  + (f"{opened:7.2f}" if opened is not None else "      -"))


if __name__ == "__main__":
    main()
