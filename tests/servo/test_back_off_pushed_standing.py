"""The back-off's wait for the re-measure, pushed toward the object's side (issue 23; seed 14
trial 162, "hit the object, its side at x -0.18 m"). The robot's line passed through the object
(the body 1.9 cm from its side by the servo's estimate), and the back-off stood while the
target was measured again; a sideways push of 0.89 cm/s (fitted by the controller while it
stood beside the object) carried the body onto the side in 2.6 s, the re-measure not yet done.
Standing with a gap below what the push covers in the hold's push horizon, no back-off could
begin and clear the side in time: the run ends named, standing. A gap the push does not cover
in that time is waited on as before."""

from __future__ import annotations

from host.servo.controller import ControlConfig
from host.servo.recovery import DONE, BackOff

BLOCK = ControlConfig().block_m
HORIZON = ControlConfig().push_horizon_s
FRAME_S = 0.066  # the trial's frame interval (15 frames/s)


def _stand(gap: float, push_mps: float, target: float = 1.306, z: float = 1.321,
           confirm_after_s: float = 10.0) -> tuple[BackOff, list[tuple[int, int]], float]:
    """Frames of a back-off standing beside the object while a push closes the gap
    (push_mps toward the side), the target confirmed after confirm_after_s: the BackOff,
    its commands until its outcome (or the first move), and the gap then."""
    b, t, cmds = BackOff(BLOCK), 0.0, []
    while t < 12.0 and not b.outcome:
        cmd = b.update(t, z, gap, target, t >= confirm_after_s, False, 0.0,
                       push_mps * HORIZON)
        cmds.append(cmd)
        if cmd != (0, 0):
            break
        gap -= push_mps * FRAME_S
        t += FRAME_S
    return b, cmds, gap


def test_pushed_onto_the_side_while_the_target_is_measured_again_stops_named() -> None:
    """Trial 162's figures: 1.9 cm from the side, pushed at 0.89 cm/s, the re-measure not
    done: the run ends named at once, standing, the body clear of the side (on 31d3fc3 it
    stood on until the push had it across the side's line)."""
    b, cmds, gap = _stand(0.019, 0.0089)
    assert b.outcome.startswith("no safe way back: pushed toward the object's side")
    assert all(c == (0, 0) for c in cmds)
    assert gap > 0.01


def test_a_push_that_leaves_room_is_waited_on_and_backed_off() -> None:
    """6 cm from the side, pushed at 0.8 cm/s (the closed-loop back-off test's slope): the
    push does not cover the gap within the horizon, the wait goes on; measured again after
    1 s, the robot backs off (its first command moves it)."""
    b, cmds, gap = _stand(0.06, 0.008, confirm_after_s=1.0)
    assert b.outcome == ""
    assert cmds[-1] != (0, 0) and len(cmds) > 10
    assert gap > 0.04


def test_no_push_fitted_waits_as_before() -> None:
    """Without a push (pushed_m 0) the standing wait is what it was: it ends when the target
    has been measured again away from the robot (the object moved: DONE without a move)."""
    b = BackOff(BLOCK)
    for k in range(20):
        assert b.update(k * FRAME_S, 1.321, 0.019, 1.306, False, False, 0.0) == (0, 0)
    assert b.outcome == ""
    assert b.update(20 * FRAME_S, 1.321, 0.019, 0.9, True, False, 0.0) == (0, 0)
    assert b.outcome == DONE
