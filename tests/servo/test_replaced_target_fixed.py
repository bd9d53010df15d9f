"""A target a nearer object replaced while it still stands stays a fixed object (host/servo/
tracker.py with_replaced, called by the loop on a retarget; issue 23). Seed 14's trial 446 with a
sooner acquisition (536032e): the box moved farther (1.50 -> 1.686 m, toward the robot), the lane's
reference followed it there (not new), then a look-alike nearer, beside the robot's line, became the
target: the keep-out became its extent alone and the fixed objects' cells still had the box where
the reference saw it, so nothing kept the robot out of the box's face (unsafe, "hit the object").
Constructed maps through the controller's own fixed-object checks (others, fixed_in_path)."""

from __future__ import annotations

import numpy as np

from host.camera.geometry import Geometry
from host.servo.controller import Controller
from host.servo.perception import Target, fixed_cells, fixed_in_path
from host.servo.tracker import with_replaced

G = Geometry(260.0, 0.06, 160.0, 120.0)
CAMERA_H = 0.25
BOX = (-0.10, 0.10)  # the target box's lateral extent (m), across the robot's line (x 0)
LOOK_ALIKE = (0.20, 0.36)  # the nearer object beside the line that replaced it


def _put(disp: np.ndarray, z: float, x0: float, x1: float, height: float) -> tuple[int, ...]:
    """A face at depth z (m) from x0 to x1 (m), from the floor to height (m); its region."""
    d = G.disparity_px(z)
    u0, u1 = (int(round(G.cx + G.focal_px * x / z)) for x in (x0, x1))
    v0, v1 = (int(round(G.cy + G.focal_px * (CAMERA_H - y) / z)) for y in (height, 0.0))
    disp[v0:v1, u0:u1] = d
    return u0, v0, u1 - u0, v1 - v0


def _wall() -> np.ndarray:
    return np.full((240, 320), G.disparity_px(3.0), np.float64)


def _controller(now: np.ndarray, reference: np.ndarray, box: Target | None) -> Controller:
    """The controller after the retarget onto the look-alike: its extent the keep-out, the
    fixed objects those of the reference (and, given box, the replaced target's now)."""
    c = Controller(1.60)
    c.keep_out = LOOK_ALIKE
    c.fixed = fixed_cells(reference, G, camera_height_m=CAMERA_H, cell_m=c.cfg.cell_m)
    if box is not None:
        c.fixed = with_replaced(c.fixed, now, box, G, camera_height_m=CAMERA_H,
                                cell_m=c.cfg.cell_m)
    return c


def _ahead(c: Controller) -> float | None:
    # the robot at 2.0 m on x 0, driving toward the camera: its stopping stretch reaches 1.60 m
    cfg = c.cfg
    return fixed_in_path(c.others(), 2.0, 0.0, -1, 0.30, cfg.half_width_m + cfg.block_margin_m / 2,
                         cfg.cell_m)


def _scenes() -> tuple[np.ndarray, np.ndarray, Target]:
    reference, now = _wall(), _wall()
    _put(reference, 1.50, *BOX, 0.20)
    bx, by, bw, bh = _put(now, 1.686, *BOX, 0.20)  # the box moved toward the robot
    _put(now, 1.60, *LOOK_ALIKE, 0.15)
    return reference, now, Target(G.disparity_px(1.686), bw * bh, (bx, by, bw, bh), 0.05)


def test_the_replaced_target_still_standing_is_in_the_path() -> None:
    reference, now, box = _scenes()
    assert _ahead(_controller(now, reference, None)) is None  # the fault as it was: unseen
    ahead = _ahead(_controller(now, reference, box))
    assert ahead is not None and 2.0 - ahead < 1.75, ahead  # its face, ahead of the robot


def test_a_replaced_target_seen_through_adds_nothing() -> None:
    reference, now, box = _scenes()
    gone = _wall()
    _put(gone, 1.60, *LOOK_ALIKE, 0.15)
    c = _controller(gone, reference, box)
    assert len(c.fixed) == len(fixed_cells(reference, G, camera_height_m=CAMERA_H,
                                           cell_m=c.cfg.cell_m))
    assert _ahead(c) is None
