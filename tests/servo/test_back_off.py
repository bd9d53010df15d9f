"""Backing off the object's side rather than ending the run (issue 23, recovery.BackOff): a robot
pushed toward the object's side while it holds (seed 13 trials 105 and 114: "pushed sideways
onto the object while holding"), or whose line passes through the object on a depth the object
has left (trial 710), stands while the target is measured again, then backs off straight along
its line out of the object's depth, the other way when that way closes on the object's side;
where neither way is safe, the run ends named. A small kinematic robot (heading, a sideways
push) stands in for the world; the closed loop in the simulated world is test_fixed_objects'."""

from __future__ import annotations

import math

import pytest

from host.servo.controller import ControlConfig
from host.servo.recovery import DONE, BackOff, BackOffConfig
from host.sim.faults import MotorFaults, WorldFaults
from host.sim.run import Setup, simulation
from tests.servo.judged import Judged

BOX = (-0.50, -0.18)  # the object's lateral extent (m): the default scene's nearest box
HALF_WIDTH = 0.08
BLOCK = 0.15  # controller.ControlConfig.block_m


def _gap(x: float) -> float:
    """The body's clearance across from the box (m, < 0: across it), as the loop gives it."""
    return max(x - BOX[1], BOX[0] - x) - HALF_WIDTH


def _back_off(z: float, x: float, theta: float, target: float, push: float = 0.0,
              facing_away: bool = True, confirm_after: int = 0, seconds: float = 12.0
              ) -> tuple[BackOff, float, float, float, list[tuple[int, int]]]:
    """Frames at 30 Hz until the back-off ends: the BackOff, the final z and x, the least gap
    on the way and the commands. The robot moves along its heading theta (0: facing away from
    the camera, pi: facing it; facing_away must agree) at the duty's speed (0.35 m/s at full
    duty past a dead zone of 120), and the push moves it sideways (m/s) all the while."""
    b = BackOff(BLOCK)
    t, least, cmds = 0.0, _gap(x), []
    while t < seconds and not b.outcome:
        left, right = b.update(t, z, _gap(x), target, len(cmds) >= confirm_after, facing_away,
                               0.0)
        cmds.append((left, right))
        duty = (left + right) / 2
        v = 0.0 if abs(duty) <= 120 else math.copysign(0.35 * (abs(duty) - 120) / 880, duty)
        dt = 1 / 30
        z, x = z + v * math.cos(theta) * dt, x + (v * math.sin(theta) + push) * dt
        least = min(least, _gap(x))
        t += dt
    return b, z, x, least, cmds


def test_a_robot_pushed_beside_the_object_backs_off_out_of_its_depth() -> None:
    """Holding at the object's depth 5 cm from its side, pushed toward it at 8 mm/s: it
    backs off toward the camera (facing away: in reverse) to block_m + clear_m from the
    object's depth, the body clear of the side all the way; a push alone does not make it
    turn round to the other way."""
    b, z, _, least, cmds = _back_off(1.2, -0.05, 0.0, 1.2, push=-0.008)
    assert b.outcome == DONE
    assert z <= 1.2 - BLOCK - BackOffConfig().clear_m
    assert least > 0.0
    assert not b.flipped
    assert all(left < 0 and right < 0 for left, right in cmds if left or right)


def test_the_target_measured_again_away_from_the_robot_ends_it_standing() -> None:
    """The object moved 24 cm nearer the camera (trial 710): the stale depth put it beside the
    robot. The robot stands until the target is measured again; the fresh depth is far from
    it, and the back-off ends without a move."""
    b, z, _, _, cmds = _back_off(1.36, -0.08, math.pi, 0.968, facing_away=False,
                                 confirm_after=10)
    assert b.outcome == DONE
    assert all(c == (0, 0) for c in cmds) and len(cmds) == 11
    assert z == 1.36
    # the same robot with the object's depth 11 cm nearer the camera backs off deeper,
    # away from the camera (facing it: in reverse): it is beyond the object's face
    b, z, _, _, cmds = _back_off(1.36, -0.08, math.pi, 1.25, facing_away=False)
    assert b.outcome == DONE and z >= 1.25 + BLOCK + BackOffConfig().clear_m
    assert all(left < 0 and right < 0 for left, right in cmds if left or right)


