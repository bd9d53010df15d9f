"""Calibration on rendered chessboards recovers the intrinsics and baseline, and rectifies."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from host.camera.calibration import Calibration, Rectifier, calibrate, find_board
from host.camera.source import CameraError

from .boards import BASELINE_MM, BOARD, R_RIGHT, SQUARE_MM, K, views


@pytest.fixture(scope="module")
def calibrated() -> tuple[Calibration, int]:
    return calibrate(views(14), BOARD, SQUARE_MM)


def test_focal_length_and_baseline_within_one_percent(calibrated) -> None:
    calib, used = calibrated
    assert used >= 12
    for name in ("K1", "K2"):
        assert calib.mats[name][0, 0] == pytest.approx(K[0, 0], rel=0.01)
        assert calib.mats[name][1, 1] == pytest.approx(K[1, 1], rel=0.01)
    assert calib.baseline_mm == pytest.approx(BASELINE_MM, rel=0.01)
    assert calib.geometry.baseline_m == pytest.approx(BASELINE_MM / 1000, rel=0.01)
    assert calib.rms < 0.5


def test_rectified_pairs_have_rows_aligned_below_half_a_pixel(calibrated) -> None:
    # known 3-D points seen by the true cameras, then rectified with the estimated calibration
    calib, _ = calibrated
    m = calib.mats
    rng = np.random.default_rng(5)
    pts = np.column_stack([rng.uniform(-0.5, 0.5, 500), rng.uniform(-0.35, 0.35, 500),
                           np.ones(500)]) * rng.uniform(500, 3000, (500, 1))
    left_px = (K @ pts.T).T
    right_px = (K @ (R_RIGHT @ (pts - [BASELINE_MM, 0, 0]).T)).T
    inside = [(p[:, :2] / p[:, 2:]) for p in (left_px, right_px)]
    ul = cv2.undistortPoints(inside[0].reshape(-1, 1, 2), m["K1"], m["D1"], R=m["R1"], P=m["P1"])
    ur = cv2.undistortPoints(inside[1].reshape(-1, 1, 2), m["K2"], m["D2"], R=m["R2"], P=m["P2"])
    seen = np.all([(q[:, 0] >= 0) & (q[:, 0] < 640) & (q[:, 1] >= 0) & (q[:, 1] < 480)
                   for q in inside], axis=0)
    assert seen.sum() > 200
    dy = (ul - ur).reshape(-1, 2)[seen, 1]
    assert np.abs(dy).max() < 0.5, np.abs(dy).max()
    # and on rendered images the corners agree in row on average (detection noise aside)
    rectify = Rectifier(calib)
    for frame in views(3, seed=99):
        r = rectify(frame)
        cl, cr = find_board(r.left, BOARD), find_board(r.right, BOARD)
        assert abs(float(np.mean(cl[:, 0, 1] - cr[:, 0, 1]))) < 0.1
    assert calib.epipolar_rms < 0.5


def test_calibration_file_round_trip(calibrated, tmp_path: Path) -> None:
    calib, _ = calibrated
    path = tmp_path / "calib.yml"
    calib.save(path)
    back = Calibration.load(path)
    assert back.size == calib.size and back.rms == pytest.approx(calib.rms)
    for k, v in calib.mats.items():
        np.testing.assert_allclose(back.mats[k], v, rtol=1e-9, atol=1e-12)
    text = path.read_text()
    assert text.startswith("%YAML") and "baseline_mm" in text


def test_too_few_boards_is_refused_with_a_clear_message() -> None:
    frames = views(3)
    with pytest.raises(CameraError, match="found in both views of only 3 of 3 pairs; need 6"):
        calibrate(frames, BOARD, SQUARE_MM)
    with pytest.raises(CameraError, match="only 0 of"):
        calibrate(views(6), (7, 5), SQUARE_MM)


def test_frames_of_another_size_are_refused(calibrated) -> None:
    from host.camera.source import StereoFrame

    small = StereoFrame(np.zeros((240, 320), np.uint8), np.zeros((240, 320), np.uint8), 0, 0)
    with pytest.raises(CameraError, match="calibration is for 640x480, the frames are 320x240"):
        Rectifier(calibrated[0])(small)
