"""A probe beside the target object is checked against the object's own face, its heading
(not yet travelled) within the card's turn either way (host/servo/loop.py, Servo._fixed_fault):
seed 18's trial 98, the campaign's one unsafe trial, started facing sideways 9 cm before the
box's face and 14 cm from its side; its find spin left it turned 28 degrees toward the side,
and its probe's 6 cm forward ran the body's corner into the box (no line check watches a probe;
the fixed-object check left out the target's own cells and took the heading within 5 degrees
of the depth axis)."""

from __future__ import annotations

import math

from host.servo.controller import INTO_FIXED, Command
from host.servo.loop import Servo
from host.servo.phase import Phase
from tests.servo.test_fixed_objects import _at, _path, scene  # noqa: F401 (the fixture)


def _probing(servo: Servo, turn_deg: float) -> Servo:
    """The robot 9.5 cm before the target's face and 13.5 cm from its side (x1), standing
    in its probe's first leg, no heading travelled, the card showing turn_deg off square."""
    c = servo.controller
    assert c is not None and c.keep_out is not None
    servo = _at(servo, c.target_m - 0.095, c.keep_out[1] + 0.135, None)
    c.turns = [math.radians(turn_deg)] * c.cfg.reach_frames
    acq = servo.acquisition
    acq.phase, acq._leg, acq.facing_away = Phase.PROBE, 1, None
    return servo


def test_a_turned_probe_beside_the_object_is_refused(scene: Servo) -> None:  # noqa: F811
    leg = Command(400, 400, Phase.PROBE, None)
    try:
        why = _path(_probing(scene, 28.0), leg)
        assert why.startswith(INTO_FIXED.format("probe")), why
        assert _path(_probing(scene, 0.0), leg) == ""  # square: it runs past the side
    finally:
        scene.acquisition.phase, scene.acquisition._leg = Phase.DONE, 1
        scene.controller.turns = []  # type: ignore[union-attr]
