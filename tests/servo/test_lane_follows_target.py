"""The lane's reference follows a target that moved (host/servo/tracker.py with_target): the
target's own edge, pushed into columns where the reference saw the wall, is no new object in
the lane; a box put down beside it, or nearer than its face, still is. Constructed maps through
perception.lane_obstacle, the lane's own test."""

from __future__ import annotations

import numpy as np

from host.camera.geometry import Geometry
from host.servo.perception import Target, lane_obstacle
from host.servo.tracker import with_target

G = Geometry(260.0, 0.06, 160.0, 120.0)
CAMERA_H = 0.25
EXTENT = (-0.50, -0.18)  # the target's lateral extent (m), as the reference measured it


def _put(disp: np.ndarray, z: float, x0: float, x1: float, height: float) -> None:
    """A face at depth z (m) from x0 to x1 (m), from the floor to height (m)."""
    d = G.disparity_px(z)
    u0, u1 = (int(round(G.cx + G.focal_px * x / z)) for x in (x0, x1))
    v0, v1 = (int(round(G.cy + G.focal_px * (CAMERA_H - y) / z)) for y in (height, 0.0))
    disp[max(0, v0):v1, max(0, u0):u1] = d


def _scene(target_z: float) -> np.ndarray:
    disp = np.full((240, 320), G.disparity_px(3.0), np.float32)  # the wall
    _put(disp, target_z, *EXTENT, 0.38)
    return disp


def _target(z: float) -> Target:
    """The target's region as the re-measure (object_extent) gives it: its rows."""
    v0 = int(round(G.cy + G.focal_px * (CAMERA_H - 0.38) / z))
    v1 = int(round(G.cy + G.focal_px * CAMERA_H / z))
    return Target(G.disparity_px(z), 5000, (0, v0, 120, v1 - v0), 0.1)


def _lane(disp: np.ndarray, reference: np.ndarray):
    # the robot at 1.30 m, 8 cm left of the axis, driving toward the camera (target nearer)
    return lane_obstacle(disp, G, 1.30, -0.08, -1, 0.25, reference, camera_height_m=CAMERA_H)


def test_the_target_pushed_farther_is_not_an_object_in_the_lane():
    """Pushed from 1.02 to 1.12 m, its edge at x -0.18 lies inside the robot's 12 cm lane in
    columns that showed the wall: on the reference phase's map the lane reports it (seed 12's
    trial 482 waited 16 s on it); on the reference with the target where it stands now, not."""
    reference, now = _scene(1.02), _scene(1.12)
    assert _lane(now, reference) is not None  # the fault as it was
    followed = with_target(reference, _target(1.12), EXTENT, G.baseline_m, G.cx)
    assert _lane(now, followed) is None


def test_a_box_beside_the_moved_target_or_nearer_than_its_face_is_still_in_the_lane():
    reference = _scene(1.02)
    followed = with_target(reference, _target(1.12), EXTENT, G.baseline_m, G.cx)
    beside = _scene(1.12)
    _put(beside, 1.12, -0.17, -0.05, 0.2)  # at the target's depth, in the lane beside it
    found = _lane(beside, followed)
    assert found is not None and abs(found.depth_m - 1.12) < 0.03
    nearer = _scene(1.12)
    _put(nearer, 1.0, -0.30, -0.12, 0.2)  # 12 cm in front of its face, reaching the lane
    found = _lane(nearer, followed)
    assert found is not None and abs(found.depth_m - 1.0) < 0.03
