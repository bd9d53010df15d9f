"""Perception of the reference scene: the floor (a line in v-disparity) and the nearest object.

The floor of a camera looking along it has disparity growing linearly with the image row below
the horizon (d = B (y - cy) / h); it is the nearest thing in the lower rows, so it is fitted and
removed before the nearest object is sought. The nearest object is the connected region of
largest disparity with at least min_area pixels, and its disparity is a robust statistic (the
median) over that region, not a single pixel.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import cv2
import numpy as np

from host.errors import HostError


@dataclass(frozen=True)
class Floor:
    """Floor disparity d(y) = slope * y + offset (px), fitted on the lower rows."""

    slope: float
    offset: float

    def disparity(self, rows: np.ndarray) -> np.ndarray:
        return self.slope * rows + self.offset


def fit_floor(disp: np.ndarray, min_slope: float = 0.02) -> Floor | None:
    """Fit the floor in v-disparity over the lowest 40% of rows: each row's most common
    disparity (the floor fills most of a low row, at one disparity), then a line through them
    that outlying rows (an object filling a row) do not pull. None when the rows do not show a
    floor (no steady growth of disparity with the row)."""
    h = disp.shape[0]
    rows, modes = [], []
    for y in range(int(h * 0.6), h):
        row = disp[y][np.isfinite(disp[y])]
        if row.size < disp.shape[1] // 4:
            continue
        hist, edges = np.histogram(row, bins=np.arange(row.min(), row.max() + 0.5, 0.25))
        if hist.size:
            k = int(np.argmax(hist))
            rows.append(y)
            modes.append((edges[k] + edges[k + 1]) / 2)
    if len(rows) < 10:
        return None
    ys, ds = np.array(rows, float), np.array(modes, float)
    keep = np.ones(len(ys), bool)
    for _ in range(4):  # refit without the rows that an object dominates
        slope, offset = np.polyfit(ys[keep], ds[keep], 1)
        resid = np.abs(ds - (slope * ys + offset))
        keep = resid < max(0.5, 2.5 * float(np.median(resid[keep])))
        if keep.sum() < 10:
            return None
    return Floor(float(slope), float(offset)) if slope > min_slope else None


def without_floor(disp: np.ndarray, floor: Floor | None, tol_px: float = 1.0) -> np.ndarray:
    """disp with the floor's pixels set to NaN."""
    if floor is None:
        return disp
    rows = np.arange(disp.shape[0], dtype=np.float32)[:, None]
    out = disp.copy()
    out[np.abs(disp - floor.disparity(rows)) < tol_px] = np.nan
    return out


@dataclass(frozen=True)
class Target:
    disparity: float  # px, median over the region
    area: int  # px
    bbox: tuple[int, int, int, int]  # x, y, w, h
    spread: float  # px, interquartile range of the region's disparity


def nearest_object(disp: np.ndarray, min_area: int, step: float = 0.5) -> Target:
    """The connected region of largest disparity with at least min_area pixels.

    Thresholds sweep down from the largest disparity; the first level at which some connected
    region of pixels at or above it reaches min_area gives the object (speckle never grows to
    that size). Its disparity is the median over the region's pixels within 2 px of the level.
    """
    clean = cv2.medianBlur(np.nan_to_num(disp, nan=0.0).astype(np.float32), 5)
    clean[~np.isfinite(disp)] = 0.0
    top = float(np.percentile(clean[clean > 0], 99.9)) if (clean > 0).any() else 0.0
    level = top
    while level > step:
        mask = (clean >= level).astype(np.uint8)
        n, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=4)
        if n > 1:
            best = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
            if stats[best, cv2.CC_STAT_AREA] >= min_area:
                region = (labels == best) & (clean < level + 2.0)
                values = clean[region]
                q1, q2, q3 = np.percentile(values, [25, 50, 75])
                x, y, w, h = (int(v) for v in stats[best, :4])
                return Target(float(q2), int(stats[best, cv2.CC_STAT_AREA]), (x, y, w, h),
                              float(q3 - q1))
        level -= step
    raise HostError(f"no object of at least {min_area} px found in the reference scene")


def reference_target(disps: list[np.ndarray], min_area: int) -> tuple[Target, Floor | None]:
    """Target from several disparity maps of the scene without the robot (per-pixel median)."""
    stack = np.stack(disps)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # pixels invalid in every map stay NaN
        median = np.nanmedian(stack, axis=0) if len(disps) > 1 else stack[0]
    floor = fit_floor(median)
    return nearest_object(without_floor(median, floor), min_area), floor


def match_exposure(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """The right view with the left's exposure: each channel scaled and shifted so its mean and
    spread equal the left's (the Minoru's two sensors expose and balance separately, and a
    sum of absolute differences reads every grey level of difference as mismatch)."""
    lf, rf = left.reshape(-1, *left.shape[2:]), right.reshape(-1, *right.shape[2:])
    lm, ls = lf.mean(axis=0), lf.std(axis=0)
    rm, rs = rf.mean(axis=0), rf.std(axis=0)
    scale = ls / np.maximum(rs, 1e-6)
    out = (right.astype(np.float32) - rm) * scale + lm
    return np.clip(np.rint(out), 0, 255).astype(np.uint8)
