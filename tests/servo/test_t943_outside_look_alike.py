"""Seed 16's trial 943: the marker seen only outside the gate (a look-alike at 1.40 m, x +0.38,
0.23 m beyond the robot's 0.18 m reach), the servo acquired from scratch, took the look-alike
for the robot and probed it: the probe drove the unseen robot (turned 230 degrees by a turn spun
blind through a frozen sensor) 11 cm toward it, and the search spin after "did not move" touched
it. A sighting still beyond where the robot could be is not probed: a spin test in place shows
whether the card turns with the robot (a look-alike's stays: left out, looked for again)."""

from __future__ import annotations

from host.camera.geometry import Geometry
from host.servo.controller import Command, Controller
from host.servo.estimator import Sighting
from host.servo.loop import Servo
from host.servo.marker import Blob, MarkerPair
from host.servo.phase import Phase
from host.stereo.params import MatcherParams

G = Geometry(300.0, 0.06, 160.0, 120.0)
DT = 0.066


def _pair(z: float, x: float, aspect: float) -> MarkerPair:
    d = G.focal_px * G.baseline_m / z
    u = G.cx + x * d / G.baseline_m
    r = G.focal_px * 0.03 / z
    return MarkerPair(Blob(u, 120.0, r, aspect), Blob(u - d, 120.0, r, aspect))


def _sighting(t: float, pair: MarkerPair) -> Sighting:
    b = pair.left
    return Sighting(t, pair.disparity, b.u, 2 * b.radius / (1 + min(1.0, b.aspect)))


def _servo_after_outside() -> tuple[Servo, float]:
    """A servo past its acquisition, the robot standing at 1.336 m, x +0.09, then a look-alike
    at 1.40 m, x +0.38 seen alone, outside the gate, until the outside recovery acquires again."""
    servo = Servo(None, None, MatcherParams(), G)  # type: ignore[arg-type]
    servo.controller = c = Controller(1.01)
    c.facing_away = True
    servo.acquisition.phase = Phase.DONE
    est, t = servo.estimator, 0.0
    robot = _pair(1.336, 0.09, 0.95)
    for _ in range(15):
        t += DT
        est.commanded(t, 0, 0)
        est.accept(_sighting(t, robot))
    decoy = _pair(1.40, 0.38, 0.9)
    assert est.gate(_sighting(t + DT, decoy))  # beyond where the robot can be
    while not est.outside_too_long(t):
        t += DT
        est.commanded(t, 0, 0)
        est.reject(t, est.gate(_sighting(t, decoy)))
    servo._outside_gate(t)
    assert not servo.acquisition.done and servo.estimator.state is None
    return servo, t


def test_a_look_alike_refused_by_the_gate_is_not_probed_after_the_outside_recovery() -> None:
    servo, t = _servo_after_outside()
    decoy = _pair(1.40, 0.38, 0.9)
    sent: list[Command] = []
    for _ in range(120):  # 8 s of the look-alike alone, standing, its card as it stands
        t += DT
        s = _sighting(t, decoy)
        assert not servo.estimator.gate(s) or servo._statics
        if servo._statics:
            break  # left out: the acquisition looks for another marker
        servo.estimator.accept(s)
        servo.last_pair = decoy
        cmd = servo._acquire(t, servo.estimator.position(s), decoy.disparity)
        servo.estimator.commanded(t, cmd.left, cmd.right)
        sent.append(cmd)
        if servo.stop_reason:
            break
    drives = [c for c in sent if c.left == c.right != 0]
    assert not drives, f"the robot was driven on the look-alike: {drives[:3]}"
    assert any(c.left == -c.right != 0 for c in sent)  # the spin test turned it in place
    assert servo._statics and not servo.stop_reason  # a look-alike: left out, looked for again
    assert any("did not move with the robot" in n for n in servo.notes)


def test_the_robots_own_card_found_again_within_its_reach_is_probed_as_before() -> None:
    servo, t = _servo_after_outside()
    robot = _pair(1.34, 0.10, 0.95)  # the robot's card back where the robot can be
    sent: list[Command] = []
    for _ in range(20):
        t += DT
        s = _sighting(t, robot)
        servo.estimator.accept(s)
        servo.last_pair = robot
        cmd = servo._acquire(t, servo.estimator.position(s), robot.disparity)
        sent.append(cmd)
    assert any(c.phase == Phase.PROBE and c.left == c.right != 0 for c in sent)
    assert not servo.stop_reason
