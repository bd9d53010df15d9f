"""lane_obstacle works on the box round the map's valid pixels (match_window's box) only: the
same obstacle, depth and size as the whole-map computation it replaced (kept below as the
oracle, verbatim), for boxes anywhere, robots inside them, patches of equal size (a tie: the
whole map's numbering decides)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from host.camera.calibration import Geometry
from host.servo.perception import LaneObstacle, lane_obstacle


def whole_map_lane_obstacle(disp: np.ndarray, geometry: Geometry, depth_m: float, lateral_m: float,
                  direction: int, reach_m: float, reference: np.ndarray | None = None, *,
                  camera_height_m: float, half_width_m: float = 0.12, body_m: float = 0.10,
                  floor_clear_m: float = 0.03, height_m: float = 0.30, tol_px: float = 1.0,
                  min_size_m: float = 0.04, robot_px: int = 4) -> LaneObstacle | None:
    """An object in the robot's lane within reach_m ahead of its front, or None.

    Each valid pixel of disp is a point in the world (x = B (u - cx) / d, z = f B / d, height
    above the floor = camera_height_m - B (v - cy) / d, camera_height_m from the floor fit:
    camera_height). Counted: points in the stretch from body_m to body_m + reach_m ahead of
    the robot's centre (depth_m, direction +1 away from the camera, -1 toward it), within
    half_width_m of its line (lateral_m), higher than floor_clear_m above the floor (the
    floor is never an obstacle, whatever the floor fit says) and below height_m, not within
    robot_px of a pixel at the robot's own disparity (the mismatches along its silhouette),
    and, with a reference map (the scene without the robot, same geometry), nearer than what
    the reference had there by tol_px (the object the robot drives to and the wall are not
    new). The largest connected patch of such pixels, if it covers at least a min_size_m
    square at its depth ((min_size_m f / z)^2 px; at least 25): the obstacle, at its median
    depth. Moving away from the camera the robot hides what is right behind it: a low object
    is seen only beside or above it.

    A result (not None) means: stop now, before it closes; reach_m is the stopping distance at
    the current speed (stopping_distance_m) plus any margin.
    """
    g = geometry
    fb = g.focal_px * g.baseline_m
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(disp) & (disp > 0.5)
        robot = (np.abs(disp - fb / depth_m) < 1.5).astype(np.uint8)
    if robot_px and robot.any():
        k = 2 * robot_px + 1
        ok &= cv2.dilate(robot, np.ones((k, k), np.uint8)) == 0
    vs, us = np.nonzero(ok)
    if vs.size == 0:
        return None
    d = disp[vs, us].astype(np.float64)
    z = fb / d
    x = g.baseline_m * (us - g.cx) / d
    y = camera_height_m - g.baseline_m * (vs - g.cy) / d
    ahead = (z - depth_m) * direction
    keep = ((ahead >= body_m) & (ahead <= body_m + reach_m) & (np.abs(x - lateral_m)
            <= half_width_m) & (y > floor_clear_m) & (y < height_m))
    if reference is not None:
        ref = reference[vs, us]
        with np.errstate(invalid="ignore"):
            keep &= ~(ref >= d - tol_px)  # NaN in the reference: unknown, so new
    if int(keep.sum()) < 25:
        return None
    mask = np.zeros(disp.shape, np.uint8)
    mask[vs[keep], us[keep]] = 1
    _, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    best = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    zm = float(np.median(fb / disp[labels == best]))
    area = int(stats[best, cv2.CC_STAT_AREA])
    if area < max(25.0, (min_size_m * g.focal_px / zm) ** 2):
        return None
    return LaneObstacle(zm, (zm - depth_m) * direction, area)


G = Geometry(213.0, 0.06, 159.5, 119.5)
FB = G.focal_px * G.baseline_m


def scene(rng: np.random.Generator, tie: bool) -> tuple[np.ndarray, np.ndarray, float, float]:
    """A map NaN outside a random box, holding background, the robot and a few objects; its
    reference (the background), the robot's depth and lateral offset."""
    disp = np.full((240, 320), np.nan, np.float32)
    y0, x0 = int(rng.integers(0, 150)), int(rng.integers(0, 220))
    y1, x1 = y0 + int(rng.integers(20, 90)), x0 + int(rng.integers(20, 100))
    z = float(rng.uniform(0.8, 1.6))
    back = FB / (z + 0.9)
    disp[y0:y1, x0:x1] = back + rng.normal(0, 0.3, (y1 - y0, x1 - x0))
    ref = np.full((240, 320), back, np.float32)
    ry, rx = int(rng.integers(y0, y1)), int(rng.integers(x0, x1))
    disp[ry:ry + 12, rx:rx + 8] = FB / z  # the robot's own disparity
    near = FB / (z + 0.2)
    for k in range(int(rng.integers(1, 4))):
        h, w = (7, 7) if tie else (int(rng.integers(3, 15)), int(rng.integers(3, 15)))
        py, px = int(rng.integers(y0, y1)), int(rng.integers(x0, x1))
        disp[py:py + h, px:px + w] = near + 0.05 * k
    disp[(rng.random(disp.shape) < 0.05)] = np.nan  # invalid matches
    lateral = G.baseline_m * ((x0 + x1) / 2 - G.cx) / near
    return disp, ref, z, lateral


@pytest.mark.parametrize("tie", [False, True])
def test_the_boxed_map_finds_what_the_whole_map_found(tie: bool) -> None:
    rng = np.random.default_rng(7 if tie else 8)
    found = 0
    for _ in range(300):
        disp, ref, z, lateral = scene(rng, tie)
        for reference in (ref, None):
            kw = dict(camera_height_m=0.35 + float(rng.uniform(-0.2, 0.2)),
                      half_width_m=0.5, height_m=2.0, floor_clear_m=-2.0, min_size_m=0.01)
            want = whole_map_lane_obstacle(disp, G, z, lateral, 1, 0.6, reference, **kw)
            got = lane_obstacle(disp, G, z, lateral, 1, 0.6, reference, **kw)
            assert got == want
            found += want is not None
    assert found > 100  # most scenes hold an obstacle, not only "none" twice
