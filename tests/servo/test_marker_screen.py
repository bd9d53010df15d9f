"""find_discs' shape tests in one numba pass (marker._screen) keep exactly the outlines the
OpenCV calls kept (issue 25): every outline's bounding box is cv2.boundingRect's, its area
cv2.contourArea's and its perimeter cv2.arcLength's to the last bit, and the outlines passing
are those the tests written with those calls pass, on random masks (discs, ellipses, squares,
rings, specks, noise, shapes cut by the border) and on the dark masks of rendered frames."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from host.servo import marker
from tests.servo.test_marker_speedup import FRAMES

MIN_AREA = math.pi * 2.5 ** 2
MAX_AREA = math.pi * 80.0 ** 2


def _random_mask(rng: np.random.Generator) -> np.ndarray:
    h, w = (int(v) for v in rng.integers(8, 130, 2))
    mask = np.zeros((h, w), np.uint8)
    for _ in range(int(rng.integers(1, 25))):
        cx, cy = (float(v) for v in rng.uniform(-10, [w + 10, h + 10]))
        a, b = (float(v) for v in rng.uniform(0.5, 30, 2))
        kind = int(rng.integers(0, 5))
        if kind == 0:
            cv2.ellipse(mask, (round(cx), round(cy)), (round(a), round(b)),
                        float(rng.uniform(0, 180)), 0, 360, 255, -1)
        elif kind == 1:
            cv2.circle(mask, (round(cx), round(cy)), round(a), 255, -1)
        elif kind == 2:
            cv2.rectangle(mask, (round(cx), round(cy)), (round(cx + a), round(cy + a)), 255, -1)
        elif kind == 3:  # a ring: a blob with a hole, maybe a disc inside
            cv2.circle(mask, (round(cx), round(cy)), round(a) + 3, 255, 2)
        else:  # specks and texture
            y, x = rng.integers(0, h), rng.integers(0, w)
            mask[y:y + int(b // 4) + 1, x:x + int(a // 4) + 1] = 255
    if rng.random() < 0.3:  # texture over it all
        noise = rng.random((h, w)) < float(rng.uniform(0, 0.2))
        mask[noise] = 255 - mask[noise]
    return mask


def _dark_masks() -> list[np.ndarray]:
    out = []
    for left, right in FRAMES:
        for image in (left, right):
            grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY) if image.ndim == 3 else image
            for window in (31, 121):
                local = cv2.blur(grey, (window, window))
                out.append(cv2.compare(grey, cv2.subtract(local, np.full_like(local, 40)),
                                       cv2.CMP_LT))
    return out


def _old_screen(outlines: list[np.ndarray]) -> list[tuple[int, int, int, int, int]]:
    """The tests as find_discs wrote them with OpenCV's calls (marker_oracle.find_discs)."""
    out = []
    for i, c in enumerate(outlines):
        x, y, w, h = cv2.boundingRect(c)
        if not 0.75 < w / h < 1.33 or (w - 1) * (h - 1) < MIN_AREA:
            continue
        area = cv2.contourArea(c)
        if area < MIN_AREA or area > MAX_AREA:
            continue
        perimeter = cv2.arcLength(c, True)
        if perimeter <= 0 or 4 * math.pi * area / perimeter ** 2 < 0.7:
            continue
        out.append((i, x, y, w, h))
    return out


def _check(mask: np.ndarray) -> tuple[int, int]:
    outlines = list(cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)[0])
    if not outlines:
        return 0, 0
    sizes = np.array([c.shape[0] for c in outlines], np.intp)
    points = np.concatenate(outlines).reshape(-1, 2)
    start = 0
    for c, n in zip(outlines, sizes):
        assert marker._box(points, start, n) == cv2.boundingRect(c)
        area, perimeter = marker._area_and_perimeter(points, start, n)
        assert area == cv2.contourArea(c), (area, cv2.contourArea(c))
        assert perimeter == cv2.arcLength(c, True), (perimeter, cv2.arcLength(c, True))
        start += n
    got = [tuple(int(v) for v in t) for t in marker._screen(points, sizes, MIN_AREA, MAX_AREA)]
    want = _old_screen(outlines)
    assert got == want
    return len(outlines), len(want)


@pytest.mark.parametrize("seed", range(8))
def test_screen_is_opencvs_on_random_masks(seed: int) -> None:
    rng = np.random.default_rng(seed)
    outlines = kept = 0
    for _ in range(60):
        n, k = _check(_random_mask(rng))
        outlines, kept = outlines + n, kept + k
    assert kept > 0 and outlines > 5 * kept  # some pass, most do not: both sides compared


def test_screen_is_opencvs_on_rendered_frames() -> None:
    kept = sum(_check(mask)[1] for mask in _dark_masks())
    assert kept > 0
