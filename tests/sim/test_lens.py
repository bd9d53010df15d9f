"""Lens distortion, and the simulated camera calibrated by the project's own calibration on
rendered chessboards: the calibration finds the lenses, and the servo, rectifying with it, still
ends at the object's true depth."""

from __future__ import annotations

import numpy as np
import pytest

from host.sim.chessboard import calibrate_camera
from host.sim.faults import CameraFaults, WorldFaults
from host.sim.run import Setup, simulation
from host.sim.world import World

LENS = CameraFaults(distortion=(-0.1, 0.04))


def test_calibration_on_rendered_boards_finds_the_lenses() -> None:
    calib = calibrate_camera(World(), LENS)
    assert calib.rms < 0.5 and calib.epipolar_rms < 0.2
    assert calib.mats["D1"].ravel()[0] == pytest.approx(-0.1, abs=0.02)
    assert calib.geometry.baseline_m == pytest.approx(0.060, abs=0.001)


def test_distorted_views_move_the_marker_and_the_servo_still_holds() -> None:
    with simulation(Setup((320, 240), 0.8, faults=WorldFaults(camera=LENS))) as sim:
        assert sim.source.rectify is not None
        assert sim.servo.geometry != sim.world.geometry  # the calibration's, not the truth
        raw = sim.source.renderer.view(0)[0].astype(float)
        ideal = type(sim.source.renderer)(sim.world, CameraFaults()).view(0)[0].astype(float)
        assert np.abs(raw - ideal).mean() > 5  # the lens bends the picture
        sim.run(20.0)
        assert sim.servo.outcome() == ("held", "")
        assert abs(sim.depth_error_m()) <= 0.02
