"""The back-off watched the way it goes (issue 23, the review of recovery.BackOff): the lane
watch looks the way the robot backs off (it looked only toward the target, the other way),
the view's check judges the marker's run toward the camera by the back-off's own way (it took
the drive's), a body behind the object's face across its extent stops (a real box's body lies
behind its face: the simulation's box is its face alone), and no wheel backs off below the
least duty that moves the robot (the controller's floor)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from types import SimpleNamespace

import numpy as np
import pytest

from host.servo.clearance import Heading
from host.servo.controller import Command
from host.servo.estimator import _State
from host.servo.loop import Servo
from host.servo.marker import Blob, MarkerPair
from host.servo.perception import in_view
from host.servo.phase import Phase
from host.servo.recovery import DONE, BackOff
from host.sim.faults import Event, MotorFaults, WorldFaults
from host.sim.run import Setup, simulation
from tests.servo.judged import Judged

BOX = (-0.50, -0.18)  # the default scene's target box, lateral extent (m)
HALF_WIDTH = 0.08  # controller.ControlConfig.half_width_m
BLOCK = 0.15  # controller.ControlConfig.block_m


def _gap(x: float) -> float:
    """The body's clearance across from the box (m, < 0: across it), as the loop gives it."""
    return max(x - BOX[1], BOX[0] - x) - HALF_WIDTH


def _back_off(z: float, x: float, theta: float, target: float, dead: int = 120,
              floor: int = 0) -> tuple[BackOff, float, float, list[tuple[int, int]]]:
    """Frames at 30 Hz for up to 12 s: the BackOff, the final depth, the least gap on the
    way and the commands. The
    robot moves along its heading theta (pi: facing the camera) at 0.35 m/s at full duty past
    a dead zone of `dead` permille (no wheel below it turns); floor: the controller's."""
    b = BackOff(BLOCK)
    t, cmds, dt, least = 0.0, [], 1 / 30, _gap(x)
    facing_away = math.cos(theta) > 0
    while t < 12.0 and not b.outcome:
        left, right = b.update(t, z, _gap(x), target, True, facing_away, 0.0, 0.0, floor)
        cmds.append((left, right))
        duty = (left + right) / 2 if min(abs(left), abs(right)) > dead else 0.0
        v = 0.0 if not duty else math.copysign(0.35 * (abs(duty) - dead) / (1000 - dead), duty)
        z, x = z + v * math.cos(theta) * dt, x + v * math.sin(theta) * dt
        least = min(least, _gap(x))
        t += dt
    return b, z, least, cmds


def test_the_back_off_drives_no_wheel_below_the_floor_duty() -> None:
    """The controller's floor raised to 420 (stiction, a sagging battery: the wheels do not
    turn at 350): the back-off drives at the floor and gets out of the object's depth; at
    its own 350 it stood, commanded, going nowhere."""
    b, z, _, cmds = _back_off(1.2, -0.05, 0.0, 1.2, dead=350, floor=420)
    assert b.outcome == DONE and z <= 1.2 - BLOCK
    assert all(min(abs(left), abs(right)) >= 420 for left, right in cmds if left or right)
    b = BackOff(BLOCK)
    left, right = b.update(0.0, 1.2, 0.05, 1.2, True, True, 0.1, 0.0, 420)  # trimmed
    assert min(abs(left), abs(right)) >= 420 and left > right  # the trim's sense kept


def test_a_body_behind_the_face_across_the_extent_does_not_back_off_deeper() -> None:
    """The robot 6 cm behind the object's face with its body 3 cm across the object's
    extent (its line through a box the simulation draws as a face alone): a real box's body
    is there. Backing off deeper went on behind the face (DONE 25 cm behind it); it stands,
    named, without a move."""
    b, z, _, cmds = _back_off(1.26, -0.23, 0.0, 1.2)
    assert b.outcome.startswith("no safe way back") and "behind the object's face" in b.outcome
    assert all(c == (0, 0) for c in cmds) and z == 1.26


