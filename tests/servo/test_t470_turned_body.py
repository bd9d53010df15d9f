"""Seed 16 trial 470 (session 9, issue 23): the target box vanished, the servo retargeted to
box 2 (face at 1.80 m, x +0.22..+0.55) and drove the robot, facing the camera but turned 15-29
degrees off its axis after a turn round, down beside box 2's side. The block check
(Controller.overlaps: half the body's width, 8 cm, and the 2 cm margin) passed it at 1.3-2.5 cm
from the side on the servo's lateral, while the turned body reached 10.8 cm across x: it
touched the side ("hit the object, its side at x +0.22 m"). The check now takes the body's
reach across x turned by the learnt heading's angle off the camera axis and its spread."""

from __future__ import annotations

import math

import pytest

from host.servo.controller import LINE_BLOCKED, Command, ControlConfig, Controller, Observation
from host.servo.phase import Phase


def _beside_box(turned_by: float | None) -> tuple[Controller, Command]:
    """The servo's own figures of #470 at 5.96 s: box 2's keep-out as it measured it, the
    robot's lateral 9.2 cm at 1.92 m (13 cm from the target's depth: within block_m)."""
    c = Controller(1.793, ControlConfig())
    c.keep_out = (0.211, 0.533)
    c.lateral_ref = 0.072
    c.facing_away = False
    c.turned_by = turned_by
    return c, c.update(Observation(5.961, 1.921, 0.092, 1.0))


def test_a_body_turned_off_the_axis_reaches_farther_across() -> None:
    c = Controller(1.5, ControlConfig())
    assert c.across_m() == pytest.approx(0.08)  # not known: half the width, as before
    c.turned_by = 0.0
    assert c.across_m() == pytest.approx(0.08)
    c.turned_by = math.radians(29)  # #470's body: the world's own extent, 10.8 cm
    assert c.across_m() == pytest.approx(0.08 * (math.cos(0.506) + math.sin(0.506)), abs=1e-3)
    assert c.across_m() > 0.107
    c.turned_by = math.radians(-29)
    assert c.across_m() > 0.107
    c.turned_by = 3.0  # at most a quarter turn, never less than half the width
    assert c.across_m() == pytest.approx(0.08)


def test_the_turned_body_beside_the_box_is_blocked() -> None:
    c, cmd = _beside_box(math.radians(20) + math.radians(5))  # learnt 20 deg, spread 5
    assert cmd.phase == Phase.BLOCKED and c.fault == LINE_BLOCKED
    c, cmd = _beside_box(None)  # the heading not known: the check as it was (clear at 9.2 cm)
    assert cmd.phase != Phase.BLOCKED and not c.fault


def test_the_loop_gives_the_controller_the_heading_off_the_axis() -> None:
    """Servo._track_heading: a straight run toward the camera 20 degrees off its axis sets
    controller.turned_by to that angle plus the heading's spread."""
    from host.servo.estimator import _State
    from host.sim.run import Setup, simulation

    with simulation(Setup(start_z_m=1.6, seed=3)) as sim:
        servo = sim.servo
        c = servo.controller
        assert c is not None
        servo._cmd = Command(300, 300, Phase.DRIVE, None)
        off = math.radians(20)
        vz, vx = -0.15 * math.cos(off), -0.15 * math.sin(off)  # facing the camera, turned
        for k in range(31):
            t = 10.0 + k / 30
            servo.estimator.state = _State(t, 1.6 + vz * k / 30, 0.1 + vx * k / 30, vz, vx)
            servo._track_heading(t, servo._cmd)
        assert servo.heading.value is not None
        assert c.turned_by == pytest.approx(off + servo.heading.spread, abs=0.02)
        assert c.across_m() > 0.08 * (math.cos(off) + math.sin(off)) - 1e-3
