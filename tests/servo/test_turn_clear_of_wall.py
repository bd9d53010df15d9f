"""A turn round is started only where the drive after it could go on (controller.turn_tight,
_behind_turn; issue 23, fixed2): after a turn whose half turn the card did not witness, the
robot's way is unshown, and the servo checks its drive the other way too (the way it faced
before the turn) within the stopping distance and the travel that shows the way (loop.py
_fixed_fault). Seed 17's trial 105 and dev seed 1's trial 0 turned round 25 cm from the back
wall at 2.9-2.95 m (the wall's cells at 3.17-3.19 m) and their drive toward the camera was
refused "if it faces the other way" 0.08-0.16 m on, the run ended. There the leg is reversed
(the probe showed the facing: the reversed drive goes the way it shows)."""

from __future__ import annotations

from host.servo.controller import ControlConfig, Controller, Observation
from tests.servo.test_clearance import _face

WALL = _face(3.19, -1.0, 1.0)  # the back wall's cells as the reference puts them
BOX = (-0.50, -0.18)


def _controller() -> Controller:
    ctl = Controller(1.26, ControlConfig())  # dev seed 1 #0's target
    ctl.keep_out = BOX
    ctl.fixed = WALL
    ctl.facing_away = True
    return ctl


def test_a_turn_round_by_the_back_wall_is_a_reversed_leg() -> None:
    """At 2.95 m, 0.1 m left (dev seed 1 #0 at its turn), facing away: the turn's circle clears
    the wall (the servo's spin check and turn_slack_m let it start), but the drive after it,
    were the turn not witnessed, would be refused: the leg is reversed, not turned."""
    ctl = _controller()
    assert not ctl.sweeps(2.95, -0.1, slack_m=ctl.cfg.turn_slack_m)  # the old rule turns
    cmd = ctl.update(Observation(0.0, 2.95, -0.1))
    assert cmd.phase == "drive" and cmd.left < 0 and cmd.right < 0, cmd
    assert not ctl.fault


def test_with_room_behind_the_robot_still_turns_round() -> None:
    """At 2.6 m (the wall 0.59 m behind its centre) the drive after the turn has its room:
    the robot turns round as before."""
    ctl = _controller()
    assert ctl.update(Observation(0.0, 2.6, -0.1)).phase == "turn"


def test_a_robot_facing_the_camera_is_not_held_back_by_the_wall_behind_it() -> None:
    """Facing the camera at 2.95 m with the target nearer (forward: no turn at all); and facing
    the camera, near the camera, sent away from it (the turn's other way is toward the camera,
    nothing there): it turns."""
    ctl = _controller()
    ctl.facing_away = False
    cmd = ctl.update(Observation(0.0, 2.95, -0.1))
    assert cmd.phase == "drive" and cmd.left > 0, cmd
    near = Controller(1.26, ControlConfig())
    near.keep_out, near.fixed, near.facing_away = BOX, WALL, False
    assert near.update(Observation(0.0, 0.7, -0.1)).phase == "turn"
