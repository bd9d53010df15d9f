"""The target's own fixed cells are those of its extent, not of its band at every depth
(issue 23): Controller.others left out every cell across the target's keep-out at any depth,
so the back wall's cells directly behind the target (its face at 1.2 m, the wall at 3.2 m)
were no obstacle to a robot standing by the wall in the target's band. Now the cells across
the keep-out are the target's only up to own_depth_m behind its face; the wall stays one. The
checks are the servo's (Servo._fixed_fault: controller.obstacles, then clearance.run_fault for
a run, in_the_way for a spin), on a constructed scene."""

from __future__ import annotations

import math

import numpy as np

from host.servo.clearance import Body, in_the_way, run_fault
from host.servo.controller import ControlConfig, Controller

BOX = (-0.50, -0.18)  # the target's lateral extent, m (the default scene's nearest box)
TARGET_M, WALL_M = 1.2, 3.2


def _cells(zs: list[float], x0: float, x1: float) -> np.ndarray:
    """Rows of 2 cm cells at depths zs across x0..x1 (cell centres, as fixed_cells gives)."""
    xs = np.arange(math.floor(x0 / 0.02), math.ceil(x1 / 0.02)) * 0.02 + 0.01
    return np.array([(z, x) for z in zs for x in xs])


def _scene() -> Controller:
    """The target's face at 1.2 m (its cells a cell either side, as seed 3's reference puts
    them: 1.19-1.21 m) and the back wall's at 3.19-3.21 m from x -1.1 to 1.1 m."""
    c = Controller(TARGET_M, ControlConfig())
    c.keep_out = BOX
    c.fixed = np.vstack([_cells([1.19, 1.21], *BOX), _cells([3.19, 3.21], -1.1, 1.1)])
    return c


def _run(c: Controller, z: float, x: float, duty: int, travel_m: float = 0.12) -> float | None:
    """Where a run at duty (negative: backward) from (z, x), facing away from the camera,
    meets a cell of the obstacles (the servo's body and margins), or None."""
    cfg = c.cfg
    body = Body(cfg.half_width_m, cfg.half_length_m, cfg.block_margin_m + cfg.cell_m / 2)
    return run_fault(c.obstacles(z, x), z, x, duty, duty, 0.0, 0.0, travel_m, body,
                     cfg.wheelbase_m)


def test_the_wall_behind_the_target_is_an_obstacle_in_its_band() -> None:
    """A robot 3.0 m deep, 30 cm left of centre (within the target's band, 1.8 m behind its
    face), facing away: a drive or a probe forward runs into the wall 20 cm on (its front
    8 cm, the margins 3 cm, a 12 cm run): refused. Before, only the wall beside the band
    was checked and the way was clear. Backing (toward the camera) it is clear."""
    c = _scene()
    assert _run(c, 3.0, -0.30, 600) is not None
    assert _run(c, 3.0, -0.30, -600) is None  # backing toward the camera, away from the wall
    wall = c.others()
    assert ((wall[:, 0] > 3.1) & (wall[:, 1] > BOX[0]) & (wall[:, 1] < BOX[1])).sum() >= 30


def test_a_spin_by_the_wall_in_the_band_is_an_obstacle() -> None:
    """A spin 8 cm from the wall's cells (3.1 m deep) in the target's band sweeps its circle
    (11.5 cm and margins) into the wall; 25 cm from it the spin is clear."""
    c = _scene()
    cfg = c.cfg
    r = cfg.turn_radius_m + cfg.block_margin_m + cfg.cell_m / 2
    assert in_the_way(c.obstacles(3.1, -0.3), 3.1, -0.3, None, 0.0, r) is not None
    assert in_the_way(c.obstacles(2.94, -0.3), 2.94, -0.3, None, 0.0, r) is None


def test_the_targets_own_cells_are_still_left_out_and_do_not_move_the_lane() -> None:
    """The target's face cells (and any within own_depth_m behind it: the face's spread)
    are no obstacle and do not push the lane: beside the target, backing away from the
    camera, the run is clear; the lane from behind the target (2.0 m, card seen 5 cm
    left of centre, inside the keep-out's clearance) is the same as with no fixed cells at
    all, and a cell own_depth_m + 2 cm behind the face is another thing's."""
    c = _scene()
    z = TARGET_M
    x = BOX[1] + c.cfg.clearance_m  # the lane beside the object
    assert _run(c, z, x, -300, 0.05) is None and _run(c, z, x, 300, 0.05) is None
    c.fixed = np.vstack([c.fixed, _cells([TARGET_M + 0.11], *BOX)])
    c.lateral_ref = -0.05
    bare = _scene()
    bare.fixed, bare.lateral_ref = np.zeros((0, 2)), -0.05
    assert c.lane(2.0) == bare.lane(2.0)
    assert len(c.others()) == len(_cells([3.19, 3.21], -1.1, 1.1))
    c.fixed = np.vstack([c.fixed, _cells([TARGET_M + c.cfg.own_depth_m + 0.02], *BOX)])
    assert len(c.others()) == len(_cells([3.19, 3.21], -1.1, 1.1)) + len(_cells([0.0], *BOX))
