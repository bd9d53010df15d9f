"""One calibration of rendered chessboards with spoiled views, shared by the camera tests."""

from __future__ import annotations

import pytest

from host.camera.calibration import CalibrationRun, calibrate

from .boards import BOARD, SQUARE_MM, spoiled_sequence


@pytest.fixture(scope="session")
def spoiled_run() -> CalibrationRun:
    return calibrate(spoiled_sequence(), BOARD, SQUARE_MM)
