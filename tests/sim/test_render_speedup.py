"""The faster renderer draws the same images as before it was made faster: every view of a set of
poses and events (near, far, turning, hidden, occluded, behind a box, blurred, a person, a decoy,
a box appearing, a knocked rig, flicker, lens distortion, white balance, noise) is bit-identical
to the frozen oracle's (tests/sim/renderer_oracle.py, the renderer at 6fb3425), and so is the
disparity it returns."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from host.sim.faults import CameraFaults
from host.sim.renderer import Flicker, Renderer
from host.sim.world import Box, Person, Robot, World
from tests.sim import renderer_oracle

FAULTY = CameraFaults(gain=(0.87, 1.13), bias=(-12.5, 9.25),
                      white=((0.9, 1.05, 1.12), (1.1, 0.95, 0.88)), exposure_ms=20.0,
                      noise=2.7)
CAMERAS = {
    "default": CameraFaults(),
    "faulty": FAULTY,
    "lens": CameraFaults(gain=(1.1, 0.9), bias=(3.0, -4.0), distortion=(-0.1, 0.04)),
    "lens-white": CameraFaults(white=FAULTY.white, distortion=(0.05, -0.08), noise=1.5),
    "no-noise": CameraFaults(noise=0.0, gain=(1.2, 0.8)),
}


def _pose(z: float, x: float = 0.0, theta: float = 0.0, **kw) -> Callable[[World, object], None]:
    def apply(w: World, _r: object) -> None:
        for k, v in dict(z_m=z, x_m=x, theta=theta, **kw).items():
            setattr(w.robot, k, v)
    return apply


def _set(**kw) -> Callable[[World, object], None]:
    def apply(w: World, r: object) -> None:
        for k, v in kw.items():
            target = r if k in ("pitch_deg", "flicker") else w
            setattr(target, k, v)
    return apply


# each step changes the world (or the rig), then both sides are rendered with each blur
STEPS = [
    _pose(1.9), _pose(0.35), _pose(0.28, 0.02), _pose(2.8, -0.3), _pose(1.2, 0.1, 0.6),
    _pose(1.0, 0.0, math.pi / 2), _pose(0.9, -0.05, math.pi), _pose(1.5, 0.4, -0.3),
    _pose(1.1, 0.0, 0.2, marker_hidden=True), _pose(1.1, 0.0, 0.0, occlusion=0.35),
    _pose(1.6, -0.36, 0.0),  # behind the box on the left
    _pose(0.7, 0.5),  # half out of the picture
    _set(people=(Person(-0.2, 0.9),)), _pose(1.4, 0.05),
    _set(people=(), decoys=(Robot(x_m=0.3, z_m=1.5),)),
    _set(boxes=(Box(1.2, -0.50, -0.18, 0.38), Box(1.8, 0.22, 0.55, 0.30),
                Box(0.8, -0.05, 0.12, 0.3))),
    _pose(1.0, 0.0, 0.1),
    _set(flicker=Flicker(0.2, 100.0, 0.009)), _pose(0.9, 0.02, 0.0),
    _set(flicker=None, pitch_deg=1.5), _pose(0.8, 0.0, 0.3),
    _set(flicker=Flicker(0.2, 100.0, 0.012)),
    _set(flicker=None, pitch_deg=-2.2), _pose(1.3, 0.1, 0.0),
    _set(pitch_deg=0.0), _pose(1.9),
]
BLURS = [(0.0, 0.0), (0.3, -0.2), (2.6, 0.7), (-1.4, -3.1)]


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and a.dtype == b.dtype and np.array_equal(a, b, equal_nan=True)


@pytest.mark.parametrize("size", [(320, 240), (160, 120)])
@pytest.mark.parametrize("camera", list(CAMERAS))
def test_views_are_bit_identical_to_the_oracle(camera: str, size: tuple[int, int]) -> None:
    world = World.for_size(*size, seed=3)
    new = Renderer(world, CAMERAS[camera], seed=11)
    old = renderer_oracle.Renderer(world, CAMERAS[camera], seed=11)
    views = 0
    for i, step in enumerate(STEPS):
        step(world, new)
        step(world, old)
        world.t = 0.1 * i
        for blur in BLURS:
            for side in (0, 1):
                for with_robot in ((True, False) if blur == (0.0, 0.0) else (True,)):
                    t_s = None if side == 0 else world.t + 0.004
                    got = new.view(side, with_robot, blur, t_s)
                    want = old.view(side, with_robot, blur, t_s)
                    where = f"step {i}, blur {blur}, side {side}, robot {with_robot}"
                    assert _same(got[0], want[0]), f"image differs: {where}"
                    assert _same(got[1], want[1]), f"disparity differs: {where}"
                    views += 1
    frame_new, frame_old = new.frame(), old.frame()
    assert _same(frame_new.left, frame_old.left) and _same(frame_new.right, frame_old.right)
    assert views > 200
