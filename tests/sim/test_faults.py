"""The simulated world fails like hardware, and does so reproducibly: each fault model has the
effect it names, and the same seed gives the same faults."""

from __future__ import annotations

import math

import numpy as np

from host.sim.faults import (
    HAZARDS,
    CameraFaults,
    Event,
    MotorFaults,
    WorldFaults,
    random_faults,
)
from host.sim.renderer import Renderer
from host.sim.source import SimSource
from host.sim.world import Person, Robot, World


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


# ------------------------------------------------------------------ issue 23's hazards


def test_hazards_are_drawn_named_from_their_own_stream() -> None:
    """Each hazard is drawn by some seed, under its own name; drawing them leaves the other
    faults, and the caller's next draws, as they were without them."""
    seen: set[str] = set()
    for seed in range(200):
        a, b = np.random.default_rng(seed), np.random.default_rng(seed)
        with_h, without = random_faults(a, 1.2), random_faults(b, 1.2, hazards=0.0)
        assert a.random() == b.random()
        assert (with_h.motor, with_h.camera, with_h.link) == (without.motor, without.camera,
                                                              without.link)
        extra = [e for e in with_h.events if e not in without.events]
        assert all(e.kind in HAZARDS for e in extra)
        seen |= {e.kind for e in extra}
    assert seen == set(HAZARDS)


def source_with(*events: Event, robot_z: float = 0.9, camera: CameraFaults | None = None,
                duty: tuple[int, int] = (0, 0)) -> SimSource:
    world = World()
    world.robot.z_m = robot_z
    renderer = Renderer(world, camera or CameraFaults(noise=0.0))
    return SimSource(world, Board(duty), renderer=renderer, events=events, reference_frames=0)


def test_facing_places_the_robot_with_its_heading() -> None:
    source = source_with(Event(0.0, "facing", angle_deg=180))
    source.read()
    source.read()
    assert source.world.robot.theta == math.pi


def test_a_lane_box_appears_ahead_of_the_moving_robot_and_is_taken_away() -> None:
    source = source_with(Event(0.5, "lane-box", ahead_m=0.29, width_m=0.6, duration_s=0.5),
                         duty=(500, 500))
    source.run_ms(499)
    assert len(source.world.boxes) == 3
    source.run_ms(2)
    r, box = source.world.robot, source.world.boxes[-1]
    assert abs(box.z_m - r.z_m - 0.29) < 0.005 and abs((box.x0_m + box.x1_m) / 2 - r.x_m) < 1e-3
    assert abs(box.x1_m - box.x0_m - 0.6) < 1e-9
    source.run_ms(500)
    assert len(source.world.boxes) == 3


def test_a_knock_pitches_the_view_by_its_angle() -> None:
    """Tilted down by 2 degrees, the scene moves up by f tan(2 deg) rows (14.9 px here), and
    the rows it brings in are drawn, not repeated."""
    source = source_with(Event(0.05, "knock", angle_deg=2.0))
    before = source.read().left.astype(float)
    for _ in range(3):
        after = source.read().left.astype(float)
    expect = 426.0 * math.tan(math.radians(2.0))
    cols = slice(40, 280)

    def mismatch(shift: int) -> float:
        return float(np.abs(before[60 + shift:180 + shift, cols] - after[60:180, cols]).mean())

    best = min(range(25), key=mismatch)
    assert abs(best - expect) <= 1.0 and mismatch(best) < 0.3 * mismatch(0)
    top = after[:10]
    assert np.abs(np.diff(top, axis=0)).mean() > 5  # the wall goes on above, no streaks


def test_a_frozen_sensor_repeats_its_image_with_or_without_its_stamps() -> None:
    for stamps in (True, False):
        source = source_with(Event(0.1, "freeze", sensor=1, stamps=stamps, duration_s=0.3),
                             duty=(500, 500), camera=CameraFaults(noise=2.0))
        frames = [source.read() for _ in range(16)]
        during = [f for f in frames if 0.15 < f.t_left < 0.38]
        assert len(during) >= 5
        assert all(np.array_equal(f.right, during[0].right) for f in during)
        assert not np.array_equal(during[0].left, during[1].left)
        advancing = np.diff([f.t_right for f in during]) > 0
        assert advancing.all() if stamps else not advancing.any()
        assert not np.array_equal(frames[-1].right, frames[-2].right)  # it ends


