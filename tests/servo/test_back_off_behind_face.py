"""Backing off behind the object's face (seed 14 trial 609, recovery.BackOff): a robot beyond
the object's face (14 cm deeper than it, off level), its body 2 mm clear of the object's side
and facing the camera turned 17.5 degrees so that reversing takes it across the object's
extent, backed off deeper along its line: its body went 3 cm across the extent behind the
face (where a box's body is, and what the face hides from the camera; the back-off has no lane
watch), the object was pushed 21 cm farther onto it there and the body closed on the object's
side. The body coming across the object's extent behind its face ends the back-off, named,
as it does level with the face."""

from __future__ import annotations

import math

from host.servo.recovery import DONE, BackOff

BOX = (-0.50, -0.171)  # the object's lateral extent as trial 609's servo measured it (m)
HALF_WIDTH = 0.08  # controller.ControlConfig.half_width_m
BLOCK = 0.15  # controller.ControlConfig.block_m


def _gap(x: float) -> float:
    """The body's clearance across from the object (m, < 0: across it), as the loop gives it."""
    return max(x - BOX[1], BOX[0] - x) - HALF_WIDTH


def _back_off(z: float, x: float, theta: float, target: float, push: float
              ) -> tuple[BackOff, float, list[tuple[int, int]]]:
    """Frames at 15 Hz (the trial's step rate) until the back-off ends or 12 s pass: the
    BackOff, the least gap on the way and the commands. The robot moves along its heading
    theta (pi: facing the camera) at the duty's speed (0.35 m/s at full duty past a dead zone
    of 120) and is pushed sideways (m/s)."""
    b = BackOff(BLOCK)
    t, least, cmds, dt = 0.0, _gap(x), [], 1 / 15
    while t < 12.0 and not b.outcome:
        left, right = b.update(t, z, _gap(x), target, True, False, 0.0)
        cmds.append((left, right))
        duty = (left + right) / 2
        v = 0.0 if abs(duty) <= 120 else math.copysign(0.35 * (abs(duty) - 120) / 880, duty)
        z, x = z + v * math.cos(theta) * dt, x + (v * math.sin(theta) + push) * dt
        least = min(least, _gap(x))
        t += dt
    return b, least, cmds


def test_backing_off_across_the_extent_behind_the_face_stops_named() -> None:
    """Trial 609 at its back-off's start (6.08 s): depth 1.564 m, the estimate 8.9 cm left of
    centre (the body 2 mm from the side), heading 162.5 degrees, the object at 1.424 m,
    pushed 9.6 mm/s toward it. It backs off (deeper, in reverse) and stands, named, as the
    body comes across the extent: not 3 cm across it, nor DONE behind the face."""
    b, least, cmds = _back_off(1.564, -0.089, math.radians(162.5), 1.424, push=-0.0096)
    assert any(left < 0 and right < 0 for left, right in cmds)  # it did back off
    assert b.outcome.startswith("no safe way back") and b.outcome != DONE
    assert "behind the object's face" in b.outcome
    assert least > -0.01  # stood within a frame or two of the body reaching the extent
