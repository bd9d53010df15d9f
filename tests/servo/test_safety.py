"""Safety: a hidden marker stops the robot within one frame; a robot that stops answering is
reported and its own link-loss stop holds it."""

from __future__ import annotations

import pytest

from host.emulator.emulator import Faults
from host.link.client import LinkError

from .simulation import simulation


def test_hidden_marker_stops_the_robot_within_one_frame() -> None:
    with simulation(0.75) as sim:
        for _ in range(30):  # past the measure and the probe move
            sim.servo.step(sim.world.robot.z_m)
        assert sim.servo.rows[-1].phase in ("drive", "creep") and sim.emulator.motors() != (0, 0)
        sim.world.robot.marker_hidden = True
        row = sim.servo.step(sim.world.robot.z_m)  # the first frame without the marker
        assert (row.left, row.right) == (0, 0)
        assert sim.emulator.motors() == (0, 0)
        for _ in range(4):
            row = sim.servo.step(sim.world.robot.z_m)
        assert row.phase == "lost" and sim.emulator.motors() == (0, 0)
        sim.world.robot.marker_hidden = False
        for _ in range(3):
            row = sim.servo.step(sim.world.robot.z_m)
        assert row.phase in ("drive", "creep")  # it goes on once the marker is back


def test_a_silent_robot_is_reported_and_its_link_loss_stop_holds() -> None:
    with simulation(0.75, faults=Faults(silent_after_ms=1500), retries=3) as sim:
        with pytest.raises(LinkError, match="did not answer"):
            sim.run(10.0, settle=None)
        assert sim.servo.rows[-1].left != 0  # it was driving when the line went dead
        # the link's three tries ran on the simulated clock, past the firmware's 250 ms
        # link-loss timeout: the robot has stopped by itself
        assert sim.source.now_ms >= 1500 + 250
        assert sim.emulator.motors() == (0, 0)  # the firmware's link-loss stop
        for _ in range(500):  # the wheels run down (motor lag)
            sim.source.run_ms(1)
        z = sim.world.robot.z_m
        for _ in range(1000):
            sim.source.run_ms(1)
        assert abs(sim.world.robot.z_m - z) < 0.001  # and the robot stays where it stopped
