"""Disparity maps as colour pictures: turbo colour map, invalid pixels black; picture() adds
a colour bar in px and a legend for the invalid pixels below the map."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

_FONT = cv2.FONT_HERSHEY_SIMPLEX
_INVALID_LABEL = "no disparity"


def colourise(disp: np.ndarray, max_disparity: float | None = None) -> np.ndarray:
    """BGR uint8 picture of a disparity map (px, NaN = invalid); near is warm, far is cool."""
    valid = np.isfinite(disp)
    top = max_disparity or (float(np.nanmax(disp)) if valid.any() else 1.0)
    scaled = np.clip(np.nan_to_num(disp) / max(top, 1e-6) * 255.0, 0, 255).astype(np.uint8)
    pic = cv2.applyColorMap(scaled, cv2.COLORMAP_TURBO)
    pic[~valid] = 0
    return np.asarray(pic)


@dataclass(frozen=True)
class Legend:
    """Where the legend panel's parts are, in the panel's own pixels (below the map)."""

    width: int
    height: int
    scale: float  # font scale
    swatch: tuple[int, int, int, int]  # x, y, w, h of the black "no disparity" square
    bar: tuple[int, int, int, int]  # x, y, w, h of the colour bar (0 px at its left end)


def legend_layout(width: int) -> Legend:
    """The legend's layout for a panel `width` px wide (at least 240)."""
    s = max(1.0, width / 640)
    size = int(round(12 * s))
    pad = int(round(8 * s))
    (tw, _), _ = cv2.getTextSize(_INVALID_LABEL, _FONT, 0.4 * s, 1)
    bar_x = pad + size + pad // 2 + tw + 2 * pad
    bar_w = width - bar_x - 3 * pad
    return Legend(width, int(round(40 * s)), 0.4 * s, (pad, pad, size, size),
                  (bar_x, pad, bar_w, size))


def _ticks(top: float, room: int) -> list[float]:
    """Round tick values from 0 to top, at most about one per `room` / 5 pixels."""
    count = max(2, min(6, room // 60))
    raw = top / count
    step = 10 ** math.floor(math.log10(raw)) if raw > 0 else 1.0
    for k in (1, 2, 5, 10):
        if k * step >= raw:
            step *= k
            break
    return [i * step for i in range(int(top // step) + 1)]


def picture(disp: np.ndarray, max_disparity: float | None = None) -> np.ndarray:
    """The colourised map with a legend panel below it: a colour bar from 0 to the top
    disparity with ticks labelled in px, and a black square for pixels without a disparity."""
    valid = np.isfinite(disp)
    top = max_disparity or (float(np.nanmax(disp)) if valid.any() else 1.0)
    pic = colourise(disp, top)
    h, w = pic.shape[:2]
    lay = legend_layout(max(w, 240))
    panel = np.full((lay.height, lay.width, 3), 255, np.uint8)
    x, y, sw, sh = lay.swatch
    cv2.rectangle(panel, (x, y), (x + sw - 1, y + sh - 1), (0, 0, 0), -1)
    cv2.rectangle(panel, (x, y), (x + sw - 1, y + sh - 1), (128, 128, 128), 1)
    cv2.putText(panel, _INVALID_LABEL, (x + sw + sw // 3, y + sh - 2), _FONT, lay.scale,
                (0, 0, 0), 1, cv2.LINE_AA)
    bx, by, bw, bh = lay.bar
    ramp = np.linspace(0, 255, bw).astype(np.uint8)[None, :]
    panel[by:by + bh, bx:bx + bw] = cv2.applyColorMap(np.repeat(ramp, bh, 0),
                                                      cv2.COLORMAP_TURBO)
    for value in _ticks(top, bw):
        tx = bx + int(round(value / top * (bw - 1)))
        cv2.line(panel, (tx, by + bh), (tx, by + bh + bh // 3), (0, 0, 0), 1)
        label = f"{value:g}"
        (lw, lh), _ = cv2.getTextSize(label, _FONT, lay.scale, 1)
        cv2.putText(panel, label, (tx - lw // 2, by + bh + bh // 3 + lh + 3), _FONT, lay.scale,
                    (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(panel, "px", (bx + bw + bh // 2, by + bh - 2), _FONT, lay.scale, (0, 0, 0), 1,
                cv2.LINE_AA)
    if lay.width > w:  # a narrow map: pad it on the right to the legend's width
        pic = np.hstack([pic, np.full((h, lay.width - w, 3), 255, np.uint8)])
    return np.vstack([pic, panel])
