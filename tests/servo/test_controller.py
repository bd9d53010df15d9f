"""The control law on its own, against a small plant (wheel lag, actuation latency, depth noise
growing as z^2, a card seen only within 41 degrees of facing the camera): the hold is centred
on zero error from either side, and the turn ends facing back with a weaker motor too."""

from __future__ import annotations

import math
from collections import deque

import numpy as np
import pytest

from host.camera.geometry import MINORU_BASELINE_M, MINORU_FOCAL_PX_320
from host.servo.controller import ControlConfig, Controller, Observation

FB = MINORU_FOCAL_PX_320 * MINORU_BASELINE_M  # the simulated Minoru at 320x240, px m


class Plant:
    """A differential drive seen by the camera: speed = gain x (duty - dead zone), lag, delay."""

    def __init__(self, z: float, gains=(1.0, 1.0), latency_ms: int = 90, seed: int = 0) -> None:
        self.z, self.x, self.theta = z, 0.0, 0.0
        self.vl = self.vr = 0.0
        self.gains = gains
        self.queue = deque([(0, 0)] * latency_ms)
        self.rng = np.random.default_rng(seed)
        self.t = 0.0

    def run(self, ms: int, cmd: tuple[int, int]) -> None:
        for _ in range(ms):
            self.queue.append(cmd)
            dl, dr = self.queue.popleft()
            a = 1 - math.exp(-0.001 / 0.08)
            for side, duty in ((0, dl), (1, dr)):
                v = 0.0 if abs(duty) <= 120 else math.copysign(0.35 * (abs(duty) - 120) / 880,
                                                               duty)
                v *= self.gains[side]
                if side == 0:
                    self.vl += (v - self.vl) * a
                else:
                    self.vr += (v - self.vr) * a
            v = (self.vl + self.vr) / 2
            self.theta += (self.vl - self.vr) / 0.14 * 0.001
            self.z += v * math.cos(self.theta) * 0.001
            self.x += v * math.sin(self.theta) * 0.001
            self.t += 0.001

    def observe(self) -> Observation:
        aspect = abs(math.cos(self.theta))
        if aspect < 0.75:
            return Observation(self.t, None)
        d = FB / self.z + self.rng.normal(0, 0.03)
        return Observation(self.t, FB / d, self.x, aspect + self.rng.normal(0, 0.02))


def servo(plant: Plant, target: float, seconds: float = 30.0) -> Controller:
    ctl = Controller(target, ControlConfig())
    while plant.t < seconds:
        cmd = ctl.update(plant.observe())
        plant.run(33, (cmd.left, cmd.right))
        if ctl.phase == "hold" and plant.t > 3 and abs(plant.vl) + abs(plant.vr) < 1e-4:
            break
    return ctl


@pytest.mark.parametrize("start", [0.8, 1.6])
def test_hold_is_centred_on_zero_error_from_either_side(start: float) -> None:
    """The old law stopped at the edge of the band (about +tolerance from behind); this one
    creeps to zero: over seeds the mean error is well inside a quarter of the tolerance."""
    errors = []
    for seed in range(6):
        plant = Plant(start, seed=seed)
        ctl = servo(plant, 1.2)
        assert ctl.phase == "hold"
        errors.append(plant.z - 1.2)
    assert abs(float(np.mean(errors))) < 0.0025
    assert max(abs(e) for e in errors) < 0.01


def test_turn_ends_facing_back_with_a_weaker_right_motor() -> None:
    """The turn's length comes from the card seen again, not from a motor model: with the
    right motor 15% weaker the robot still ends facing the camera and at the target."""
    plant = Plant(1.7, gains=(1.0, 0.85))
    ctl = servo(plant, 1.2)
    assert not ctl.facing_away
    assert abs(abs(plant.theta) - math.pi) < math.radians(20)
    assert ctl.phase == "hold" and abs(plant.z - 1.2) < 0.01


def test_a_flicker_of_the_card_does_not_end_the_turn() -> None:
    """The card seen again 0.1 s after it went edge-on is noise at the edge of detection, not
    its other side: the turn goes on."""
    ctl = Controller(1.2, ControlConfig())
    t = 0.0
    assert ctl.update(Observation(t, 2.0, 0.0, 1.0)).phase == "turn"
    for aspect in (0.95, 0.85, 0.77):
        t += 0.1
        ctl.update(Observation(t, 2.0, 0.0, aspect))
    t += 0.05
    assert ctl.update(Observation(t, None)).phase == "turn"  # edge-on
    t += 0.05
    assert ctl.update(Observation(t, 2.0, 0.0, 0.76)).phase == "turn"  # a flicker
    for _ in range(8):
        t += 0.1
        assert ctl.update(Observation(t, None)).phase == "turn"
    assert ctl.facing_away


