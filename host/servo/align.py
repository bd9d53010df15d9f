"""The target's disparity to a small fraction of a pixel: its face's two views aligned by one shift.

The disparity map's sub-pixel fit (a parabola through three SAD costs) is pixel-locked: on a face
at 20.35 px its values crowd toward 20, and the region's median is off by up to ~0.15 px, 0.9 cm
at 1.25 m (the largest term of the hold's error in the nominal world). One shift for the whole
face, found by Gauss-Newton on the squared difference of the left view and the right view moved
by it (cubic interpolation), has no such lock: the face is a plane parallel to the image, so all
its pixels share one disparity. The map says which pixels are the face (within band_px of its
disparity, the region's edges eroded off); the result is a refinement, not a new measure: a
shift that does not converge within max_step_px of the map's is not taken.
"""

from __future__ import annotations

import cv2
import numpy as np

from host.stereo.grey import to_grey

MIN_PIXELS = 200  # fewer face pixels than this (hidden, cut by the view's edge): no refinement
MAP_COLS = 4096  # the points sampled a row of the remap maps at a time (cv2.remap: < SHRT_MAX)


def aligned_disparity(left: np.ndarray, right: np.ndarray, disp: np.ndarray,
                      bbox: tuple[int, int, int, int], d0: float, band_px: float = 1.0,
                      erode_px: int = 3, max_step_px: float = 0.5, iterations: int = 8,
                      hide: tuple[int, int, int, int] | None = None) -> float:
    """The disparity (px) of the face in bbox (x, y, w, h) of the rectified views whose map
    disparity disp (px, NaN invalid) is d0: the shift of the right view that best matches the
    left over the face's pixels (map within band_px of d0, eroded by erode_px, outside hide
    (x0, y0, x1, y1), e.g. the robot's image box). d0 when there are too few such pixels, no
    texture, or the shift leaves max_step_px of d0."""
    x, y, w, h = bbox
    box = disp[y:y + h, x:x + w]
    face = (np.abs(np.nan_to_num(box, nan=-1e6) - d0) <= band_px).astype(np.uint8)
    if hide is not None:
        face[max(0, hide[1] - y):max(0, hide[3] - y), max(0, hide[0] - x):max(0, hide[2] - x)] = 0
    kernel = np.ones((2 * erode_px + 1, 2 * erode_px + 1), np.uint8)
    rows, cols = np.nonzero(cv2.erode(face, kernel))
    if len(rows) < MIN_PIXELS:
        return d0
    lg, rg = (to_grey(v).astype(np.float32) for v in (left, right))
    ys, xs = (rows + y).astype(np.float32), (cols + x).astype(np.float32)
    lp = lg[rows + y, cols + x]
    gradient = cv2.Sobel(rg, cv2.CV_32F, 1, 0, ksize=3) / 8
    d = d0
    for _ in range(iterations):
        shifted = _sample(rg, xs - d, ys)
        gx = _sample(gradient, xs - d, ys)
        den = float(gx @ gx)
        if den <= 0.0:
            return d0
        step = float((shifted - lp) @ gx) / den  # d(R(x - d))/dd = -gx
        d += step
        if abs(d - d0) > max_step_px:
            return d0
        if abs(step) < 1e-4:
            break
    return d


def _sample(image: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """image at the points (xs, ys) by cubic interpolation: cv2.remap takes maps of fewer than
    SHRT_MAX columns, so the points go in rows of MAP_COLS (each point's value does not depend
    on the map's shape)."""
    n = len(xs)
    rows = -(-n // MAP_COLS)
    mx = np.zeros(rows * MAP_COLS, np.float32)
    my = np.zeros(rows * MAP_COLS, np.float32)
    mx[:n], my[:n] = xs, ys
    out = cv2.remap(image, mx.reshape(rows, MAP_COLS), my.reshape(rows, MAP_COLS),
                    cv2.INTER_CUBIC)
    return np.asarray(out).ravel()[:n]
