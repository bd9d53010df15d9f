"""The paper's metrics on small arrays computed by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from host.errors import HostError
from host.stereo.metrics import evaluate

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