def test_a_glimpse_of_the_card_after_a_turn_does_not_end_the_search_for_it() -> None:
    """The turn ends short of facing back (dev seed 104's trial 1: the target moved, the robot
    turned, its card was seen for one frame and then not for 5 s: "marker lost"). One frame
    of the card is a glimpse, not the card found: the robot spins on to find it (SEARCH)
    rather than stand lost until the run ends."""
    plant = Plant(1.2)
    ctl = Controller(1.2, ControlConfig())
    while plant.t < 2:  # holding, the card seen every frame
        cmd = ctl.update(plant.observe())
        plant.run(33, (cmd.left, cmd.right))
    assert ctl.phase == "hold"
    ctl.target_m = 0.9  # the target moved nearer: the robot must turn round
    turned = False
    while plant.t < 15 and not turned:
        cmd = ctl.update(plant.observe())
        plant.run(33, (cmd.left, cmd.right))
        turned = ctl.facing_away is False and cmd.phase != "turn"
    assert turned
    t = plant.t
    ctl.update(Observation(t, 1.5, 0.0, 0.8))  # one frame of the card
    phases = [ctl.update(Observation(t + 0.033 * (i + 1), None)).phase for i in range(30)]
    assert "search" in phases, phases


@pytest.mark.parametrize("x0", [-0.2, 0.2])
def test_a_far_robot_off_its_lane_keeps_its_card_near_square(x0: float) -> None:
    """A robot at 2.8 m facing the camera, 20 cm off its lane: the lane's pull asks for a
    sideways rate at once, and the drift rate that damps it lags the heading by the fit's half
    second; with the pull fading as the card's aspect turns (square_deg) the card stays within
    30 degrees of square (33 without), in view all the way, and the robot still reaches its
    lane."""
    plant = Plant(2.8)
    plant.theta, plant.x = math.pi, x0
    ctl = Controller(1.2, ControlConfig())
    ctl.facing_away, ctl.lateral_ref = False, 0.0
    worst, unseen = 0.0, 0
    while plant.t < 25.0 and ctl.phase != "hold":
        obs = plant.observe()
        unseen += obs.depth_m is None
        cmd = ctl.update(obs)
        plant.run(33, (cmd.left, cmd.right))
        worst = max(worst, math.degrees(math.acos(abs(math.cos(plant.theta)))))
    assert ctl.phase == "hold" and unseen == 0, (worst, unseen, plant.z)
    assert worst < 30.0 and abs(plant.x) < 0.03, (worst, plant.x)


def test_a_push_in_the_travels_heading_is_still_carried_while_the_card_is_unseen() -> None:
    """Driven straight away from the camera at 0.1 m/s beside the object under a 1 cm/s push
    toward it, the card lost: the heading learnt from the travel leans 5.7 degrees toward the
    object, the push's own share (clearance.Heading is the travel's chord), so the sideways
    rate cannot be taken for the robot's own motion by that heading. The rate is carried and
    the run ends ("drifting ... unseen"): 5.3 cm from the 2 cm margin, 6 cm in the 6 s."""
    from host.servo.clearance import Heading
    from host.servo.controller import DRIFTED, Command
    from host.servo.estimator import _State
    from host.servo.phase import Phase
    from host.sim.run import Setup, simulation

    with simulation(Setup(start_z_m=2.7, start_x_m=-0.1, seed=3)) as sim:
        servo = sim.servo
        c = servo.controller
        assert c is not None
        c.target_m, c.keep_out = 1.213, (-0.389, -0.178)  # seed 12 trial 213's object
        t, z, x, vz, vx = 10.0, 1.2, -0.0234, 0.1, -0.01
        servo.heading = Heading()
        for k in range(15):  # the last second's travel: along the depth axis and the push
            back = 1.0 - k / 14
            servo.heading.update(t - back, z - vz * back, x - vx * back, 300, 300, 0.002)
        assert servo.heading.value == pytest.approx(math.atan2(vx, vz), abs=0.01)
        servo.estimator.state = _State(t, z, x, vz, vx)
        servo._still_since = t + 0.03  # stopped as the card went
        assert servo._spin_fault(t + 0.2, Command(0, 0, Phase.WAIT, None)) == DRIFTED
