"""The controller's look-ahead by another object's end (controller._end_hit) models the servo's
own check: its reaction, the robot's speed and track come from the servo's configs, so a robot
configured slower or wider is looked ahead for as the servo checks it."""

from __future__ import annotations

from host.camera.geometry import Geometry
from host.servo.estimator import EstimatorConfig
from host.servo.loop import Servo, ServoConfig
from host.stereo.params import MatcherParams


def test_the_controllers_look_ahead_takes_the_servos_reaction_speed_and_track() -> None:
    cfg = ServoConfig(react_s=0.5, wheelbase_m=0.2,
                      estimator=EstimatorConfig(max_speed_mps=0.3))
    servo = Servo(None, None, MatcherParams(), Geometry(300.0, 0.06, 160.0, 120.0),  # type: ignore[arg-type]
                  config=cfg)
    c = servo.control
    assert (c.check_react_s, c.max_speed_mps, c.wheelbase_m) == (0.5, 0.3, 0.2)
