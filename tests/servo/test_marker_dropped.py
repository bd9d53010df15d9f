"""find_discs clears, besides the specks, the blobs whose box it drops for its aspect before
tracing contours (marker._without_dropped, issue 25): the contours left are the whole mask's,
in the same order, less only ones whose box find_discs drops; every one it keeps is there. On
random masks with lines, specks, and elongated rings holding a disc in their hole (the ring
must stay, or the disc would become an outer contour) or only specks."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from host.servo import marker

MIN_AREA = math.pi * 2.5 ** 2


def _contours(mask: np.ndarray) -> list[np.ndarray]:
    return list(cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)[0])


def _kept(contour: np.ndarray) -> bool:
    """find_discs' box tests (marker_oracle.find_discs)."""
    x, y, w, h = cv2.boundingRect(contour)
    return 0.75 < w / h < 1.33 and (w - 1) * (h - 1) >= MIN_AREA


def _mask(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(20, 120, 2))
    mask = ((rng.random((h, w)) < float(rng.uniform(0, 0.2))) * 255).astype(np.uint8)
    for _ in range(int(rng.integers(2, 8))):
        x, y = (int(v) for v in rng.integers(0, [w, h]))
        a, b = (int(v) for v in rng.integers(3, 25, 2))
        kind = int(rng.integers(0, 4))
        if kind == 0:  # an elongated ring, a disc (or a speck) in its hole
            cv2.ellipse(mask, (x, y), (a, max(2, a // 2)), float(rng.choice([0, 90])), 0, 360,
                        255, 1)
            cv2.circle(mask, (x, y), int(rng.integers(0, 4)), 255, -1)
        elif kind == 1:  # a line
            cv2.line(mask, (x, y), (x + a, y + int(rng.integers(-3, 4))), 255,
                     int(rng.integers(1, 3)))
        elif kind == 2:  # a round ring, an elongated blob in it
            cv2.circle(mask, (x, y), a, 255, 1)
            cv2.ellipse(mask, (x, y), (max(1, a // 2), max(1, a // 5)), 0, 0, 360, 255, -1)
        else:
            cv2.circle(mask, (x, y), b // 2, 255, -1)
    return mask


def _left(whole: list[np.ndarray], got: list[np.ndarray]) -> list[int]:
    """The indices in whole of the contours got, in order (got a subsequence of whole)."""
    out, i = [], 0
    for c in got:
        while not (whole[i].shape == c.shape and np.array_equal(whole[i], c)):
            i += 1  # IndexError: c is not one of the whole mask's, in order
        out.append(i)
        i += 1
    return out


@pytest.mark.parametrize("seed", range(60))
def test_cleared_mask_keeps_every_contour_find_discs_keeps(seed: int) -> None:
    mask = _mask(seed)
    whole = _contours(mask)
    left = _left(whole, _contours(marker._without_dropped(mask, MIN_AREA)))
    assert [i for i, c in enumerate(whole) if _kept(c)] == [i for i in left if _kept(whole[i])]


def test_lines_are_cleared() -> None:
    """The masks are worth comparing on: lines go, and some stay for what their box holds."""
    dropped = held = 0
    for seed in range(60):
        mask = _mask(seed)
        whole = [c for c in _contours(mask)
                 if (lambda b: (b[2] - 1) * (b[3] - 1) >= MIN_AREA)(cv2.boundingRect(c))]
        got = _contours(marker._without_dropped(mask, MIN_AREA))
        dropped += len(whole) - len(got)
        held += sum(not _kept(c) for c in got)
    assert dropped > 60 and held > 5
