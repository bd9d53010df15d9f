"""The simulated colour camera renders grey images when the servo matches in grey (the trials'
configuration): each image within a grey level of OpenCV's grey of the colour image the same
camera renders (where no colour channel saturates), through a lens too; with colour matching the
simulation stays in colour."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from host.sim.faults import CameraFaults, WorldFaults
from host.sim.renderer import Renderer
from host.sim.run import Setup, simulation
from host.sim.world import World
from host.stereo.params import MatcherParams

CAMERA = CameraFaults(gain=(1.1, 0.9), bias=(4.0, -6.0), noise=2.0,
                      white=((0.86, 1.05, 1.14), (1.14, 0.95, 0.86)))


def _views(camera: CameraFaults, grey: bool) -> list[np.ndarray]:
    world = World.for_size(160, 120, seed=5)
    world.robot.z_m = 1.3
    renderer = Renderer(world, camera, seed=5, grey=grey)
    views = []
    for blur in ((0.0, 0.0), (2.5, 0.0)):  # the robot drawn still and blurred
        for side in (0, 1):
            views.append(renderer.view(side, True, blur)[0])
    return views


@pytest.mark.parametrize("lens", [(0.0, 0.0), (-0.08, 0.03)])
def test_grey_views_are_the_colour_views_in_grey(lens: tuple[float, float]) -> None:
    camera = CameraFaults(**{**CAMERA.__dict__, "distortion": lens})
    for colour, grey in zip(_views(camera, False), _views(camera, True)):
        assert colour.ndim == 3 and grey.shape == colour.shape[:2] and grey.dtype == np.uint8
        unsaturated = (colour.min(2) > 0) & (colour.max(2) < 255)
        assert unsaturated.mean() > 0.8  # the comparison covers most of the view
        diff = np.abs(grey.astype(int) - cv2.cvtColor(colour, cv2.COLOR_BGR2GRAY))
        assert diff[unsaturated].max() <= 1


def test_the_simulation_sends_grey_when_the_servo_matches_in_grey() -> None:
    faults = WorldFaults(camera=CAMERA)
    for colour in (False, True):
        params = MatcherParams(block_size=9, num_disparities=48, border="clip", colour=colour)
        with simulation(Setup(size=(160, 120), faults=faults, params=params),
                        reference=False) as sim:
            f = sim.source.read()
            assert f is not None
            assert f.left.ndim == f.right.ndim == (3 if colour else 2)
