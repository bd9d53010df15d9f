"""find_discs clears the mask's specks before tracing contours (marker._without_specks): the
contours left are exactly those of the whole mask whose box find_discs keeps, in the same
order, on random masks (specks, diagonal joins, blobs inside other blobs' holes)."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from host.servo import marker

MIN_AREA = math.pi * 2.5 ** 2


def _contours(mask: np.ndarray) -> list[np.ndarray]:
    return list(cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)[0])


def _boxed(contour: np.ndarray) -> bool:
    x, y, w, h = cv2.boundingRect(contour)
    return (w - 1) * (h - 1) >= MIN_AREA


def _mask(seed: int) -> np.ndarray:
    """Random specks and lines (many joined only at a corner), rings with a blob in the hole
    (large and small), a disc."""
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(20, 90, 2))
    mask = ((rng.random((h, w)) < 0.18) * 255).astype(np.uint8)
    for _ in range(6):
        x, y = (int(v) for v in rng.integers(0, [w, h]))
        r = int(rng.integers(3, 12))
        cv2.circle(mask, (x, y), r, 255, 1)
        cv2.circle(mask, (x, y), max(0, r // 3), 255, -1)
    cv2.circle(mask, (w // 2, h // 2), 5, 255, -1)
    return mask


@pytest.mark.parametrize("seed", range(40))
def test_cleared_mask_keeps_the_contours_find_discs_keeps(seed: int) -> None:
    mask = _mask(seed)
    want = [c for c in _contours(mask) if _boxed(c)]
    got = _contours(marker._without_specks(mask, MIN_AREA))
    assert len(got) == len(want)
    for a, b in zip(got, want):
        np.testing.assert_array_equal(a, b)
    assert all(_boxed(c) for c in got)


def test_specks_are_cleared() -> None:
    """The masks are worth comparing on: most of their contours are specks."""
    mask = _mask(0)
    assert len(_contours(mask)) > 3 * len(_contours(marker._without_specks(mask, MIN_AREA)))
