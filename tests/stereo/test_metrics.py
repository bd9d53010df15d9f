"""The paper's metrics on small arrays computed by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from host.errors import HostError
from host.stereo.metrics import evaluate, middlebury, round_submission

NAN = np.nan


def test_bad_rate_counts_missing_disparities_as_bad() -> None:
    gt = np.array([[10.0, 10.0, 10.0, NAN]], np.float32)
    disp = np.array([[10.5, 12.0, NAN, 3.0]], np.float32)
    s = evaluate(disp, gt)
    # region: 3 known pixels; bad: 12.0 (err 2) and NaN -> 2 of 3
    assert s.n == 3
    assert s.bad == pytest.approx(200 / 3)
    assert s.density == pytest.approx(200 / 3)
    assert s.rms == pytest.approx(math.sqrt((0.25 + 4.0) / 2))


def test_threshold_is_strictly_greater_than_rho() -> None:
    gt = np.zeros((1, 3), np.float32)
    disp = np.array([[1.0, 1.01, -1.0]], np.float32)
    assert evaluate(disp, gt, rho=1.0).bad == pytest.approx(100 / 3)


def test_mask_restricts_the_region() -> None:
    gt = np.array([[5.0, 5.0], [5.0, 5.0]], np.float32)
    disp = np.array([[5.0, 9.0], [NAN, 5.2]], np.float32)
    mask = np.array([[True, False], [False, True]])
    s = evaluate(disp, gt, mask)
    assert (s.n, s.bad, s.density) == (2, 0.0, 100.0)
    assert evaluate(disp, gt).bad == 50.0


def test_empty_region_and_no_valid_pixel() -> None:
    gt = np.full((2, 2), NAN, np.float32)
    assert evaluate(np.zeros((2, 2), np.float32), gt).n == 0
    s = evaluate(np.full((2, 2), NAN, np.float32), np.ones((2, 2), np.float32))
    assert s.bad == 100.0 and s.density == 0.0 and math.isnan(s.rms)


def test_size_mismatch_is_an_error() -> None:
    with pytest.raises(HostError, match="differ in size"):
        evaluate(np.zeros((2, 3), np.float32), np.zeros((3, 2), np.float32))


def test_middlebury_regions_take_each_mask_and_all_falls_back_to_known_gt() -> None:
    gt = np.array([[4.0, 4.0, 4.0, 4.0, NAN]], np.float32)
    disp = np.array([[4.0, 9.0, 4.0, 9.0, 4.0]], np.float32)
    masks = {"nonocc": np.array([[1, 0, 1, 0, 0]], bool),
             "all": np.array([[1, 1, 1, 0, 0]], bool),
             "disc": np.array([[0, 0, 1, 0, 0]], bool)}
    s = middlebury(disp, gt, masks)
    assert list(s) == ["nonocc", "all", "disc"]
    assert (s["nonocc"].bad, s["nonocc"].n) == (0.0, 2)
    assert (s["all"].bad, s["all"].n) == (pytest.approx(100 / 3), 3)  # all.png, not 4 known
    assert (s["disc"].bad, s["disc"].n) == (0.0, 1)
    no_all = middlebury(disp, gt, {"nonocc": masks["nonocc"]})
    assert list(no_all) == ["nonocc", "all"]
    assert (no_all["all"].bad, no_all["all"].n) == (50.0, 4)  # every known pixel


def test_round_submission_stores_what_an_8_bit_png_would() -> None:
    disp = np.array([[1.30, 1.20, 2.0 / 3.0, -0.4, 300.0, NAN]], np.float32)
    out = round_submission(disp, 4.0)
    assert out[0, :5].tolist() == [1.25, 1.25, 0.75, 0.0, 63.75]
    assert np.isnan(out[0, 5])
    # a whole-pixel scale: 1.4 px off by 1.4 becomes 1 px off, which is good at rho 1
    gt = np.zeros((1, 1), np.float32)
    d = np.array([[1.4]], np.float32)
    assert evaluate(d, gt).bad == 100.0
    assert evaluate(round_submission(d, 1.0), gt).bad == 0.0
    with pytest.raises(HostError, match="scale"):
        round_submission(d, 0.0)
