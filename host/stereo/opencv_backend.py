"""OpenCV's StereoBM and StereoSGBM behind the matcher interface (float px, NaN = invalid)."""

from __future__ import annotations

import cv2
import numpy as np

from host.stereo.grey import to_grey
from host.stereo.params import SGBM_MODES, MatcherParams


def _to_pixels(raw: np.ndarray, min_disparity: int) -> np.ndarray:
    # OpenCV returns disparity x16 (fixed point) and marks invalid as (minDisparity - 1) * 16.
    disp = raw.astype(np.float32) / 16.0
    disp[raw < min_disparity * 16] = np.nan
    return disp


def opencv_disparity(left: np.ndarray, right: np.ndarray, p: MatcherParams) -> np.ndarray:
    """Disparity of the left view in px (NaN = invalid); StereoBM works on grey, StereoSGBM on
    colour when p.colour is set and the input has it."""
    colour = p.colour and p.matcher == "opencv-sgbm" and left.ndim == 3
    if not colour:
        left, right = to_grey(left), to_grey(right)
    lr = -1 if p.lr_check is None else max(1, int(round(p.lr_check)))
    m: cv2.StereoBM | cv2.StereoSGBM
    if p.matcher == "opencv-bm":
        m = cv2.StereoBM.create(p.num_disparities, p.block_size)
        m.setPreFilterCap(max(1, min(63, p.pre_filter_cap)))
        m.setTextureThreshold(p.texture_threshold)
    else:
        cn = 3 if colour else 1
        area = cn * p.block_size * p.block_size
        m = cv2.StereoSGBM.create(
            minDisparity=p.min_disparity,
            numDisparities=p.num_disparities,
            blockSize=p.block_size,
            P1=p.p1 or 8 * area,
            P2=p.p2 or 32 * area,
            preFilterCap=p.pre_filter_cap,
            mode=SGBM_MODES[p.mode],
        )
    m.setMinDisparity(p.min_disparity)
    m.setUniquenessRatio(int(round(p.uniqueness_ratio)))
    m.setSpeckleWindowSize(p.speckle_window_size)
    m.setSpeckleRange(p.speckle_range)
    m.setDisp12MaxDiff(lr)
    return _to_pixels(m.compute(left, right), p.min_disparity)
