"""The dynamics check on real skeleton (BVH) captures: the Bandai Namco corpus, whose feet
end at joint centres (ankle, toe joint) with the soles below them."""
from __future__ import annotations

import numpy as np
import pytest

from dynamics.humanoid.check import check_motion
from dynamics.humanoid.contact import _runs, points_in_world
from dynamics.humanoid.soles import rig_soles
from dynamics.humanoid.kinematics import centre_of_mass
from dynamics.humanoid.model import build_humanoid
from dynamics.humanoid.tracking import simulate_tracking
from mocap.body.retarget import reduce_to_segments
from mocap.io.motion import read_motion
from mocap.skeleton import Motion
from tests.conftest import realdata_path

STYLES = ("active", "elderly", "exhausted", "feminine", "masculine", "normal", "youthful")


def _body(content: str, style: str, take: int = 1) -> Motion:
    path = realdata_path(f"bandai2/dataset-2_{content}_{style}_{take:03d}.bvh")
    return reduce_to_segments(read_motion(path), partial=True)


@pytest.fixture(scope="module")
def walk():
    body = _body("walk", "normal")
    return body, check_motion(body)


def test_rig_soles_lie_below_the_joints_on_the_floor(walk):
    """Bandai's ankle joint stands 117 mm and its toe joint 42 mm above y = 0 (shod feet):
    the soles are found on the floor there, where the trial's still feet stand (the
    calibration to the stances then moves them by under 3 mm), not at the joints (which
    floated 60 mm above it)."""
    body, report = walk
    assert body.metadata["feet_at_joints"] == {"l_foot": "toe joint", "r_foot": "toe joint"}
    calibration = report.calibration
    assert calibration.levels == [0.0]
    for shift in calibration.shift_mm.values():
        assert abs(shift) < 3.0
    heights = report.contact_positions[..., 1] - calibration.floors
    assert abs(np.median(heights[report.contact_active])) < 0.003
    # The sole plane lies ~117 mm below the ankle joint (the stance ankle height).
    world_r, world_p = body.forward_kinematics()
    ankle = world_p[:, body.skeleton.index("l_foot"), 1]
    still = np.linalg.norm(np.gradient(world_p[:, body.skeleton.index("l_foot")], axis=0)
                           * body.rate, axis=1) < 0.1
    foot = [k for k, s in enumerate(report.contact_segments)
            if s == body.skeleton.index("l_foot")]
    lowest = (report.contact_positions[:, foot, 1]).min(axis=1)
    np.testing.assert_allclose(np.median((ankle - lowest)[still]), np.median(ankle[still]),
                               atol=0.005)
    assert not any(r.startswith("floating") for r in report.reasons)


def test_standing_captures_are_plausible():
    """Waving and raising both hands (standing still on both feet) in every style."""
    verdicts = [check_motion(_body(content, style)).verdict
                for content in ("wave-both-hands", "raise-up-both-hands") for style in STYLES]
    assert verdicts == ["plausible"] * len(verdicts)


def test_faults_on_a_real_rig_are_flagged(walk):
    body, _ = walk

    def moved(dy: float = 0.0, glide: float = 0.0) -> list[str]:
        root = body.root_translation + [0.0, dy, 0.0]
        root[:, 0] += glide * body.times
        return check_motion(Motion(body.skeleton, root, body.rotations, body.rate,
                                   dict(body.metadata))).reasons

    assert any(r.startswith("floating") for r in moved(dy=0.30))      # held up 30 cm
    assert any(r.startswith("floating") for r in moved(dy=0.05))      # 5 cm up
    # Sunk 8 cm: the toe joints stand 38 mm below the floor. Sunk 5 cm they stand 8 mm
    # below it, which a rig whose joints are its soles (a game export) shows standing
    # 8 mm deep: the check reports what the rig's points show and invents no sole
    # below them, so it cannot tell a shod rig sunk by less than its toe joint's 42 mm.
    assert any(r.startswith("penetrates") for r in moved(dy=-0.08))   # sunk 8 cm
    assert any("skate" in r for r in moved(glide=0.5))                 # sliding 0.5 m/s


