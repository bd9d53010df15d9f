"""Mains flicker read by rolling shutters taken out of a stereo pair: each row's light factor.

A rolling shutter reads its rows one after the other, so light varying at 100 Hz multiplies
each row by its own factor (a band pattern, 80 rows a period at 320x240 with a 30 ms readout),
and the two sensors, a few ms apart, see different bands. The marker's ring is then no longer
uniform and its disc no longer darker than its neighbourhood on every row: it is missed two
frames in three. The factor of each row of the left view is the median over the row of its
ratio to the reference image (the scene without the robot: the robot covers a few columns of a
row, the median ignores them); the right view's is the left's times the ratio of the two rows'
medians (both views see the same row of the scene). A pure function on arrays; the servo uses
it only to search again for a marker it missed, and whatever it finds goes through the same
gate, size and block-matching checks as any sighting.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from host.camera.source import StereoFrame
from host.stereo.grey import to_grey

MIN_SPREAD = 0.05  # rows' factors spread less than this (5th to 95th percentile): no flicker


def row_gains(grey: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Each row's light factor (float32, height) of grey against reference (same size, the
    reference phase's left image, float32), smoothed over 5 rows."""
    step = max(1, grey.shape[1] // 80)  # 80 columns or so: the median of a row is robust
    ratio = grey[:, ::step].astype(np.float32) / np.maximum(reference[:, ::step], 8.0)
    gains = _row_medians(ratio).astype(np.float32)
    smooth: np.ndarray = cv2.medianBlur(gains.reshape(-1, 1), 5)
    return smooth.ravel()


def _row_medians(a: np.ndarray) -> np.ndarray:
    """np.median(a, axis=1) of a float array, exactly, from a sort of the rows (a quarter of
    median's CPU on 240 rows of 80: its partition and checks cost more than the sort): the
    middle element, or the two middle ones' mean in a's precision as np.mean takes it. A row
    holding NaN goes to np.median (its median is NaN)."""
    n = a.shape[1]
    if not n or np.isnan(a).any():
        median: np.ndarray = np.median(a, axis=1)
        return median
    s = np.sort(a, axis=1)
    if n % 2:
        middle: np.ndarray = s[:, n // 2]
        return middle
    out: np.ndarray = s[:, n // 2 - 1] + s[:, n // 2]
    out /= 2
    return out


def _spread_reaches(gains: np.ndarray, min_spread: float) -> bool:
    """Whether the gains' 5th to 95th percentile (np.percentile's) spread at least
    min_spread. Each percentile lies between the sorted gains on either side of its place, so
    the sorted gains alone decide, but within a millionth of the limit, where np.percentile
    does (its argument handling costs more than the rest of deflickered without flicker)."""
    n = gains.size
    if not n or np.isnan(gains).any():
        lo, hi = np.percentile(gains, [5, 95])
        return bool(hi - lo >= min_spread)
    s = np.sort(gains.astype(np.float64))
    i5, i95 = (n - 1) * 0.05, (n - 1) * 0.95
    lo_least, lo_most = s[max(0, math.floor(i5) - 1)], s[min(n - 1, math.ceil(i5) + 1)]
    hi_least, hi_most = s[max(0, math.floor(i95) - 1)], s[min(n - 1, math.ceil(i95) + 1)]
    if hi_most - lo_least < min_spread - 1e-6:
        return False
    if hi_least - lo_most >= min_spread + 1e-6:
        return True
    lo, hi = np.percentile(gains, [5, 95])
    return bool(hi - lo >= min_spread)


def _scaled(image: np.ndarray, gains: np.ndarray) -> np.ndarray:
    inv = (1.0 / np.maximum(gains, 0.2)).astype(np.float32)
    shape = (-1, 1, 1) if image.ndim == 3 else (-1, 1)
    out: np.ndarray = np.clip(image.astype(np.float32) * inv.reshape(shape), 0, 255)
    return out.astype(np.uint8)


def deflickered(frame: StereoFrame, reference: np.ndarray,
                min_spread: float = MIN_SPREAD) -> StereoFrame | None:
    """The pair with each row of each view divided by its light factor, or None when the rows'
    factors do not vary (no flicker: nothing to take out). reference: the left image of the
    reference phase (grey, float32, host.servo.rig.reference_image)."""
    left, right = to_grey(frame.left), to_grey(frame.right)
    if left.shape != reference.shape:
        return None
    g_left = row_gains(left, reference)
    if not _spread_reaches(g_left, min_spread):
        return None
    with np.errstate(invalid="ignore", divide="ignore"):
        step = max(1, left.shape[1] // 80)
        rows = np.median(right[:, ::step], axis=1) / np.maximum(
            np.median(left[:, ::step], axis=1), 1.0)
    g_right = g_left * cv2.medianBlur(rows.astype(np.float32).reshape(-1, 1), 5).ravel()
    return StereoFrame(_scaled(frame.left, g_left), _scaled(frame.right, g_right),
                       frame.t_left, frame.t_right)
