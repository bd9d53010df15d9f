"""A box keeps its face when the scene around it changes (host/sim/renderer.py): another box
put down, one taken away, or the box itself moved in depth. Before, every box's texture was
drawn again in depth order from one stream, so a box put down behind the target gave the
target a new face, and the servo's check of the target's picture after a knock (which a
real box passes) failed."""

from __future__ import annotations

import numpy as np

from host.sim.faults import CameraFaults
from host.sim.renderer import Renderer
from host.sim.world import Box, World

TARGET = Box(1.2, -0.50, -0.18, 0.38)


def _target_pixels(renderer: Renderer, world: World) -> np.ndarray:
    """The left view's pixels of the middle of the target's face."""
    image, _ = renderer.view(0, False, (0.0, 0.0), None)
    u0, v0 = world.project(-0.40, 0.30, TARGET.z_m)
    u1, v1 = world.project(-0.25, 0.05, TARGET.z_m)
    return image[int(v0):int(v1), int(u0):int(u1)].copy()


def test_a_box_put_down_behind_the_target_leaves_its_face_as_it_was():
    world = World(seed=3, boxes=(TARGET, Box(1.8, 0.22, 0.55, 0.30)))
    renderer = Renderer(world, CameraFaults(noise=0.0), seed=3)
    before = _target_pixels(renderer, world)
    world.boxes = (*world.boxes, Box(1.6, 0.35, 0.6, 0.3))  # farther: drawn before it
    np.testing.assert_array_equal(_target_pixels(renderer, world), before)
    world.boxes = (TARGET,)  # and taken away again, with the other
    np.testing.assert_array_equal(_target_pixels(renderer, world), before)


def test_boxes_put_down_later_have_faces_of_their_own():
    world = World(seed=3, boxes=(TARGET,))
    renderer = Renderer(world, CameraFaults(noise=0.0), seed=3)
    before = _target_pixels(renderer, world)
    world.boxes = (Box(1.2, -0.50, -0.18, 0.45),)  # another box (taller) in its place
    assert not np.array_equal(_target_pixels(renderer, world), before)
