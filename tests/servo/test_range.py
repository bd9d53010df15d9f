"""Range-aware perception: the search range follows the marker's disparity, so a robot 0.4 m
from the camera (64 px at 320x240, 128 px at 640x480) is seen and servoed, and a run that never
sees the marker is not reported as held."""

from __future__ import annotations

import pytest

from host.servo.phase import Phase
from host.sim.faults import WorldFaults
from host.sim.run import Setup, simulation
from host.stereo import MatcherParams


@pytest.mark.parametrize("size", [(320, 240), (640, 480)])
def test_near_marker_is_measured_beyond_the_default_search_range(size) -> None:
    """At 0.4 m the marker's disparity is beyond num-disp 48 / 64; the cross-check searches
    around it and agrees with the marker's centres."""
    params = MatcherParams(block_size=9, num_disparities=48 * size[0] // 320, border="clip")
    with simulation(Setup(size, 0.4, params=params)) as sim:
        for _ in range(3):
            row = sim.servo.step(sim.world.robot.z_m)
        truth = sim.world.marker_truth()[2]
        assert truth > params.num_disparities
        assert row.robot_px == pytest.approx(truth, abs=0.3)
        assert row.block_px == pytest.approx(truth, abs=1.5)
        assert sim.servo.mismatches == 0


def test_robot_servoes_from_near_range() -> None:
    with simulation(Setup((320, 240), 0.45)) as sim:
        sim.run(20.0)
        assert sim.servo.outcome() == ("held", "")
        assert abs(sim.depth_error_m()) <= 0.02


def test_a_run_that_never_sees_the_marker_is_not_held() -> None:
    """It spins in place looking for its card, then stops with the reason."""
    with simulation(Setup((320, 240), 0.9, faults=WorldFaults())) as sim:
        sim.world.robot.marker_hidden = True
        sim.run(15.0)
        outcome, reason = sim.servo.outcome()
        assert outcome == "stopped" and "never seen" in reason
        assert sim.servo.stop_reason == "the marker was never seen"
        assert {r.phase for r in sim.servo.rows} <= {Phase.WAIT, Phase.FIND, Phase.STOP}
        assert abs(sim.world.robot.z_m - 0.9) < 0.01  # in place
        sim.run(sim.source.t + 0.5)
        assert sim.emulator.motors() == (0, 0)
