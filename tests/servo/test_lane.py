"""The lane ahead watched every frame: a box put down 29 cm ahead of the driving robot stops it
short of the box, at 320x240 and at 640x480 (where the lane is matched on frames scaled to
320x240); a box that stays ends the run with that reason (not "the camera moved") once the
lane's wait runs out (host/servo/recovery.py; shortened to 8 s here). On main (711cc8e) the
robot hit it."""

from __future__ import annotations

import pytest

from host.servo.recovery import BOUNDS, LANE, Bound, Recovery
from host.sim.faults import Event, WorldFaults
from host.sim.run import Setup, simulation
from host.stereo import MatcherParams


@pytest.mark.parametrize("size, width", [((320, 240), 0.3), ((320, 240), 0.6), ((640, 480), 0.3)])
def test_a_box_put_down_in_the_lane_stops_the_robot_short_of_it(size, width: float) -> None:
    """The 60 cm box hides the floor's low rows: their disparity is off the floor line, but the
    picture did not move, and the stop names the box, not a moved camera."""
    faults = WorldFaults(events=(Event(1.0, "lane-box", ahead_m=0.29, width_m=width),))
    params = MatcherParams(block_size=9, num_disparities=48 * size[0] // 320, border="clip")
    with simulation(Setup(size, 0.6, faults=faults, params=params)) as sim:
        sim.servo.recovery = Recovery({**BOUNDS, LANE: Bound(8.0, 1.0, 6)})
        gap = 9.0
        while sim.source.t < 12 and not sim.servo.stop_reason:
            sim.step()
            r = sim.world.robot
            for b in sim.world.boxes[3:]:  # the box put down
                assert b.x0_m - 0.08 < r.x_m < b.x1_m + 0.08
                gap = min(gap, b.z_m - r.z_m)
        assert 0.1 < gap < 0.29  # it stopped before the box, 10 cm or more short
        assert sim.servo.stop_reason.startswith("an object in the lane"), sim.servo.notes
        assert sim.servo.stop_reason.endswith("for 8 s")
        assert sim.emulator.motors() == (0, 0)
