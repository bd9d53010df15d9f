"""Calibration on rendered chessboards, some of them deliberately spoiled: the spoiled views are
rejected and reported, and the intrinsics and baseline come out within 0.5 % of the truth."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from host.camera.calib_report import check_picture, coverage, coverage_lines
from host.camera.calibration import Rectifier, calibrate, find_board
from host.camera.source import CameraError, StereoFrame

from .boards import BASELINE_MM, BOARD, R_RIGHT, SPOILED, SQUARE_MM, K, bent_view, views


def test_spoiled_views_are_rejected_and_the_rest_used(spoiled_run) -> None:
    rejected = [i for i, v in enumerate(spoiled_run.views) if v.status == "rejected"]
    assert rejected == sorted(SPOILED)
    assert spoiled_run.used == 18
    assert all(v.status == "used" for i, v in enumerate(spoiled_run.views) if i not in SPOILED)
    worst_used = max(v.error_px for v in spoiled_run.named("used"))
    assert min(v.error_px for v in spoiled_run.named("rejected")) > 2 * worst_used


def test_focal_length_and_baseline_within_half_a_percent(spoiled_run) -> None:
    calib = spoiled_run.calibration
    for name in ("M1", "M2"):
        assert calib.mats[name][0, 0] == pytest.approx(K[0, 0], rel=0.005)
        assert calib.mats[name][1, 1] == pytest.approx(K[1, 1], rel=0.005)
    assert calib.baseline_mm == pytest.approx(BASELINE_MM, rel=0.005)
    assert calib.geometry.baseline_m == pytest.approx(BASELINE_MM / 1000, rel=0.005)
    assert calib.rms < 0.35


def test_rectified_pairs_have_rows_aligned_below_half_a_pixel(spoiled_run) -> None:
    # known 3-D points seen by the true cameras, then rectified with the estimated calibration
    calib = spoiled_run.calibration
    m = calib.mats
    rng = np.random.default_rng(5)
    pts = np.column_stack([rng.uniform(-0.5, 0.5, 500), rng.uniform(-0.35, 0.35, 500),
                           np.ones(500)]) * rng.uniform(500, 3000, (500, 1))
    left_px = (K @ pts.T).T
    right_px = (K @ (R_RIGHT @ (pts - [BASELINE_MM, 0, 0]).T)).T
    inside = [(p[:, :2] / p[:, 2:]) for p in (left_px, right_px)]
    ul = cv2.undistortPoints(inside[0].reshape(-1, 1, 2), m["M1"], m["D1"], R=m["R1"], P=m["P1"])
    ur = cv2.undistortPoints(inside[1].reshape(-1, 1, 2), m["M2"], m["D2"], R=m["R2"], P=m["P2"])
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


def test_coverage_report_shows_where_corners_fell(spoiled_run) -> None:
    used = spoiled_run.named("used")
    counts = coverage([v.corners[0] for v in used], spoiled_run.calibration.size)
    assert counts.sum() == 54 * len(used)
    lines = coverage_lines(counts, "left")
    assert lines[0].startswith("left: corners in ") and len(lines) >= 7
    # one board in the middle covers few cells: the user is told where to add views
    centre = coverage([used[0].corners[0]], (640, 480))
    assert "add views with the board near the empty cells" in coverage_lines(centre, "left")[-1]


def test_check_picture_is_the_rectified_pair_with_horizontal_lines(spoiled_run) -> None:
    frame = views(1, seed=7)[0]
    pic = check_picture(spoiled_run.calibration, frame)
    assert pic.shape == (480, 1280, 3)
    line_rows = np.where(np.all(pic[:, :, :2] == (0, 200), axis=2).all(axis=1))[0]
    assert list(line_rows[:2]) == [12, 60]
    rect = Rectifier(spoiled_run.calibration)(frame)
    np.testing.assert_array_equal(pic[13, :640, 0], rect.left[13])


def test_too_few_boards_is_refused_with_a_clear_message() -> None:
    frames = views(3)
    with pytest.raises(CameraError, match="found in both views of only 3 of 3 pairs; need 15"):
        calibrate(frames, BOARD, SQUARE_MM)
    with pytest.raises(CameraError, match="only 0 of 2 pairs; need 2 .check --board"):
        calibrate(views(2), (7, 5), SQUARE_MM, min_views=2)


def test_rejections_that_leave_too_few_views_are_refused() -> None:
    pairs = views(5) + [bent_view(102)]
    with pytest.raises(CameraError, match=r"only 5 of 6 chessboard pairs fit well \(1 "
                                          r"rejected\); need 6"):
        calibrate(pairs, BOARD, SQUARE_MM, min_views=6)


def test_frames_of_another_size_are_refused(spoiled_run) -> None:
    small = StereoFrame(np.zeros((240, 320), np.uint8), np.zeros((240, 320), np.uint8), 0, 0)
    with pytest.raises(CameraError, match="calibration is for 640x480, the frames are 320x240"):
        Rectifier(spoiled_run.calibration)(small)
