"""Renderer.image draws the robots and people over the static view itself and puts the drawn
rectangles back (issue 25): every image is bit-identical to the frozen oracle's view (the same
poses, events, blurs and cameras as test_render_speedup), the static views are as they were
after each, and a view() after an image() still gives the oracle's image and disparity."""

from __future__ import annotations

import numpy as np
import pytest

from host.sim.renderer import Renderer
from host.sim.world import World
from tests.sim import renderer_oracle
from tests.sim.test_render_speedup import BLURS, CAMERAS, STEPS


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and a.dtype == b.dtype and np.array_equal(a, b, equal_nan=True)


@pytest.mark.parametrize("camera", list(CAMERAS))
def test_images_drawn_in_place_are_the_oracles_and_leave_the_scene_as_it_was(
        camera: str) -> None:
    world = World.for_size(320, 240, seed=3)
    new = Renderer(world, CAMERAS[camera], seed=11)
    old = renderer_oracle.Renderer(world, CAMERAS[camera], seed=11)
    images = 0
    for i, step in enumerate(STEPS):
        step(world, new)
        step(world, old)
        world.t = 0.1 * i
        for n, blur in enumerate(BLURS):
            for side in (0, 1):
                t_s = None if side == 0 else world.t + 0.004
                static = [a.copy() for a in new._static_views()[side]]
                where = f"step {i}, blur {blur}, side {side}"
                if n == len(BLURS) - 1:  # now and then the whole view, after the images
                    got, disp = new.view(side, True, blur, t_s)
                    want, want_disp = old.view(side, True, blur, t_s)
                    assert _same(disp, want_disp), f"disparity differs: {where}"
                else:
                    got = new.image(side, True, blur, t_s)
                    want = old.view(side, True, blur, t_s)[0]
                assert _same(got, want), f"image differs: {where}"
                after = new._static_views()[side]
                assert all(_same(a, b) for a, b in zip(after, static)), \
                    f"the static view was not put back: {where}"
                images += 1
    assert images > 150