def test_a_robot_turned_toward_the_side_backs_off_the_other_way() -> None:
    """Turned 27 degrees (seed 13 trial 105), backing off toward the camera takes it toward
    the object's side: it goes the other way, away from the camera, before its body
    reaches the side. Level with the face (3 cm in front of it, as the trial was, the body,
    square as this robot's card shows it, clears the side's region on the way toward the
    camera and goes on: recovery.front_clear, test_back_off_front_clear.py)."""
    b, z, _, least, _ = _back_off(1.2, -0.05, math.radians(27), 1.2, push=-0.002)
    assert b.flipped
    assert b.outcome == DONE and z >= 1.2 + BLOCK
    assert least > 0.0


def test_no_safe_way_back_ends_the_run_named() -> None:
    """A body that closes on the object's side either way (turned toward it and pushed at
    10 cm/s) has no safe way back: the outcome says so, and it stands before its body
    reaches the side."""
    b, _, _, least, _ = _back_off(1.2, -0.05, math.radians(30), 1.2, push=-0.1)
    assert b.outcome.startswith("no safe way back")
    assert least > 0.0  # it stood before its body reached the side


def test_a_line_through_the_object_backs_off_only_away_from_its_face() -> None:
    """Its line through the object (the body across the object's extent, 10 cm in front of
    its face: "the robot's line passes through the object") and turned 20 degrees so that
    backing off takes it farther across: the way away from the face is the one way back (the
    other way is into the face), so it does not turn to it; it backs off to block_m +
    clear_m from the face."""
    b, z, _, _, cmds = _back_off(1.1, -0.15, math.radians(20), 1.2)
    assert b.outcome == DONE and not b.flipped
    assert z <= 1.2 - BLOCK - BackOffConfig().clear_m
    assert all(left < 0 and right < 0 for left, right in cmds if left or right)


@pytest.mark.slow  # a closed-loop run (the slow tier's, as test_fixed_objects')
def test_in_closed_loop_a_robot_pushed_while_it_holds_backs_off_and_holds_again() -> None:
    """The simulated world: the robot holds beside the object 4 cm left of centre (its body
    6 cm from the object's side) while a slope pushes it toward the object at 8 mm/s. It
    backed off and planned its lane anew rather than ending the run ("pushed sideways onto
    the object while holding", as it did before the back-off), and holds again, its body
    never touching the object (the trials' judge), and its body as it truly is, turned
    (13-20 degrees: the lane's steer against the push), clear of the object's side by the
    checks' margin when it holds (controller.reach_m: the half width alone was taken, it
    held 1.5 cm from the side, turned 19.6 degrees, the push closing at 8 mm/s)."""
    faults = WorldFaults(motor=MotorFaults(push_mps=-0.008))
    with simulation(Setup(start_z_m=1.25, start_x_m=-0.04, faults=faults, seed=3)) as sim:
        servo, judged, outcome = sim.servo, Judged(sim), "unsettled"
        while sim.source.t < 30.0:
            why = judged.step()
            assert not why, why
            if servo.stop_reason:
                outcome = servo.stop_reason
                break
            if servo.held_for(1.0) and sim.source.t > 8.0:
                outcome = "held"
                break
        assert outcome == "held"
        assert any("backed off" in note for note in servo.notes)
        r, box = sim.world.robot, sim.world.nearest_box()
        side = max(box.x0_m - r.x_m, r.x_m - box.x1_m) - r.half_extent()[0]
        assert side >= ControlConfig().block_margin_m, side
