"""Pictures and numbers for the page: the colour-mapped disparity map, its colour bar, the
overlay geometry, and JPEG encoding. Pure functions on arrays."""

from __future__ import annotations

import math
from typing import Any

import cv2
import numpy as np

from host.camera.geometry import Geometry
from host.servo.snapshot import Snapshot

INVALID_BGR = (128, 128, 128)  # pixels without a disparity: plain grey (not in the colour map)
COLORMAP = cv2.COLORMAP_TURBO


def disparity_range(disp: np.ndarray, step: int = 8) -> tuple[float, float]:
    """Colour range (px) for a map: 0 to its 99.5th percentile rounded up to a multiple of
    step, so that the colour bar stays put from frame to frame."""
    valid = disp[np.isfinite(disp)]
    top = float(np.percentile(valid, 99.5)) if valid.size else float(step)
    return 0.0, float(max(step, math.ceil(top / step) * step))


def colour_disparity(disp: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """BGR picture of a disparity map (px, NaN = invalid): turbo from lo (blue, far) to hi
    (red, near); invalid pixels grey."""
    valid = np.isfinite(disp)
    scaled = np.zeros(disp.shape, np.uint8)
    scaled[valid] = np.clip((disp[valid] - lo) * (255.0 / (hi - lo)), 0, 255).astype(np.uint8)
    out = cv2.applyColorMap(scaled, COLORMAP)
    out[~valid] = INVALID_BGR
    return out


def colour_stops(n: int = 16) -> list[str]:
    """The colour map as n CSS colours, low to high, for the page's colour bar."""
    ramp = cv2.applyColorMap(np.linspace(0, 255, n).astype(np.uint8)[:, None], COLORMAP)
    return [f"rgb({r},{g},{b})" for b, g, r in ramp[:, 0]]


def colour_ticks(lo: float, hi: float, geometry: Geometry | None, n: int = 5
                 ) -> list[dict[str, Any]]:
    """Tick marks of the colour bar: disparity in px and, where it is positive and the geometry
    known, depth in m."""
    ticks = []
    for px in np.linspace(lo, hi, n):
        depth = geometry.depth_m(float(px)) if geometry is not None and px > 0 else None
        ticks.append({"px": round(float(px), 1), "m": None if depth is None else round(depth, 2)})
    return ticks


def compose_map(full: np.ndarray | None, band: np.ndarray | None, y0: int,
                shape: tuple[int, int]) -> np.ndarray:
    """The page's disparity map: the last full map with this step's band of rows laid over it
    (the servo matches only a band round the marker); NaN where nothing was computed."""
    out = full.copy() if full is not None and full.shape == shape else np.full(shape, np.nan,
                                                                               np.float32)
    if band is not None and band is not full:
        out[y0:y0 + band.shape[0], :band.shape[1]] = band
    return out


def _num(v: float | None, digits: int = 2) -> float | None:
    return None if v is None or not math.isfinite(v) else round(float(v), digits)


def _depth(geometry: Geometry, disparity: float | None) -> float | None:
    if disparity is None or not math.isfinite(disparity) or disparity <= 0:
        return None
    return geometry.depth_m(disparity)


def overlay(snap: Snapshot) -> dict[str, Any]:
    """What the page draws over the left image, in image pixels: the target region and its
    disparity/depth, the marker as found in the left and in the right view, the robot's
    disparity/depth."""
    g = snap.geometry
    out: dict[str, Any] = {"target": None, "marker": None}
    if snap.target is not None:
        x, y, w, h = snap.target.bbox
        out["target"] = {"x": x, "y": y, "w": w, "h": h, "px": _num(snap.target.disparity),
                         "m": _num(_depth(g, snap.target.disparity), 3)}
    if snap.marker_pair is not None:
        left, right = snap.marker_pair.left, snap.marker_pair.right
        out["marker"] = {"left": [_num(left.u, 1), _num(left.v, 1), _num(left.radius, 1)],
                         "right": [_num(right.u, 1), _num(right.v, 1), _num(right.radius, 1)],
                         "px": _num(snap.marker_pair.disparity),
                         "m": _num(_depth(g, snap.marker_pair.disparity), 3)}
    return out


def encode_jpeg(image: np.ndarray, quality: int = 80) -> bytes:
    ok, buf = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, quality])
    if not ok:
        raise ValueError("JPEG encoding failed")
    return buf.tobytes()
