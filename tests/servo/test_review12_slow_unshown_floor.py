"""Review (issue 23, branch turn12, 84ed645): a drive whose heading a spin forgot is slowed
near a fixed object's end (clearance.unshown_duties, loop.Servo._slow_unshown) by scaling both
wheels' duties by spun_duty over their mean. The controller never sends a wheel below the
least duty that moves the robot (controller.lifted: its floor, min_duty 180 at least); the
scaling does. Right after a turn round the body runs 12-36 degrees off the axis, drifting
across its lane, and the lane steer is then at or near its bound (half the duty: 300 at 600):
(300, 900) becomes (150, 450). In the simulated world a wheel with offset 30-40 (motor faults:
0-40) stops below its dead zone (120): the robot pivots on that wheel, a bend far tighter than
the one the fixed-object check sweeps for those duties (clearance.run_fault: the duties' ratio,
unchanged by the scaling), in the very state (heading unknown, a fixed object's end near) the
slowing is for. Mend: lift the slowed duties to the controller's floor (controller.lifted), or
scale the mean and keep the steer's difference within what the floor allows."""

from __future__ import annotations

import math

import pytest

from host.servo.clearance import Body, Heading, depth_noise_m, unshown_duties
from host.servo.controller import ControlConfig
from host.servo.loop import ServoConfig
from host.servo.perception import stopping_distance_m
from host.sim.world import Motors
from tests.servo.test_clearance import _face

END = _face(1.60, -0.60, -0.25)  # box 2's face; its end at x = -0.25 (review11's scene)
FB = 25.6  # px m, focal x baseline at 320x240
SIGMA = 0.05
BODY = Body(0.08, 0.08, 0.02 + 0.01)
FULL = 0.4 * 600 / 1000
FLOOR = ControlConfig().min_duty
SERVO = ServoConfig()


def _slowed(left: int, right: int) -> tuple[int, int]:
    """unshown_duties at 1.75 m, the side 7 cm from box 2's end, facing the camera, a heading
    forgotten by a spin (review11's first case), the drive (left, right)."""
    return unshown_duties(Heading(), END, 1.75, -0.10, left, right, False,
                          stopping_distance_m(FULL, margin_m=0.02),
                          depth_noise_m(1.75, SIGMA, FB, 1.0), BODY, 0.12,
                          math.radians(SERVO.spun_spread_deg), SERVO.spun_duty, FLOOR)


def test_the_scene_is_slowed() -> None:
    """The precondition: a straight full drive there is slowed (as on turn12)."""
    assert _slowed(600, 600) == (300, 300)


@pytest.mark.parametrize("cmd", [(300, 900), (900, 300), (240, 760), (400, 800)])
def test_slowing_keeps_every_wheel_turning(cmd: tuple[int, int]) -> None:
    """No wheel of the slowed drive below the controller's floor (which its own command
    kept): on turn12 (300, 900) -> (150, 450) and (240, 760) -> (144, 456) fail."""
    left, right = _slowed(*cmd)
    assert min(abs(left), abs(right)) >= FLOOR, (cmd, (left, right))


def test_the_slowed_wheel_stops_in_the_simulated_world() -> None:
    """What the floor is for, in the world's own motor model: a wheel offset by 35 (a motor
    fault within 0-40) turns under 180 but not under the slowed 150 (a pivot, not the arc
    the check sweeps)."""
    m = Motors()
    assert m.speed(FLOOR - 35) > 0
    assert m.speed(150 - 35) == 0.0