def test_walks_and_turns_are_plausible():
    """One take of every style walking straight and turning, with the 6 Hz low-pass of
    ``mocap check``: at least 90 % plausible, residual median below 5 % of body weight
    (the real Plug-in Gait walks checked against force plates: median 0.9, up to 6.8)."""
    reports = [check_motion(_body(content, style), lowpass=6.0)
               for content in ("walk", "walk-turn-left", "walk-turn-right") for style in STYLES]
    plausible = [r.verdict == "plausible" for r in reports]
    assert np.mean(plausible) >= 0.9
    assert np.median([r.summary()["residual_force_rms_pct_bw"] for r in reports]) < 5.0


def test_check_command_filters_a_bvh_capture(capsys):
    import json

    from mocap.cli import main

    path = str(realdata_path("bandai2/dataset-2_walk_normal_001.bvh"))
    assert main(["check", path, "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["lowpass_hz"] == 6.0 and result["verdict"] == "plausible"
    assert main(["check", path, "--json", "--lowpass", "0"]) == 0
    assert json.loads(capsys.readouterr().out)["lowpass_hz"] is None


def test_running_flights_are_ballistic_not_floating():
    """Real runs leave the floor for 4-7 frames at 30 Hz; the captured centre of mass falls
    at g then (a parabola through each flight: within 0.25 g), so the flights are free
    falls, not floating, though the 6 Hz low-pass spreads the landings into them."""
    for style in ("normal", "masculine", "youthful", "active"):
        body = _body("run", style)
        report = check_motion(body, lowpass=6.0)
        airborne = ~report.contact_active.any(axis=1)
        assert airborne.mean() > 0.15, style
        assert not any(r.startswith("floating") for r in report.reasons), style
        world_r, world_p = body.forward_kinematics()
        com = centre_of_mass(build_humanoid(body.skeleton), world_r, world_p)
        falls = [2.0 * np.polyfit(np.arange(b - a) / body.rate, com[a:b, 1], 2)[0]
                 for a, b in _runs(airborne, 4)]
        assert len(falls) >= 2 and np.all(np.abs(np.array(falls) + 9.81) < 0.25 * 9.81), style


def test_a_still_foot_on_its_toes_is_not_a_step():
    """The 'active' turns hold a foot still on its toes, heel up (ankle 4-7 cm above its
    flat stances): one floor, no step up, plausible."""
    report = check_motion(_body("walk-turn-left", "active", 2), lowpass=6.0)
    assert report.calibration.levels == [0.0]
    assert report.verdict == "plausible"


def test_physics_replay_stands_a_rig_on_the_check_soles():
    """The physics replay stands a rig on the soles the check finds below its foot joints:
    on the first 2 s of a real Bandai walk the replayed root keeps the captured height and
    the soles carry the body at the floor. Standing on the joints (ankle 117 mm, toe joint
    42 mm up), the body sank until the joints touched it: root 48 mm low, soles 43 mm deep
    (now 10 mm and 5 mm: the captured soles stand 5 mm up, the springs give 4 mm)."""
    motion = read_motion(realdata_path("bandai2/dataset-2_walk_normal_001.bvh")).slice(0, 60)
    body = reduce_to_segments(motion, partial=True)
    humanoid = build_humanoid(body.skeleton)
    soles, *_ = rig_soles(body, humanoid)
    assert not np.allclose(soles, humanoid.contact_points)
    moved = humanoid.with_contact_points(soles)
    assert np.allclose(moved.contact_points, soles)
    assert not np.allclose(humanoid.contact_points, soles)        # the original unchanged
    result = simulate_tracking(motion)
    sunk = body.root_translation[:, 1] - result.motion.root_translation[:, 1]
    assert abs(np.median(sunk)) < 0.015
    world_r, world_p = result.motion.forward_kinematics()
    lowest = points_in_world(soles, humanoid.contact_segments, world_r, world_p)[..., 1]
    # the replayed feet touch the floor through the penalty springs (a few mm deep)
    assert -0.012 < np.median(lowest.min(axis=1)) < 0.005
