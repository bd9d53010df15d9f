"""Perception on synthetic scenes: the nearest box (floor removed, speckle ignored) and the
marker's centres."""

from __future__ import annotations

import math

import numpy as np
import pytest

from host.servo.marker import find_marker
from host.servo.perception import reference_target
from host.sim.faults import CameraFaults
from host.sim.renderer import Renderer
from host.sim.world import Box, World
from host.stereo import MatcherParams, compute_disparity

PARAMS = MatcherParams(block_size=9, num_disparities=48, border="clip")
LAYOUTS = [
    (Box(1.2, -0.50, -0.18, 0.38), Box(1.8, 0.22, 0.55, 0.30), Box(2.4, 0.60, 0.95, 0.55)),
    (Box(2.0, -0.60, -0.20, 0.50), Box(1.4, 0.30, 0.60, 0.25), Box(2.6, -0.1, 0.2, 0.6)),
    (Box(1.7, -0.2, 0.1, 0.4), Box(1.1, 0.15, 0.38, 0.35), Box(1.5, -0.7, -0.45, 0.3)),
]


@pytest.mark.parametrize("boxes", LAYOUTS)
@pytest.mark.parametrize("speckle", [0.0, 0.02])
def test_nearest_object_is_the_nearest_box(boxes, speckle: float) -> None:
    world = World(boxes=boxes, seed=7)
    renderer = Renderer(world, seed=7)
    rng = np.random.default_rng(1)
    disps = []
    for _ in range(3):
        frame = renderer.frame(with_robot=False)
        d = compute_disparity(frame.left, frame.right, PARAMS)
        spots = rng.random(d.shape) < speckle  # speckle: single pixels with wild disparities
        d[spots] = rng.uniform(30, 47, spots.sum())
        disps.append(d)
    target, floor = reference_target(disps, min_area=320 * 240 // 100)
    near = world.nearest_box()
    truth = world.geometry.disparity_px(near.z_m)
    assert target.disparity == pytest.approx(truth, abs=0.3)
    x, y, w, h = target.bbox
    u0, _ = world.project(near.x0_m, 0, near.z_m)
    u1, _ = world.project(near.x1_m, 0, near.z_m)
    assert u0 - 3 <= x + w / 2 <= u1 + 3  # the region is the nearest box's front face
    assert floor is not None and floor.slope == pytest.approx(0.24, abs=0.01)


@pytest.mark.parametrize("z", [0.7, 1.1, 1.6, 2.2, 2.8])
@pytest.mark.parametrize("side", [-0.2, 0.0, 0.2])
def test_marker_centres_within_half_a_pixel_on_noisy_renders(z: float, side: float) -> None:
    world = World(seed=3, boxes=())  # no box: at some of these places one would hide the card
    renderer = Renderer(world, CameraFaults(noise=5.0), seed=3)
    world.robot.z_m, world.robot.x_m = z, side * z  # from the left edge to the right one
    world.robot.theta = math.radians(12)
    frame = renderer.frame()
    pair = find_marker(frame.left, frame.right, radius_m=0.03, baseline_m=0.06)
    u, v, d = world.marker_truth()
    assert pair is not None
    assert abs(pair.left.u - u) < 0.5 and abs(pair.left.v - v) < 0.5
    assert abs(pair.right.u - (u - d)) < 0.5
    assert abs(pair.disparity - d) < 0.25


def test_aruco_marker_gives_the_disparity_of_its_two_views() -> None:
    import cv2

    tag = cv2.aruco.generateImageMarker(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50),
                                        7, 60)
    rng = np.random.default_rng(0)
    base = rng.integers(90, 170, (240, 320), dtype=np.uint8)
    left, right = base.copy(), base.copy()
    padded = cv2.copyMakeBorder(tag, 10, 10, 10, 10, cv2.BORDER_CONSTANT, value=255)
    left[90:170, 150:230] = padded
    right[90:170, 130:210] = padded  # 20 px to the left in the right view
    pair = find_marker(left, right, kind="aruco")
    assert pair is not None and pair.disparity == pytest.approx(20.0, abs=0.05)
    assert pair.left.u == pytest.approx(189.5, abs=0.6) and pair.left.v == pytest.approx(129.5,
                                                                                         abs=0.6)