def test_flicker_bands_the_rows_differently_in_the_two_views() -> None:
    """+-20 % at 100 Hz read by rolling shutters 10 ms apart: the row means swing by about
    the amplitude, and the right view's bands are not the left's."""
    plain, lit = source_with(), source_with(Event(0.0, "flicker", fraction=0.2, gap_ms=7.0))
    plain.read(), lit.read()  # the first frame comes before any event
    plain, lit = plain.read(), lit.read()
    ratio_l = lit.left.mean(axis=1) / plain.left.mean(axis=1)
    ratio_r = lit.right.mean(axis=1) / plain.right.mean(axis=1)
    assert 0.75 < ratio_l.min() < 0.85 and 1.15 < ratio_l.max() < 1.25
    assert np.abs(ratio_l - ratio_r).max() > 0.2


def test_behind_the_object_half_the_card_is_hidden_by_its_edge() -> None:
    source = source_with(Event(0.0, "behind", 0, z_m=1.6, fraction=0.5))
    source.read()
    f = source.read()
    r = source.world.robot
    assert r.z_m == 1.6
    u, v, _ = source.world.marker_truth()
    ry = 426.0 * r.marker_radius_m / r.z_m
    rows = slice(int(v - ry), int(v + ry) + 1)
    dark_left = f.left[rows, int(u - 2 * ry):int(u) - 1] < 30  # the disc is 25, no noise
    dark_right = f.left[rows, int(u) + 1:int(u + 2 * ry)] < 30
    assert dark_left.sum() == 0 and dark_right.sum() > 10  # the disc's left half is behind


def test_a_walker_crosses_the_view_in_front_of_the_robot() -> None:
    source = source_with(Event(0.05, "walker", z_m=0.6, x_m=-0.3, speed_mps=1.0,
                               duration_s=1.0))
    source.run_ms(300)
    p = source.world.people[0]
    assert abs(p.x_m - (-0.3 + 0.25)) < 0.01 and p.z_m == 0.6
    _, disp = source.renderer.view(0)
    col = int(160 + 426 * p.x_m / p.z_m)
    assert abs(disp[100, col] - 426 * 0.06 / 0.6) < 0.01  # the person, in front of all
    source.run_ms(800)
    assert source.world.people == ()


def test_a_smooth_floor_lets_the_wheels_slip() -> None:
    def travelled(*events: Event) -> float:
        source = source_with(*events, duty=(500, 500))
        z0 = source.world.robot.z_m
        source.run_ms(1500)
        return source.world.robot.z_m - z0

    assert travelled(Event(0.0, "slip", traction=(0.5, 0.5), duration_s=1.5)) < \
        0.6 * travelled()
    assert travelled(Event(0.0, "slip", traction=(0.5, 0.5), duration_s=0.5)) > \
        0.6 * travelled()  # and grips again after it


def test_a_burst_of_dropped_frames_leaves_a_gap_of_its_length() -> None:
    source = source_with(Event(0.2, "drop-burst", duration_s=0.5))
    stamps = [source.read().t_left for _ in range(12)]
    gaps = np.diff(stamps)
    assert 0.5 <= gaps.max() <= 0.57 and source.dropped >= 15


def test_a_decoy_shows_a_second_marker_at_its_depth() -> None:
    source = source_with(Event(0.0, "decoy", z_m=1.6, x_m=0.35))
    source.read()
    f = source.read()
    d = source.world.decoys[0]
    u, v, disp = source.world.marker_truth(d)
    assert f.left[int(round(v)), int(round(u))] < 60  # its dark disc
    assert f.right[int(round(v)), int(round(u - disp))] < 60


def test_the_world_says_when_the_robot_bumps_into_someone() -> None:
    world = World()
    world.robot.z_m, world.robot.x_m = 1.0, 0.0
    world.people = (Person(0.25, 1.05),)
    assert world.bumped_into() == "a person"
    world.people = (Person(0.35, 1.05),)  # 0.225 + 0.08 from its centre: clear
    assert world.bumped_into() == ""
    world.decoys = (Robot(x_m=0.1, z_m=1.0),)
    assert world.bumped_into() == "another robot"


def test_a_knock_leaves_the_scene_as_it_was_only_seen_from_elsewhere() -> None:
    """The rows a pitched rig sees beyond the view are added without changing the view's own
    (target boxes at 1.0-1.5 m: at 1.3 m a floor reaching lower once painted over the box)."""
    from host.sim.world import Box

    for z in (1.0, 1.3, 1.5):
        world = World(seed=3, boxes=(Box(z, -0.50, -0.18, 0.38), Box(1.8, 0.22, 0.55, 0.30)))
        r = Renderer(world, seed=3)
        for side in (0, 1):
            plain, padded = r._render_static(0)[side][0], r._render_static(16)[side][0]
            assert np.abs(padded[16:16 + 240] - plain).max() < 0.01
