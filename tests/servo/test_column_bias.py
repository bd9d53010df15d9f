"""A calibration off at the image's edges reads disparity too high by column (seed 16's camera
11: +0.7-1 px at the left columns, the target's left strip read nearer, every hold short): the
reference's floor measures it (perception.floor_column_bias) and the right view is corrected
by it (perception.corrected_right), so the target's disparity is the true one again (issue 23)."""

from __future__ import annotations

import cv2
import numpy as np

from host.servo.perception import (
    BIAS_NOISE_PX,
    ColumnBias,
    corrected_right,
    fit_floor,
    floor_column_bias,
    nearest_object,
    without_floor,
)
from host.stereo import MatcherParams, compute_disparity

PARAMS = MatcherParams(block_size=9, num_disparities=48, border="clip")
W, H = 320, 240
HORIZON = 100  # the floor's disparity is 0 at this row
SLOPE = 0.25  # px of disparity per row below it
BOX = (10, 60, 70, 170, 16.0)  # x0, y0, x1, y1 (right view) and its disparity, px
WALL = 6.0


def _bias(x: np.ndarray) -> np.ndarray:
    """The known excess (px) by right-view column: 0.8 at column 0 down to 0 at column 90."""
    return 0.8 * np.clip(1 - x / 90.0, 0.0, 1.0)


def _pair(bias: bool) -> tuple[np.ndarray, np.ndarray]:
    """A textured scene (wall, floor, a box on the left) seen by a left and a right view; the
    right view with _bias's excess when bias."""
    rng = np.random.default_rng(3)
    big = cv2.GaussianBlur(rng.uniform(0, 255, (H, 2 * W)).astype(np.float32), (0, 0), 1.2)
    ys, xs = np.mgrid[0:H, 0:W].astype(np.float32)
    d = np.full((H, W), WALL, np.float32)
    floor = SLOPE * (ys - HORIZON)
    d = np.where(floor > d, floor, d)
    x0, y0, x1, y1, db = BOX
    d[y0:y1, x0:x1] = db
    tex = big[:, W // 2:W // 2 + W]
    # the left view: the scene's texture; the right view at column x shows what the left
    # shows at x + d (d read too high by the excess: the right view's point seen e further left)
    left = np.clip(tex, 0, 255).astype(np.uint8)
    shift = d + (_bias(xs) if bias else 0.0)
    right = cv2.remap(big, (xs + W // 2 + shift).astype(np.float32), ys, cv2.INTER_LINEAR)
    return left, np.clip(right, 0, 255).astype(np.uint8)


def _box_disparity(left: np.ndarray, right: np.ndarray) -> float:
    disp = compute_disparity(left, right, PARAMS)
    return nearest_object(without_floor(disp, fit_floor(disp)), 2000).disparity


def test_the_floor_measures_a_known_column_bias() -> None:
    left, right = _pair(bias=True)
    disp = compute_disparity(left, right, PARAMS)
    bias = floor_column_bias(disp, fit_floor(disp))
    assert bias is not None
    truth = _bias(np.arange(W, dtype=np.float64))
    # the left columns (where the excess is) and the rest, within a tenth of a pixel
    assert np.abs(bias.excess[5:120] - truth[5:120]).max() < 0.12
    assert np.abs(bias.excess[120:] - truth[120:]).max() < 0.08
    assert 0.6 < bias.largest < 1.0


def test_a_bias_free_pair_shows_none() -> None:
    left, right = _pair(bias=False)
    disp = compute_disparity(left, right, PARAMS)
    bias = floor_column_bias(disp, fit_floor(disp))
    assert bias is not None and abs(bias.largest) < 0.1


def test_the_corrected_right_view_gives_the_boxs_true_disparity() -> None:
    true_d = BOX[4]
    left, right = _pair(bias=True)
    before = _box_disparity(left, right)
    assert before - true_d > 0.3  # the box on the left columns reads near: a short hold
    disp = compute_disparity(left, right, PARAMS)
    bias = floor_column_bias(disp, fit_floor(disp))
    assert bias is not None
    whole = _box_disparity(left, corrected_right(right, bias, noise_px=0.0))
    assert abs(whole - true_d) < 0.1
    clean_left, clean_right = _pair(bias=False)
    assert abs(whole - _box_disparity(clean_left, clean_right)) < 0.1
    # beyond the measure's noise only (the servo's): the error at least halved, what is left
    # within that noise
    after = _box_disparity(left, corrected_right(right, bias))
    assert abs(after - true_d) < (before - true_d) / 2
    assert abs(after - true_d) < BIAS_NOISE_PX


def test_no_excess_leaves_the_view_as_it_was() -> None:
    _, right = _pair(bias=False)
    none = ColumnBias(np.zeros(W, np.float32), W)
    assert np.array_equal(corrected_right(right, none), right)
