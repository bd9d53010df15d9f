"""The creep's trim held back when the card shows the body turned beside the object (issue 23,
controller.ControlConfig.creep_trim_reach_m): dev seed 105 #6 and seed 1 #2 (session 10) crept
the last few cm on the wheels' trim learnt at drive speed, which near the dead zone turned the
body 21-42 degrees; the turned reach (reach_m) then made the checks stop the run (1 #2: the
card edge-on, the search spin, a false "drifting unseen"). Creeping beside a known extent with
the card showing the body turned, the trim is not steered; square, or with no extent, as before."""

from __future__ import annotations

from host.servo.controller import ControlConfig, Controller, Observation
from host.servo.phase import Phase


def _creep(aspect: float, keep_out: tuple[float, float] | None) -> tuple[int, int]:
    """A robot facing away, 2 cm short of its target at 1.2 m on its lane, trim 0.2 learnt:
    the creep's command after a few frames (the card's aspect as given)."""
    c = Controller(1.2, ControlConfig())
    c.keep_out, c.lateral_ref, c.facing_away, c.trim = keep_out, 0.0, True, 0.2
    c.phase = Phase.CREEP
    cmd = None
    for k in range(12):
        cmd = c.update(Observation(k / 30, 1.18 + 0.0002 * k, 0.0, aspect))
    assert cmd is not None and cmd.phase == Phase.CREEP
    return cmd.left, cmd.right


def test_a_turned_body_creeping_beside_the_object_is_not_trimmed() -> None:
    """Aspect 0.95 (18 degrees) beside a box: the creep's wheels are driven alike."""
    left, right = _creep(0.95, (0.15, 0.40))
    assert left == right > 0


def test_square_or_with_no_extent_the_trim_steers_as_before() -> None:
    """Square to the camera, or with no object's extent known, the trim steers the creep."""
    for aspect, keep_out in ((1.0, (0.15, 0.40)), (0.95, None)):
        left, right = _creep(aspect, keep_out)
        assert right > left > 0
