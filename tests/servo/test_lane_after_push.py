"""The lane back beside the object after a sideways push ended a hold (controller.Controller.
lane, Controller.pushed_mps): planned wider on the side the measured push comes toward, by
more than it closes over the push horizon (seed 18 #157, #211, #295 at a199819: pushed at
0.75-0.94 cm/s, backed off, came back onto a lane no wider and were pushed again on
arriving). Never on the other side, never nearer another fixed object than the lane keeps
them (issue 23)."""
import numpy as np

from host.servo.controller import PUSHED, Controller, Observation

TARGET_M = 1.0
KEEP_OUT = (-0.10, 0.10)
PUSH_MPS = 0.009  # +x: toward the object for a body on its low side
LANE_M = -0.25  # the plain lane on the low side: clearance 0.15 from the side at -0.10


def pushed_hold() -> Controller:
    """A controller holding on the low side's lane, pushed +x until its push check fires."""
    c = Controller(TARGET_M)
    c.keep_out = KEEP_OUT
    t = 0.0
    while not c.fault:
        c.update(Observation(t, TARGET_M, LANE_M + PUSH_MPS * t, 1.0))
        t += 1 / 15
        assert t < 10.0, "the push check never fired"
    assert c.fault == PUSHED
    return c


def again(old: Controller, first_seen: float, fixed: np.ndarray | None = None) -> Controller:
    """The controller made anew after the back-off, as loop.Servo._reacquire makes it."""
    c = Controller(old.target_m)
    c.cfg, c.keep_out, c.trim, c.facing_away = old.cfg, old.keep_out, old.trim, old.facing_away
    c.pushed_mps = old.pushed_mps
    if fixed is not None:
        c.fixed = fixed
    c.lateral_ref = first_seen
    return c


def test_the_lane_back_is_wider_by_the_push_over_the_horizon() -> None:
    old = pushed_hold()
    c = again(old, LANE_M)
    lane = c.lane(0.6)
    assert lane is not None
    room = PUSH_MPS * c.cfg.push_horizon_s  # what the push closes over the check's horizon
    assert lane < LANE_M - room, (lane, room)
    assert lane >= LANE_M - 0.04
    # held there under the same push, the check fires that much later
    c.update(Observation(0.0, TARGET_M, lane, 1.0))
    t = 1 / 15
    while not c.fault and t < 20.0:
        c.update(Observation(t, TARGET_M, lane + PUSH_MPS * t, 1.0))
        t += 1 / 15
    first = pushed_hold()
    assert t > first.history[-1].t + 0.8 * c.cfg.push_horizon_s, (t, first.history[-1].t)


def test_the_other_side_is_not_moved() -> None:
    """The push takes a body on the high side away from the object: that lane is as before."""
    c = again(pushed_hold(), -LANE_M)
    assert c.lane(0.6) == -LANE_M


def test_not_nearer_another_fixed_object() -> None:
    """Box 2's cells 20 cm beyond the plain lane, between the robot and the target: the wider
    lane would come within the lane's keep (clearance + spread room) of them: not taken."""
    cells = np.array([[0.8, LANE_M - 0.20], [0.82, LANE_M - 0.20]])
    c = again(pushed_hold(), LANE_M, cells)
    assert c.lane(0.6) == LANE_M
