"""The simulated world fails like hardware, and does so reproducibly: each fault model has the
effect it names, and the same seed gives the same faults."""

from __future__ import annotations

import math

import numpy as np

from host.sim.faults import CameraFaults, Event, MotorFaults, WorldFaults, random_faults
from host.sim.renderer import Renderer
from host.sim.source import SimSource
from host.sim.world import World


class Board:
    """A board that drives both wheels at a fixed duty and counts its milliseconds."""

    def __init__(self, duty: tuple[int, int] = (400, 400)) -> None:
        self.duty, self.ms = duty, 0

    def advance(self, ms: float) -> None:
        self.ms += int(ms)

    def motors(self) -> tuple[int, int]:
        return self.duty


def test_same_seed_same_faults_and_every_fault_on() -> None:
    a = random_faults(np.random.default_rng(5), 1.2)
    assert a == random_faults(np.random.default_rng(5), 1.2)
    assert a != random_faults(np.random.default_rng(6), 1.2)
    m, c = a.motor, a.camera
    assert m.gain[0] != m.gain[1] and 60 <= m.latency_ms <= 120 and m.slip > 0
    assert c.gain[0] != c.gain[1] and 0 <= c.skew_ms <= 33 and c.exposure_ms > 0 and c.white


def test_weaker_right_wheel_curves_the_robot_to_the_right() -> None:
    world = World(motor_faults=MotorFaults(gain=(1.0, 0.85)))
    for _ in range(1000):
        world.step(0.001, 400, 400)
    assert world.robot.theta > math.radians(5) and world.robot.x_m > 0


def test_battery_sag_and_offset_slow_the_robot() -> None:
    def travelled(faults: MotorFaults) -> float:
        world = World(motor_faults=faults)
        z0 = world.robot.z_m
        for _ in range(3000):
            world.step(0.001, 300, 300)
        return world.robot.z_m - z0

    nominal = travelled(MotorFaults())
    assert travelled(MotorFaults(sag_per_m=1.0)) < 0.95 * nominal
    assert travelled(MotorFaults(offset=(40.0, 40.0))) < 0.8 * nominal


def test_actuation_latency_delays_the_wheels() -> None:
    world = World()
    source = SimSource(world, Board(), latency_ms=100)
    source.run_ms(95)
    assert world.robot.v_left == 0.0
    source.run_ms(20)
    assert world.robot.v_left > 0.0


def test_skew_drops_and_exposure_show_in_the_frames() -> None:
    world = World()
    cam = CameraFaults(gain=(1.0, 0.7), skew_ms=20, drop=0.5, noise=0.0)
    source = SimSource(world, Board((0, 0)), renderer=Renderer(world, cam), reference_frames=0)
    frames = [source.read() for _ in range(12)]
    assert all(round((f.t_right - f.t_left) * 1000) == 20 for f in frames)
    gaps = np.diff([f.t_left for f in frames])
    assert source.dropped > 0 and gaps.max() > 0.05  # a dropped frame leaves a gap
    f = frames[0]
    assert f.right.mean() < 0.8 * f.left.mean()


def test_scene_events_move_add_remove_and_occlude() -> None:
    world = World()
    events = (Event(0.01, "move", 0, z_m=1.0), Event(0.02, "appear", box=(2.8, 0.3, 0.5, 0.3)),
              Event(0.03, "occlude", fraction=0.3, duration_s=0.02), Event(0.04, "vanish", 1))
    source = SimSource(world, Board((0, 0)), events=events)
    source.run_ms(25)
    assert world.boxes[0].z_m == 1.0 and len(world.boxes) == 4
    source.run_ms(10)
    assert world.robot.occlusion == 0.3
    source.run_ms(30)
    assert len(world.boxes) == 3 and world.robot.occlusion == 0.0


def test_motion_blur_smears_the_moving_marker() -> None:
    world = World()
    world.robot.v_left = world.robot.v_right = 0.3
    world.robot.theta = math.radians(60)  # moving sideways across the image
    sharp = Renderer(world, CameraFaults(noise=0.0)).view(0)[0].astype(float)
    blurred = Renderer(world, CameraFaults(noise=0.0, exposure_ms=30)).view(0, blur_px=(
        Renderer(world).image_velocity()[0] * 0.03, 0.0))[0].astype(float)
    u, v, _ = world.marker_truth()
    rows, cols = slice(int(v) - 2, int(v) + 3), slice(int(u) - 25, int(u) + 25)
    edge = np.abs(np.diff(sharp[rows, cols], axis=1)).max()
    assert np.abs(np.diff(blurred[rows, cols], axis=1)).max() < 0.7 * edge


def test_world_faults_default_is_the_nominal_world() -> None:
    f = WorldFaults()
    assert f.motor == MotorFaults() and f.camera == CameraFaults() and not f.events
