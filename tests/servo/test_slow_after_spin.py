"""A drive whose heading a spin forgot is slowed near another fixed object (loop.py
Servo._slow_unshown, clearance.unshown_duties): the fixed-object check looks along the depth
axis within 5 degrees until the travel shows the heading, and a turn round ends 12-36 degrees
off it; at full speed the check then fires too late for a body turned toward a box's end
(tests/servo/test_review11_heading_after_turn.py, the pure case). The scene: seed 3's world,
box 2 at 1.8 m across 0.22-0.55 m (tests/servo/test_fixed_objects.py)."""

from __future__ import annotations

import dataclasses

from host.servo.controller import Command
from host.servo.loop import Servo
from host.servo.phase import Phase
from tests.servo.test_fixed_objects import _at, scene  # noqa: F401 (the fixture)

DRIVE = Command(600, 560, Phase.DRIVE, 0.5)  # toward the camera, steering a little


def _facing_camera(servo: Servo, z: float, x: float, heading_deg: float | None) -> Servo:
    servo = _at(servo, z, x, heading_deg)
    servo.controller.facing_away = False  # type: ignore[union-attr]
    servo.backoff = None
    return servo


def test_a_drive_after_a_spin_beside_a_boxs_end_is_slowed(scene: Servo) -> None:  # noqa: F811
    """2.0 m deep, the body's side 6 cm from box 2's end (x 0.08: clear along the axis), the
    heading unknown: the drive runs at spun_duty, its steer kept in proportion."""
    slowed = _facing_camera(scene, 2.0, 0.08, None)._slow_unshown(DRIVE)
    cap = scene.cfg.spun_duty
    assert (slowed.left + slowed.right) / 2 <= cap, slowed
    assert slowed.left > slowed.right and slowed.phase == Phase.DRIVE


def test_a_drive_after_a_spin_in_the_open_or_with_its_heading_known_is_not(
        scene: Servo) -> None:  # noqa: F811
    """Far from any end (x -0.3, the robot's own box is the target), or the heading learnt
    from its travel: the drive runs as the controller asked."""
    assert _facing_camera(scene, 2.0, -0.30, None)._slow_unshown(DRIVE) == DRIVE
    assert _facing_camera(scene, 2.0, 0.08, 0.0)._slow_unshown(DRIVE) == DRIVE


def test_without_the_cap_the_drive_runs_at_full_duty(scene: Servo) -> None:  # noqa: F811
    """The mend's knob: spun_duty at the drive's own duty leaves the command as it was."""
    cfg = scene.cfg
    try:
        scene.cfg = dataclasses.replace(cfg, spun_duty=600)
        assert _facing_camera(scene, 2.0, 0.08, None)._slow_unshown(DRIVE) == DRIVE
    finally:
        scene.cfg = cfg
