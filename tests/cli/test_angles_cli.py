"""``mocap angles`` end to end on real Plug-in Gait files: CSV, plot, cleaning
options, several inputs, and one-line errors with no partial output."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from mocap.io.angles_csv import read_angles_csv
from mocap.cli import build_parser, main
from mocap.io import read, write
from tests.conftest import realdata_path

WALK = ("biomechzoo_sample_study", "HC002D", "Straight", "HC002D06.c3d")
WALK2 = ("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_angles_csv_and_plot_of_real_walk(tmp_path, capsys):
    source = realdata_path(*WALK)
    out, png = tmp_path / "walk.csv", tmp_path / "walk.png"
    status, _, err = run(capsys, "angles", source, "--markerset", "plugingait-lower",
                         "--no-clinical", "--sequence", "YXZ", "-o", out, "--plot", png)
    assert status == 0, err
    header = out.read_text().splitlines()[0]
    assert header.startswith("time,pelvis.Y,pelvis.X,pelvis.Z,l_thigh.Y,")
    angles = read_angles_csv(out)
    assert angles.frames == 222 and angles.sequence == "YXZ"
    np.testing.assert_allclose(angles.times[:3], [0, 0.01, 0.02])
    knee = angles.segment("l_shank")[:, 0]
    assert 40 < np.nanmax(knee) < 80
    with Image.open(png) as image:
        assert image.format == "PNG" and image.size[0] > 600


def test_gaps_stay_empty_unless_filled_and_lowpass_smooths(tmp_path, capsys):
    trial = read(realdata_path(*WALK))
    # 1 mm of seeded marker noise (the file itself is already smooth), and gaps
    points = trial.points + np.random.default_rng(0).normal(0, 0.001, trial.points.shape)
    points[60:66, trial.labels.index("LKNE")] = np.nan      # 6 frames
    points[120:170, trial.labels.index("RTOE")] = np.nan    # 50 frames
    gappy = tmp_path / "gappy.c3d"
    write(trial.with_points(points), gappy)

    plain = tmp_path / "plain.csv"
    status, _, err = run(capsys, "angles", gappy, "-m", "plugingait-lower", "--no-clinical",
                         "-o", plain)
    assert status == 0, err
    lines = plain.read_text().splitlines()
    # l_thigh (LKNE) and its child l_shank are empty cells in frames 60-65
    row = lines[1 + 62].split(",")
    header = lines[0].split(",")
    assert row[header.index("l_thigh.Z")] == "" and row[header.index("l_shank.Y")] == ""
    assert row[header.index("r_foot.X")] != "" and row[header.index("pelvis.Z")] != ""
    angles = read_angles_csv(plain)
    assert np.isnan(angles.segment("l_thigh")[60:66]).all()
    assert np.isnan(angles.segment("r_foot")[120:170]).all()

    filled = tmp_path / "filled.csv"
    status, _, err = run(capsys, "angles", gappy, "-m", "plugingait-lower", "--no-clinical",
                         "-o", filled, "--fill-gaps", "0.1")
    assert status == 0
    # the 50-frame gap is longer than 0.1 s: reported, left empty
    assert "RTOE: frames 120-169 (longer than 10 frames)" in err
    angles = read_angles_csv(filled)
    assert np.isfinite(angles.segment("l_thigh")[60:66]).all()
    assert np.isnan(angles.segment("r_foot")[120:170]).all()

    smooth = tmp_path / "smooth.csv"
    status, _, err = run(capsys, "angles", gappy, "-m", "plugingait-lower", "--no-clinical",
                         "-o", smooth, "--fill-gaps", "0.1", "--lowpass", "6",
                         "--short-runs", "drop")
    assert status == 0, err
    raw, low = read_angles_csv(filled).segment("l_shank")[:, 0], \
        read_angles_csv(smooth).segment("l_shank")[:, 0]
    ok = np.isfinite(raw) & np.isfinite(low)
    roughness = [np.nanstd(np.diff(x[ok], 2)) for x in (raw, low)]
    assert roughness[1] < 0.3 * roughness[0]
    assert abs(np.nanmax(raw) - np.nanmax(low)) < 3       # the knee peak survives


def test_many_inputs_go_to_a_folder(tmp_path, capsys):
    folder = tmp_path / "angles"
    status, _, err = run(capsys, "angles", realdata_path(*WALK), realdata_path(*WALK2),
                         "-m", "plugingait-lower", "-o", folder, "--plot", tmp_path / "plots")
    assert status == 0, err
    assert sorted(p.name for p in folder.iterdir()) == ["HC002D06.csv", "HC030A05.csv"]
    assert sorted(p.name for p in (tmp_path / "plots").iterdir()) == \
        ["HC002D06.png", "HC030A05.png"]
    assert read_angles_csv(folder / "HC030A05.csv").frames == 197


@pytest.mark.parametrize("extra, problem", [
    (["-m", "synthetic15"], "HC002D06.c3d: marker set 'synthetic15' needs "),
    (["-m", "plugingait-lower", "--no-clinical", "--sequence", "ZZY"],
     "unknown Euler sequence 'ZZY'"),
    (["-m", "plugingait-lower", "--sequence", "ZXY"], "clinical angles use Plug-in Gait's YXZ"),
    (["-m", "plugingait-lower", "--static", "no-such-static.c3d"],
     "no-such-static.c3d: static trial not found"),
    (["-m", "synthetic15", "--static", "x.c3d"], "--static calibrates the clinical"),
    (["-m", "plugingait-lower", "--lowpass", "50"], "not below the Nyquist frequency 50 Hz"),
    (["-m", "no-such-set"], "no marker set preset 'no-such-set'"),
])
def test_errors_are_one_line_with_no_output(tmp_path, capsys, extra, problem):
    out = tmp_path / "out.csv"
    status, _, err = run(capsys, "angles", realdata_path(*WALK), *extra, "-o", out)
    assert status == 2
    assert problem in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_missing_input_and_bad_marker_set_file(tmp_path, capsys):
    status, _, err = run(capsys, "angles", tmp_path / "absent.c3d", "-m", "plugingait-lower",
                         "-o", tmp_path / "x.csv")
    assert status == 2 and "absent.c3d: file not found" in err
    broken = tmp_path / "set.toml"
    broken.write_text("[[segment]]\nname='a'\nmarkers=['A','B']\n")
    status, _, err = run(capsys, "angles", realdata_path(*WALK), "-m", broken,
                         "-o", tmp_path / "x.csv")
    assert status == 2 and f"{broken}: invalid marker set: segment 'a' has 2 markers" in err


def test_help_explains_every_option():
    parser = build_parser()
    commands = parser._subparsers._group_actions[0].choices
    assert "generate" in commands
    angles = commands["angles"]
    for action in angles._actions:
        assert action.help, action.dest
    text = angles.format_help()
    for option in ("--markerset", "--sequence", "--fill-gaps", "--lowpass", "--order",
                   "--short-runs", "--output", "--plot", "--clinical", "--static",
                   "--flat-foot", "--cycles", "--upper-body"):
        assert option in text


def test_a_non_csv_output_is_refused_and_success_is_said(tmp_path, capsys):
    """``-o angles.xlsx`` wrote CSV text into an .xlsx file; a success printed nothing."""
    from mocap.cli import main

    walk = realdata_path("biomechzoo_sample_study", "HC030A", "Straight", "HC030A05.c3d")
    target = tmp_path / "angles.xlsx"
    assert main(["angles", str(walk), "-m", "plugingait-lower", "-o", str(target)]) == 2
    err = capsys.readouterr().err
    assert "angles.xlsx: the angles are written as CSV" in err and not target.exists()
    good = tmp_path / "angles.csv"
    assert main(["angles", str(walk), "-m", "plugingait-lower", "-o", str(good)]) == 0
    assert f"wrote {good}" in capsys.readouterr().err and good.exists()
