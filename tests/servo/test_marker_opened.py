"""find_discs' dark mask in one numba pass (marker._dark_opened, issue 25) is OpenCV's
cv2.compare(grey, cv2.subtract(local, 40), CMP_LT) opened by cv2.morphologyEx with a 2x2
square, bit for bit: on random grey images of every shape from one pixel up (noise, smoothed,
dark, light), with the neighbourhood's mean at several sizes."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from host.servo import marker


def _opencv(grey: np.ndarray, local: np.ndarray) -> np.ndarray:
    mask = cv2.compare(grey, cv2.subtract(local, np.full_like(local, 40)), cv2.CMP_LT)
    return cv2.morphologyEx(mask, cv2.MORPH_OPEN, np.ones((2, 2), np.uint8))


@pytest.mark.parametrize("seed", range(6))
def test_dark_mask_is_opencvs(seed: int) -> None:
    rng = np.random.default_rng(seed)
    specks = 0
    for k in range(400):
        h, w = (int(v) for v in rng.integers(1, 70, 2))
        lo, hi = sorted(int(v) for v in rng.integers(0, 256, 2))
        grey = rng.integers(lo, hi + 1, (h, w)).astype(np.uint8)
        if k % 3 == 1:
            grey = cv2.GaussianBlur(grey, (5, 5), 0)
        window = int(rng.choice([3, 7, 31, 121]))
        local = cv2.blur(grey, (window, window))
        want = _opencv(grey, local)
        np.testing.assert_array_equal(marker._dark_opened(grey, local), want)
        specks += int(np.count_nonzero(cv2.compare(grey, cv2.subtract(
            local, np.full_like(local, 40)), cv2.CMP_LT))) - int(np.count_nonzero(want))
    assert specks > 0  # the opening removed something: both of its steps compared
