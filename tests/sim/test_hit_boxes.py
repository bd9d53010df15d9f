"""The boxes the renderer's lens and the trials' rectifier redo (renderer._lens_hit_box,
rectify._hit, in numba) are the numpy computations they replaced: the tight box round the
pixels whose source meets the drawn rectangle, on real maps and many rectangles, the image's
edges (infinite limits) included."""

from __future__ import annotations

import math

import numpy as np

from host.sim import rectify, renderer
from host.sim.world import World


def _tight(hit: np.ndarray) -> tuple[int, int, int, int] | None:
    rows, cols = np.flatnonzero(hit.any(1)), np.flatnonzero(hit.any(0))
    if not rows.size:
        return None
    return int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1


def test_lens_box_is_the_tight_box_of_the_pixels_whose_source_is_inside() -> None:
    mx, my = renderer.lens_maps(World(), -0.06)
    bounds = renderer._lens_bounds(mx, my)
    rng = np.random.default_rng(2)
    for _ in range(200):
        r0, c0 = int(rng.integers(-5, 240)), int(rng.integers(-5, 320))
        r1, c1 = r0 + int(rng.integers(1, 40)), c0 + int(rng.integers(1, 40))
        lo_x, hi_x = (-math.inf if c0 <= 0 else c0 - 2), (math.inf if c1 >= 320 else c1 + 1)
        lo_y, hi_y = (-math.inf if r0 <= 0 else r0 - 2), (math.inf if r1 >= 240 else r1 + 1)
        want = _tight((mx > lo_x) & (mx < hi_x) & (my > lo_y) & (my < hi_y))
        assert renderer._lens_hit_box(bounds, mx, my, (lo_x, hi_x, lo_y, hi_y)) == want


def test_rectify_box_is_the_tight_box_of_the_pixels_whose_source_meets_the_box() -> None:
    mx, my = renderer.lens_maps(World(), 0.05)
    m1 = np.stack([np.floor(mx), np.floor(my)], axis=2).astype(np.int16)
    bounds = (m1[..., 1].min(1), m1[..., 1].max(1), m1[..., 0].min(0), m1[..., 0].max(0))
    rng = np.random.default_rng(3)
    for _ in range(200):
        r0, c0 = int(rng.integers(0, 240)), int(rng.integers(0, 320))
        box = (r0, r0 + int(rng.integers(1, 40)), c0, c0 + int(rng.integers(1, 40)))
        x, y = m1[..., 0], m1[..., 1]
        want = _tight((x >= box[2] - 1) & (x <= box[3] - 1) & (y >= box[0] - 1)
                      & (y <= box[1] - 1))
        assert rectify._hit(bounds, m1, box) == want
