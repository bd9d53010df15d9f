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


def _controller(now: np.ndarray, reference: np.ndarray, box: Target | None,
                look_alike: tuple[float, float] = LOOK_ALIKE) -> Controller:
    """The controller after the retarget onto the look-alike: its extent the keep-out, the
    fixed objects those of the reference (and, given box, the replaced target's now, kept as
    the loop keeps them)."""
    c = Controller(1.60)
    c.keep_out = look_alike
    c.fixed = fixed_cells(reference, G, camera_height_m=CAMERA_H, cell_m=c.cfg.cell_m)
    if box is not None:
        c.kept = with_replaced(c.kept, now, box, G, camera_height_m=CAMERA_H,
                               cell_m=c.cfg.cell_m)
    return c


def _ahead(c: Controller, x: float = 0.0, z: float = 2.0) -> float | None:
    # the robot at z (m) on x, driving toward the camera: its stopping stretch reaches z - 0.30
    cfg = c.cfg
    return fixed_in_path(c.others(), z, x, -1, 0.30, cfg.half_width_m + cfg.block_margin_m / 2,
                         cfg.cell_m)


def _scenes(box: tuple[float, float] = BOX, look_alike: tuple[float, float] = LOOK_ALIKE
            ) -> tuple[np.ndarray, np.ndarray, Target]:
    reference, now = _wall(), _wall()
    _put(reference, 1.50, *box, 0.20)
    bx, by, bw, bh = _put(now, 1.686, *box, 0.20)  # the box moved toward the robot
    _put(now, 1.60, *look_alike, 0.15)
    return reference, now, Target(G.disparity_px(1.686), bw * bh, (bx, by, bw, bh), 0.05)


def test_the_replaced_target_still_standing_is_in_the_path() -> None:
    reference, now, box = _scenes()
    assert _ahead(_controller(now, reference, None)) is None  # the fault as it was: unseen
    ahead = _ahead(_controller(now, reference, box))
    assert ahead is not None and 2.0 - ahead < 1.75, ahead  # its face, ahead of the robot


def test_the_replaced_target_is_an_obstacle_across_the_new_targets_band() -> None:
    """The look-alike in front of the box and across part of it (the review's case): the box's
    face lies within the new keep-out's band and less than own_depth_m behind its face, where
    others() takes cells for the target's own; the replaced region must stay an obstacle there:
    a robot at 1.85 m on x 0.15, in both bands, driving toward the camera, would meet the box's
    face at 1.686 m (hidden behind the look-alike from x 0.05: its region's cells are the
    look-alike's, within the 6 % of the box's disparity, 1.59 m)."""
    box, look_alike = (-0.10, 0.20), (0.05, 0.36)
    reference, now, replaced = _scenes(box, look_alike)
    ahead = _ahead(_controller(now, reference, replaced, look_alike), 0.15, 1.85)
    assert ahead is not None and 1.85 - ahead < 1.70, ahead


def test_a_replaced_target_seen_through_adds_nothing() -> None:
    reference, now, box = _scenes()
    gone = _wall()
    _put(gone, 1.60, *LOOK_ALIKE, 0.15)
    c = _controller(gone, reference, box)
    assert len(c.kept) == 0
    assert _ahead(c) is None
