"""The object as it is and the lane watched: object_extent grows the target's region to the
whole object at its depth; lane_obstacle sees a new object in the lane within reach, and not
the floor, the target beside the lane or the robot itself; the fixed objects' floor cells and
what the body's path and the view's edge make of them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from host.servo.perception import (
    Target,
    fit_floor,
    fixed_cells,
    fixed_in_path,
    in_view,
    lane_obstacle,
    lane_window,
    match_exposure,
    match_window,
    nearest_object,
    object_extent,
    stopping_distance_m,
    without_floor,
)
from host.sim.faults import CameraFaults
from host.sim.renderer import Renderer
from host.sim.world import Box, World
from host.stereo.matcher import compute_disparity
from host.stereo.params import MatcherParams

PARAMS = MatcherParams(block_size=9, num_disparities=48, border="clip")


def slanted_box_map(seed: int = 0) -> np.ndarray:
    """A wall at 8 px, a box of columns 40..143 (104 px) whose disparity falls from 21.6 to
    20.3 px across it (a slant, or a calibration's residual), with noise."""
    rng = np.random.default_rng(seed)
    disp = np.full((240, 320), 8.0, np.float32)
    cols = np.arange(40, 144)
    disp[70:200, 40:144] = 21.6 - 1.3 * (cols - 40) / 103
    return disp + rng.normal(0, 0.15, disp.shape).astype(np.float32)


def test_the_extent_is_the_whole_box_not_the_part_at_the_first_level() -> None:
    disp = slanted_box_map()
    first = nearest_object(disp, 768)
    assert first.bbox[2] < 60  # nearest_object's region: the nearest part only
    full = object_extent(disp, first)
    x, y, w, h = full.bbox
    assert abs(x - 40) <= 2 and abs(x + w - 144) <= 3 and abs(y - 70) <= 3 and abs(h - 130) <= 4
    assert full.disparity == first.disparity and full.area > 2 * first.area


def test_the_extent_does_not_run_along_the_floor_or_into_the_wall() -> None:
    """The floor at the box's depth fills a few rows across the whole picture; it does not
    widen the object."""
    disp = slanted_box_map()
    target = nearest_object(disp, 768)  # found with the floor removed, as the servo does
    rows = np.arange(240, dtype=np.float32)[:, None]
    floor = 0.24 * (rows - 120)
    disp[200:] = np.broadcast_to(floor[200:], disp[200:].shape)  # reaches 21 px at row 207
    full = object_extent(disp, target)  # on a map where it was not removed at all
    x, _, w, _ = full.bbox
    assert abs(x - 40) <= 2 and abs(x + w - 144) <= 3


def test_the_extent_of_a_rendered_box_reaches_its_true_side() -> None:
    world = World(seed=3, boxes=(Box(1.5, -0.50, -0.18, 0.38), Box(2.4, 0.60, 0.95, 0.55)))
    renderer = Renderer(world, seed=3)
    f = renderer.frame(with_robot=False)
    disp = compute_disparity(f.left, match_exposure(f.left, f.right), PARAMS)
    disp = without_floor(disp, fit_floor(disp))
    full = object_extent(disp, nearest_object(disp, 768))
    u1 = world.geometry.cx + world.geometry.focal_px * -0.18 / 1.5
    x, _, w, _ = full.bbox
    assert abs(x + w - u1) <= 3


def test_a_target_with_nothing_at_its_depth_is_left_as_it_was() -> None:
    disp = np.full((240, 320), 8.0, np.float32)
    t = Target(20.0, 900, (40, 70, 30, 30), 0.2)
    assert object_extent(disp, t) == t


def test_the_stopping_distance_grows_with_speed() -> None:
    assert stopping_distance_m(0.0) == pytest.approx(0.10)
    assert stopping_distance_m(0.3) == pytest.approx(0.10 + 0.3 * 0.33)
    assert stopping_distance_m(-0.3) == stopping_distance_m(0.3)


def scene(robot_z: float, robot_x: float = 0.0, lane_box: float | None = None,
          width: float = 0.3):
    """A rendered pair with the robot, and the reference map (no robot, no lane box)."""
    boxes = (Box(1.2, -0.50, -0.18, 0.38), Box(1.8, 0.22, 0.55, 0.30),
             Box(2.4, 0.60, 0.95, 0.55))
    world = World(seed=5, boxes=boxes)
    renderer = Renderer(world, CameraFaults(noise=2.0), seed=5)
    f = renderer.frame(with_robot=False)
    reference = compute_disparity(f.left, match_exposure(f.left, f.right), PARAMS)
    if lane_box is not None:
        world.boxes = (*boxes, Box(robot_z + lane_box, robot_x - width / 2,
                                   robot_x + width / 2, 0.3))
    world.robot.z_m, world.robot.x_m = robot_z, robot_x
    f = renderer.frame()
    return world, f.left, match_exposure(f.left, f.right), reference


def watch(world: World, left, right, reference, reach: float, direction: int = 1):
    g, r = world.geometry, world.robot
    win = lane_window(g, world.size, r.z_m, r.x_m, direction, reach,
                      camera_height_m=world.height_m)
    assert win is not None
    disp = match_window(left, right, PARAMS, win)
    return lane_obstacle(disp, g, r.z_m, r.x_m, direction, reach, reference,
                         camera_height_m=world.height_m)


@pytest.mark.parametrize("width", [0.3, 0.6])
def test_a_box_put_down_29_cm_ahead_is_seen_within_reach(width: float) -> None:
    world, left, right, ref = scene(0.7, lane_box=0.29, width=width)
    hit = watch(world, left, right, ref, reach=0.3)
    assert hit is not None and abs(hit.ahead_m - 0.29) < 0.03
    assert watch(world, left, right, ref, reach=0.12) is None  # beyond a short reach


def test_a_clear_lane_shows_no_obstacle_floor_target_or_robot() -> None:
    """Nothing new in the lane: not the floor ahead, not the box beside the lane at 1.2 m,
    not the robot's own silhouette. (A rig pitched since the reference puts the floor's
    heights off by B rows / d: that is camera_moved's to catch.)"""
    for z, x in ((0.7, 0.0), (1.0, 0.0), (1.05, 0.0)):
        world, left, right, ref = scene(z, x)
        assert watch(world, left, right, ref, reach=0.4) is None, (z, x)
        assert watch(world, left, right, None, reach=0.4) is None or z > 0.9  # the wall, far


def test_toward_the_camera_the_stretch_nearer_than_the_robot_is_watched() -> None:
    world, left, right, ref = scene(1.3, lane_box=-0.35)
    hit = watch(world, left, right, ref, reach=0.4, direction=-1)
    assert hit is not None and abs(hit.ahead_m - 0.35) < 0.04
    assert watch(world, left, right, ref, reach=0.4, direction=1) is None
    # nearer than the robot the floor is in view: it is not an obstacle, reference or not
    world, left, right, ref = scene(1.3)
    assert watch(world, left, right, None, reach=0.4, direction=-1) is None


def test_no_window_where_the_stretch_reaches_the_camera() -> None:
    g = World().geometry
    assert lane_window(g, (320, 240), 0.4, 0.0, -1, 0.3, camera_height_m=0.25) is None
    win = lane_window(g, (320, 240), 0.8, 0.0, 1, 0.3, camera_height_m=0.25)
    assert win is not None and win.min_disparity <= win.d_far < win.d_near <= (
        win.min_disparity + win.num_disparities)
    assert math.isclose(win.d_near, g.focal_px * g.baseline_m / 0.9)


def test_what_the_reference_showed_is_not_new() -> None:
    """A band that grazes the target box's side (at -0.18 m) sees the box; with the reference
    map the box is known, not a new object in the lane."""
    world, left, right, ref = scene(0.95, -0.08)
    assert watch(world, left, right, ref, reach=0.3) is None
    grazed = watch(world, left, right, None, reach=0.3)
    assert grazed is not None and abs(grazed.depth_m - 1.2) < 0.04


def test_fixed_cells_are_the_boxes_faces_not_the_floors_mismatches() -> None:
    """The default scene rendered without the robot: fixed_cells finds the faces of the boxes
    at 1.2 m (-0.50..-0.18; left of -0.4 m outside the search range) and 1.8 m (0.22..0.55),
    and nothing nearer than the first box. The near floor (beyond the 48 px search range
    nearer than 0.53 m) is mismatched into small patches of points up to 25 cm high at
    0.55-1.05 m, in the robot's path; an upright face rises higher and fills its cells more."""
    world = World(seed=3)
    f = Renderer(world, seed=3).frame(with_robot=False)
    disp = compute_disparity(f.left, match_exposure(f.left, f.right), PARAMS)
    cells = fixed_cells(disp, world.geometry, camera_height_m=world.height_m)
    assert not (cells[:, 0] < 1.1).any(), cells[cells[:, 0] < 1.1]
    box = cells[np.abs(cells[:, 0] - 1.8) < 0.05]
    assert box[:, 1].min() < 0.25 and box[:, 1].max() > 0.50
    target = cells[np.abs(cells[:, 0] - 1.2) < 0.05]
    assert target[:, 1].min() < -0.35 and target[:, 1].max() > -0.21  # its left is unmatched


def test_fixed_in_path_sees_a_cell_where_the_body_goes_within_reach() -> None:
    cells = np.array([[1.81, 0.23], [1.81, 0.25]])
    # toward the camera from 2.2 m on a line 15 cm right of centre: the body (9 cm each side)
    # reaches 0.24 m, over the cell at 0.23 (0.22-0.24)
    assert fixed_in_path(cells, 2.2, 0.15, -1, 0.4, 0.09) == pytest.approx(0.39)
    assert fixed_in_path(cells, 2.2, 0.15, -1, 0.2, 0.09) is None  # beyond reach
    assert fixed_in_path(cells, 2.2, 0.10, -1, 0.4, 0.09) is None  # clear of its side
    assert fixed_in_path(cells, 2.2, 0.15, 1, 0.4, 0.09) is None  # behind the robot
    # a cell where the robot stands is not in its way: the sighting is of a look-alike that
    # stood in the reference (seed 8 trial 45: a decoy robot's body, "0.00 m ahead")
    assert fixed_in_path(cells, 1.83, 0.24, -1, 0.4, 0.09) is None


def test_in_view_wants_the_whole_ring_inside_after_the_run_toward_the_camera() -> None:
    assert in_view(160, 170, 54, (320, 240))
    assert not in_view(298, 150, 46, (320, 240))  # the ring cut by the right edge
    assert in_view(250, 150, 46, (320, 240))
    assert not in_view(250, 150, 46, (320, 240), scale=1.3)  # nearer: it grows out of view
