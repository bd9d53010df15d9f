"""Disparity maps as colour pictures: turbo colour map, invalid pixels black."""

from __future__ import annotations

import cv2
import numpy as np


def colourise(disp: np.ndarray, max_disparity: float | None = None) -> np.ndarray:
    """BGR uint8 picture of a disparity map (px, NaN = invalid); near is warm, far is cool."""
    valid = np.isfinite(disp)
    top = max_disparity or (float(np.nanmax(disp)) if valid.any() else 1.0)
    scaled = np.clip(np.nan_to_num(disp) / max(top, 1e-6) * 255.0, 0, 255).astype(np.uint8)
    pic = cv2.applyColorMap(scaled, cv2.COLORMAP_TURBO)
    pic[~valid] = 0
    return pic
