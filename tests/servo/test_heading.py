"""The heading checked by what happens: a robot placed facing the camera, or at 60 or 90
degrees with its card edge-on, finds its marker, learns by a short probe move which way it
faces and servoes to the object without first driving toward the camera; a robot turned round
while it drives is noticed by its depth moving against the command, and turned back."""

from __future__ import annotations

import math

import pytest

from host.servo.controller import ControlConfig
from host.sim.run import Setup, simulation


def run_to_hold(setup: Setup, seconds: float = 25.0):
    with simulation(setup) as sim:
        nearest = setup.start_z_m
        while sim.source.t < seconds and not sim.servo.stop_reason:
            sim.step()
            nearest = min(nearest, sim.world.robot.z_m)
            if sim.servo.held_for(1.0):
                break
        return sim, nearest


@pytest.mark.parametrize("start, mode", [(0.6, "turn"), (0.9, "turn"), (0.6, "reverse")])
def test_a_robot_facing_the_camera_is_not_driven_toward_it(start: float, mode: str) -> None:
    """On main (711cc8e) it was driven 'away' at duty 600, toward the camera, until its marker
    left the view at 0.36 m."""
    sim, nearest = run_to_hold(Setup((320, 240), start, start_theta=math.pi,
                                     control=ControlConfig(mode=mode)))
    assert sim.servo.outcome() == ("held", "")
    assert abs(sim.depth_error_m()) <= 0.02
    assert nearest > start - 0.04  # the probe's few cm, no more
    assert any("faces the camera" in n for n in sim.servo.notes)


@pytest.mark.parametrize("degrees", [60, 90, -90])
def test_a_robot_started_side_on_finds_its_marker_and_holds(degrees: float) -> None:
    """Its card is edge-on, so nothing is seen: it spins in place until the card shows (on
    main only the 45 s limit ended the run)."""
    sim, _ = run_to_hold(Setup((320, 240), 0.9, start_theta=math.radians(degrees)))
    assert sim.servo.outcome() == ("held", "")
    assert abs(sim.depth_error_m()) <= 0.02
    assert any(r.phase == "find" for r in sim.servo.rows)


def test_a_robot_turned_round_while_driving_is_turned_back() -> None:
    """Someone turns the robot round while it drives away; the card looks the same from both
    sides, so only the depth falling under a forward command shows it."""
    with simulation(Setup((320, 240), 0.6)) as sim:
        while sim.servo.rows[-1:] == [] or sim.servo.rows[-1].phase != "drive":
            sim.step()
        for _ in range(10):
            sim.step()
        sim.world.robot.theta += math.pi
        turned_at = sim.world.robot.z_m
        nearest = turned_at
        while sim.source.t < 25 and not sim.servo.stop_reason and not sim.servo.held_for(1.0):
            sim.step()
            nearest = min(nearest, sim.world.robot.z_m)
        assert sim.servo.outcome() == ("held", "")
        assert abs(sim.depth_error_m()) <= 0.02
        assert nearest > turned_at - 0.10
        assert any("against the commanded direction" in n for n in sim.servo.notes)
