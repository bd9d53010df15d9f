"""The camera's height above the floor measured by the floor fit (perception.camera_height), not
assumed: a rig set up higher than the simulation's 0.25 m sees a low box in its lane, and the
servo's reference phase takes the height it measured. (Above about 0.33 m in the default
scene the boxes fill more of the lowest rows than the floor and fit_floor fits them: the
floor fit's own limit, not the height's.)"""

from __future__ import annotations

import numpy as np
import pytest

from host.servo.perception import (
    camera_height,
    fit_floor,
    lane_obstacle,
    lane_window,
    match_exposure,
    match_window,
)
from host.sim.renderer import Renderer
from host.sim.run import Setup, simulation
from host.sim.world import Box, World
from host.stereo.matcher import compute_disparity
from host.stereo.params import MatcherParams

PARAMS = MatcherParams(block_size=9, num_disparities=48, border="clip")
BOXES = (Box(1.2, -0.50, -0.18, 0.38), Box(1.8, 0.22, 0.55, 0.30), Box(2.4, 0.60, 0.95, 0.55))


def _reference(height_m: float) -> tuple[World, Renderer, np.ndarray]:
    world = World(seed=5, boxes=BOXES, height_m=height_m)
    renderer = Renderer(world, seed=5)
    f = renderer.frame(with_robot=False)
    return world, renderer, compute_disparity(f.left, match_exposure(f.left, f.right), PARAMS)


@pytest.mark.parametrize("height_m", [0.15, 0.25, 0.32])
def test_the_floor_fit_gives_the_cameras_height(height_m: float) -> None:
    world, _, ref = _reference(height_m)
    floor = fit_floor(ref)
    assert floor is not None
    assert camera_height(floor, world.geometry.baseline_m) == pytest.approx(height_m, rel=0.02)


def test_a_low_box_in_the_lane_of_a_higher_rig_is_seen_with_the_measured_height() -> None:
    """A rig at 0.32 m, a box 8 cm tall put down 25 cm ahead of the robot. Measured from an
    assumed 0.25 m every point reads 7 cm lower: the box sinks below the floor's clearance
    (3 cm) and the lane reads clear."""
    world, renderer, ref = _reference(0.32)
    floor = fit_floor(ref)
    assert floor is not None
    measured = camera_height(floor, world.geometry.baseline_m)
    r = world.robot
    r.z_m, r.x_m = 0.8, 0.0
    world.boxes = (*BOXES, Box(r.z_m + 0.25, -0.15, 0.15, 0.08))
    f = renderer.frame()
    left, right = f.left, match_exposure(f.left, f.right)
    g, reach = world.geometry, 0.3

    def watch(h: float):
        win = lane_window(g, world.size, r.z_m, r.x_m, 1, reach, camera_height_m=h)
        assert win is not None
        disp = match_window(left, right, PARAMS, win)
        return lane_obstacle(disp, g, r.z_m, r.x_m, 1, reach, ref, camera_height_m=h)

    hit = watch(measured)
    assert hit is not None and abs(hit.ahead_m - 0.25) < 0.03
    assert watch(0.25) is None  # the old assumption misses it


def test_the_servo_takes_the_height_its_reference_measured() -> None:
    with simulation(Setup(start_z_m=1.9, seed=2), reference=False) as sim:
        sim.world.height_m = 0.32
        sim.servo.reference()
        assert sim.servo.camera_height_m == pytest.approx(0.32, rel=0.02)
