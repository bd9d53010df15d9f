"""The probe's first leg, its facing not yet shown, may run either way in depth (issue 23):
seed 13's trial 157 faced the camera at 2.97 m where the servo takes a robot to face away, and
its first leg, checked along that facing alone, backed it 8 cm toward the back wall unchecked
(its move there stayed within the depth noise at 3 m, about 10 cm, for most of probe_s; its
reach is bounded only by probe_s at duty 300-400, ~15 cm). Now both legs are checked both ways
while the facing is unshown (acquire.py, Acquisition.either_way)."""

from __future__ import annotations

from host.servo.controller import INTO_FIXED, Command
from host.servo.loop import Servo
from host.servo.phase import Phase
from tests.servo.test_fixed_objects import _at, _path, scene  # noqa: F401 (the fixture)


def _probing(servo: Servo, z: float, x: float) -> Servo:
    """The servo in its probe's first leg, the robot estimated at (z, x), no heading learnt
    and the controller's facing its default (away), the probe's verdict not in."""
    servo = _at(servo, z, x, None)
    acq = servo.acquisition
    acq.phase, acq._leg, acq.facing_away = Phase.PROBE, 1, None
    return servo


def test_a_probes_first_leg_is_checked_the_other_way_too(scene: Servo) -> None:  # noqa: F811
    """The default scene's box at 1.8 m leaves fixed cells at 2.37-2.39 m, 0.73-0.89 m right.
    The robot 0.8 m right at 2.50 m (its body's front 3 cm from them if it faces the camera),
    its first leg forward at 400: facing away (the servo's assumption) it goes away from the
    cells, facing the camera it goes onto them within the leg's reach (up to three of a
    sighting's noise there, 7 cm, before the move shows its way, and the run-down). It is
    refused "if it faces the other way" (8bb4289 drove it: the first leg was checked along
    the facing alone); so is it at 2.55 m (8 cm from them). With the other way clear (2.80 m,
    33 cm from them) the same leg is driven."""
    leg1 = Command(400, 400, Phase.PROBE, None)
    try:
        for z in (2.50, 2.55):
            why = _path(_probing(scene, z, 0.8), leg1)
            assert why.startswith(INTO_FIXED.format("probe")) and "other way" in why, (z, why)
        assert _path(_probing(scene, 2.80, 0.8), leg1) == ""
    finally:
        scene.acquisition.phase, scene.acquisition._leg = Phase.DONE, 1