def test_closing_on_the_side_behind_the_face_is_no_way_back() -> None:
    """14 cm behind the face (off level), 1.5 cm clear of the object's side and facing the
    camera turned 25 degrees toward the object: backing off deeper closes on the side, which
    runs back from the face on a real box. It stands, named, before the body reaches the
    extent, as it does level with the face (it went on until the body was across it)."""
    b, _, least, _ = _back_off(1.34, BOX[1] + HALF_WIDTH + 0.015, math.radians(155), 1.2)
    assert b.outcome == "no safe way back: backing off closes on the object's side"
    assert least > 0.0


@pytest.fixture(scope="module")
def scene() -> Iterator[Servo]:
    """A servo after its reference phase (the default scene, target at 1.2 m)."""
    with simulation(Setup(start_z_m=2.7, start_x_m=-0.1, seed=3)) as sim:
        yield sim.servo


def _view_fault(servo: Servo, z: float, target: float, deeper: bool) -> str:
    """The drive check of a back-off command (reverse, facing away, 8 cm/s) at depth z with
    the object at target, the card's ring just inside the picture's right edge: in view as
    it stands, out of it once 4-5 % nearer."""
    c = servo.controller
    assert c is not None
    c.target_m, c.facing_away = target, True
    servo.estimator.state = _State(10.0, z, 0.0, -0.08 if not deeper else 0.08, 0.0)
    servo.heading = Heading()
    g, cfg = servo.geometry, servo.cfg
    w, h = 320, 240
    r = 10.0
    ring = r * cfg.ring_ratio
    run = 0.08 * cfg.react_s + 0.02
    scale = z / (z - run)
    u = math.floor(w - 1 - ring - 2.0)  # in view at scale 1, not at `scale`
    assert in_view(u, g.cy, ring, (w, h), 1.0, g.cx, g.cy)
    assert not in_view(u, g.cy, ring, (w, h), scale, g.cx, g.cy)
    servo.last_pair = MarkerPair(Blob(u, g.cy, r), Blob(u - 10, g.cy, r))
    b = BackOff(BLOCK)
    b.deeper, b.start_z = deeper, z
    servo.backoff = b
    frame = SimpleNamespace(left=np.zeros((h, w)), t_left=10.0)
    cmd = Command(-350, -350, Phase.DRIVE, None)
    try:
        return servo._path_fault(frame, cmd)  # type: ignore[arg-type]
    finally:
        servo.backoff = None


def test_the_view_is_checked_the_way_the_back_off_goes(scene: Servo) -> None:
    """Nearer the camera than the object (the drive's way: away from the camera) and backing
    off toward the camera, the card's ring 2 px inside the picture's edge: the run toward the
    camera takes it out of the view before a stop acts, so the back-off is not driven (the
    check took the drive's way and let it go). Beyond the object's face, backing off away
    from the camera, the ring shrinks: it is driven (the drive's way said it would leave)."""
    scene.cfg = dataclasses.replace(scene.cfg, fixed_check=False)
    assert _view_fault(scene, 0.75, 0.85, deeper=False).startswith("the marker would leave")
    assert _view_fault(scene, 1.30, 1.20, deeper=True) == ""


@pytest.mark.slow  # a closed-loop run (the slow tier's, as test_back_off's)
def test_an_object_put_down_in_the_back_offs_way_stops_it_named() -> None:
    """The simulated world of test_back_off's closed loop: holding beside the object, pushed
    toward it at 8 mm/s, the robot backs off toward the camera from 2.1 s; at 2.6 s a low box
    (12 cm high: the card stays in view) is put down across its line at 1.0 m, 18 cm behind
    its centre. The back-off ran into it (the trials' judge: unsafe); watched the way it
    goes, it stops, named, before its body reaches the box."""
    faults = WorldFaults(motor=MotorFaults(push_mps=-0.008),
                         events=(Event(2.6, "appear", box=(1.0, -0.21, 0.09, 0.12)),))
    with simulation(Setup(start_z_m=1.25, start_x_m=-0.04, faults=faults, seed=3)) as sim:
        servo, judged = sim.servo, Judged(sim)
        while sim.source.t < 12.0 and not servo.stop_reason:
            why = judged.step()
            assert not why, why
        assert "no safe way back: an object in the lane" in servo.stop_reason
        assert "backing off" in servo.stop_reason
