"""The simulated camera sends grey images when the servo matches in grey (the trials'
configuration): each image is the grey conversion (OpenCV's BGR2GRAY) of the colour image the
same camera would have sent, frame for frame; with colour matching it stays in colour."""

from __future__ import annotations

import cv2
import numpy as np

from host.sim.faults import CameraFaults, WorldFaults
from host.sim.renderer import Renderer
from host.sim.run import Setup, simulation
from host.sim.source import SimSource
from host.sim.world import World
from host.stereo.params import MatcherParams

CAMERA = CameraFaults(gain=(1.1, 0.9), bias=(4.0, -6.0), noise=2.0, skew_ms=7.0,
                      white=((0.9, 1.05, 1.12), (1.1, 0.95, 0.88)))


class Board:
    """Motors that drive the robot slowly toward the camera (the robot moves between frames)."""

    def motors(self) -> tuple[int, int]:
        return -400, -380

    def advance(self, ms: float) -> None:
        pass


def _frames(grey: bool, n: int = 8) -> list[tuple[np.ndarray, np.ndarray, float, float]]:
    world = World.for_size(160, 120, seed=5)
    world.robot.z_m = 1.6
    source = SimSource(world, Board(), renderer=Renderer(world, CAMERA, seed=5),
                       reference_frames=2, seed=5, grey=grey)
    out = []
    for _ in range(n):
        f = source.read()
        assert f is not None
        out.append((f.left, f.right, f.t_left, f.t_right))
    return out


def test_grey_frames_are_the_colour_frames_in_grey() -> None:
    colour, grey = _frames(False), _frames(True)
    assert colour[0][0].ndim == 3  # the camera has a white balance: colour images
    for (cl, cr, ctl, ctr), (gl, gr, gtl, gtr) in zip(colour, grey):
        assert gl.ndim == 2 and gl.dtype == np.uint8
        np.testing.assert_array_equal(gl, cv2.cvtColor(cl, cv2.COLOR_BGR2GRAY))
        np.testing.assert_array_equal(gr, cv2.cvtColor(cr, cv2.COLOR_BGR2GRAY))
        assert (gtl, gtr) == (ctl, ctr)


def test_the_simulation_sends_grey_when_the_servo_matches_in_grey() -> None:
    faults = WorldFaults(camera=CAMERA)
    for colour in (False, True):
        params = MatcherParams(block_size=9, num_disparities=48, border="clip", colour=colour)
        with simulation(Setup(size=(160, 120), faults=faults, params=params),
                        reference=False) as sim:
            f = sim.source.read()
            assert f is not None
            assert f.left.ndim == (3 if colour else 2)
            assert sim.source.grey is not colour
