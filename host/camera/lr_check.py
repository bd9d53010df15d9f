"""Is the left view really the left one? The median disparity sign over textured pixels.

In a correct pair a scene point is further right in the left view (disparity > 0); swapped
views give mostly negative disparities. Matching runs over -max..+max, so both signs compete.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

CHECKS = ("refuse", "auto", "off")


@dataclass(frozen=True)
class Handedness:
    """median_px: median disparity over textured, matched pixels; pixels: how many."""

    median_px: float
    pixels: int
    share: float  # pixels / image area

    @property
    def conclusive(self) -> bool:
        return self.share >= 0.01 and abs(self.median_px) >= 0.5

    @property
    def swapped(self) -> bool:
        return self.conclusive and self.median_px < 0


def _grey(img: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(img, cv2.COLOR_BGR2GRAY) if img.ndim == 3 else img


def handedness(left: np.ndarray, right: np.ndarray, max_disp: int | None = None,
               min_contrast: float = 6.0) -> Handedness:
    """Median signed disparity (px) of a pair over pixels with texture (local standard
    deviation >= min_contrast grey levels) that SGBM matched uniquely."""
    gl, gr = _grey(left), _grey(right)
    h, w = gl.shape
    nd = max_disp or max(16, (w // 4) // 16 * 16)
    sgbm = cv2.StereoSGBM_create(  # type: ignore[attr-defined]  # absent from cv2's stubs
        minDisparity=-nd, numDisparities=2 * nd, blockSize=7, P1=8 * 49, P2=32 * 49,
        uniquenessRatio=10, mode=cv2.STEREO_SGBM_MODE_SGBM)
    disp = sgbm.compute(gl, gr).astype(np.float32) / 16.0
    f = gl.astype(np.float32)
    std = np.sqrt(np.maximum(cv2.blur(f * f, (7, 7)) - cv2.blur(f, (7, 7)) ** 2, 0))
    ok = (disp > -nd) & (std >= min_contrast)
    ok[:, :nd] = ok[:, w - nd:] = False  # where one view cannot see the other's match
    vals = disp[ok]
    median = float(np.median(vals)) if vals.size else 0.0
    return Handedness(median, int(vals.size), vals.size / float(h * w))
