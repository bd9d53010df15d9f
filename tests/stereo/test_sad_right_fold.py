"""The SAD kernel's right map (for the left-right check) folds each output's costs into the
running minimum of the right pixels they belong to, instead of writing them skewed and
scanning each right pixel's row (issue 25: the servo's lane window match spent half its time
there). Both maps must be the frozen kernel's (tests/stereo/sad_before_right_fold.py, the
kernel at 4db45a1) to the bit: on random pairs across candidate counts, offsets, windows,
borders, fits, uniqueness, channels and bands, and on the servo's lane window of a rendered
scene through match_window."""

from __future__ import annotations

import numpy as np
import pytest

from host.servo import perception
from host.servo.perception import lane_window, match_exposure, match_window
from host.sim.faults import CameraFaults
from host.sim.renderer import Renderer
from host.sim.world import Box, World
from host.stereo import sad
from host.stereo.params import MatcherParams
from tests.stereo import sad_before_right_fold as frozen

# (channels, dmin, nd, half, clip, uniqueness, fit, bands)
CONFIGS = [(1, 0, 32, 4, False, 0.0, 1, 1), (1, 0, 32, 4, True, 0.0, 1, 1),
           (1, 3, 17, 2, False, 0.0, 2, 1), (1, 0, 64, 4, False, 0.0, 1, 3),
           (1, 5, 100, 4, True, 0.0, 1, 2), (3, 0, 48, 4, False, 0.0, 2, 1),
           (3, 2, 40, 5, True, 0.0, 0, 1), (1, 0, 56, 3, True, 15.0, 1, 1),
           (1, 0, 24, 8, False, 10.0, 0, 3), (1, 0, 16, 0, False, 0.0, 1, 1)]


def both(left: np.ndarray, right: np.ndarray, cfg: tuple) -> list[tuple[np.ndarray, ...]]:
    ch, dmin, nd, half, clip, uniq, fit, bands = cfg
    cdt, wdt = sad.lane_types(ch, 2 * half + 1)
    args = (left, right, dmin, nd, half, uniq, fit, True, clip, np.empty(0, cdt),
            np.empty(0, wdt), np.iinfo(wdt).max, bands)
    return [sad.match_sad(*args), frozen.match_sad(*args)]


def same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and a.tobytes() == b.tobytes()  # NaN and -0.0 as bits


@pytest.mark.parametrize("cfg", CONFIGS)
def test_both_maps_equal_the_frozen_kernel_on_random_pairs(cfg: tuple) -> None:
    rng = np.random.default_rng(cfg[2] + 7 * cfg[0])
    for levels, shape in ((256, (41, 150)), (4, (23, 97))):  # few levels: many tied costs
        left = rng.integers(0, levels, (cfg[0], *shape), dtype=np.uint8)
        shift = np.roll(left, cfg[1] + cfg[2] // 3, axis=2)
        right = np.where(rng.random(left.shape) < 0.2, rng.integers(0, levels, left.shape),
                         shift).astype(np.uint8)
        (new_l, new_r), (old_l, old_r) = both(left, right, cfg)
        assert np.isfinite(new_r).any()
        assert same(new_l, old_l) and same(new_r, old_r), (cfg, levels)


def lane_scene() -> tuple[World, np.ndarray, np.ndarray]:
    boxes = (Box(1.2, -0.50, -0.18, 0.38), Box(1.8, 0.22, 0.55, 0.30))
    world = World(seed=5, boxes=boxes)
    world.boxes = (*boxes, Box(0.99, -0.15, 0.15, 0.3))  # in the lane, 29 cm ahead
    world.robot.z_m, world.robot.x_m = 0.7, 0.0
    f = Renderer(world, CameraFaults(noise=2.0), seed=5).frame()
    return world, f.left, match_exposure(f.left, f.right)


@pytest.mark.parametrize("direction", [1, -1])
def test_the_lane_window_match_equals_the_frozen_kernels(direction: int,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    world, left, right = lane_scene()
    g, r = world.geometry, world.robot
    params = MatcherParams.for_matcher(MatcherParams.matcher).validate()
    for reach in (0.2, 0.4, 0.8):
        win = lane_window(g, world.size, r.z_m + (0.6 if direction < 0 else 0.0), r.x_m,
                          direction, reach, camera_height_m=world.height_m)
        assert win is not None
        new = match_window(left, right, params, win)
        with monkeypatch.context() as m:
            m.setattr(perception.compute_disparity.__globals__["sad"], "match_sad",
                      frozen.match_sad)
            old = match_window(left, right, params, win)
        assert np.isfinite(new).sum() > 500
        assert same(new, old), (direction, reach)
