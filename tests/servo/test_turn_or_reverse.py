"""Where the controller turns round and where it reverses the leg instead (controller.turn_tight,
issue 23): a turn in place takes seconds, the card lost for most of them, and the body wanders
in it; where that leaves too little room (another box's end within the check's reach plus
turn_slack_m, or beside the object within block_m of its depth, where a sideways push closes
while the card is unseen) the leg is reversed along the robot's line with the card in view.
Seed 14's trials 55 and 181 (the turn's own check ended the run mid-spin) and 7 and 235 (the
unseen drift check ended it mid-spin) are the cases."""

from __future__ import annotations

import math

from host.servo.controller import ControlConfig, Controller, Observation
from tests.servo.test_clearance import _face
from tests.servo.test_controller import Plant

BOX = (-0.35, -0.18)  # the target's lateral extent (m), as the servo measured it in trial 55


def _reversed(cmd: object) -> bool:
    return cmd.phase == "drive" and cmd.left < 0 and cmd.right < 0  # type: ignore[attr-defined]


def test_a_turn_with_little_room_to_another_boxs_end_is_a_reversed_leg() -> None:
    """Seed 14 trial 55: the robot 2 cm behind box 2's face (1.8 m, 0.22-0.55 m), 15 cm from
    its end, must come back 0.7 m. The turn's circle cleared the check by 7 mm when it began;
    the body wandered 2.2 cm in the spin and the check ended the run. With turn_slack_m the
    leg is reversed; 23 cm from the end there is room and it turns."""
    def controller() -> Controller:
        ctl = Controller(1.116, ControlConfig())
        ctl.keep_out = BOX
        ctl.fixed = _face(1.8, 0.22, 0.55)
        return ctl
    tight = controller()
    assert not tight.sweeps(1.82, 0.078)  # the servo's check alone lets this spin start
    cmd = tight.update(Observation(0.0, 1.82, 0.078))
    assert _reversed(cmd) and not tight.fault, cmd
    assert controller().update(Observation(0.0, 1.82, 0.0)).phase == "turn"


class PushedPlant(Plant):
    """The plant with the world's sideways push (m/s along x, as seed 14 trial 235's 0.9
    cm/s) acting on the body whatever it does."""

    def __init__(self, z: float, push: float) -> None:
        super().__init__(z)
        self.push = push

    def run(self, ms: int, cmd: tuple[int, int]) -> None:
        super().run(ms, cmd)
        self.x += self.push * ms / 1000


def test_a_short_leg_beside_the_object_is_reversed_with_the_card_in_view() -> None:
    """Seed 14 trial 235: 9 cm past the object's depth, 9 cm clear of its side and pushed
    toward it at 0.9 cm/s, the robot must come back. It turned round, the card edge-on for
    seconds, and the servo's unseen drift check (6 s of the last drift) ended the run mid-spin.
    Within block_m of the object's depth the leg is reversed: the card stays in view every
    frame, and the robot holds at the object's depth, never turning, its body clear. Here 11
    cm clear (beyond turn_slack_m's reach: the depth rule alone reverses it)."""
    ctl = Controller(1.008, ControlConfig())
    ctl.keep_out = (-0.31, -0.17)
    plant = PushedPlant(1.10, push=-0.009)
    plant.x = 0.02
    phases, unseen, gap = set(), 0, math.inf
    while plant.t < 10 and not ctl.fault:
        obs = plant.observe()
        unseen += obs.depth_m is None
        cmd = ctl.update(obs)
        phases.add(cmd.phase)
        plant.run(33, (cmd.left, cmd.right))
        gap = min(gap, plant.x - ctl.cfg.half_width_m - (-0.17))
        if ctl.phase == "hold" and plant.t > 2 and abs(plant.vl) + abs(plant.vr) < 1e-4:
            break
    assert ctl.phase == "hold" and not ctl.fault, (ctl.phase, ctl.fault)
    assert "turn" not in phases and unseen == 0, (phases, unseen)
    assert abs(plant.z - 1.008) <= 0.015 and gap > 0.03, (plant.z, gap)


def test_far_from_the_objects_depth_with_room_the_robot_still_turns_round() -> None:
    """The rule is no blanket reverse: 40 cm past the object's depth, nothing near, the robot
    turns round as the paper's mode does."""
    ctl = Controller(1.0, ControlConfig())
    ctl.keep_out = BOX
    assert ctl.update(Observation(0.0, 1.40, 0.0)).phase == "turn"
