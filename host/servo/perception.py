"""Perception of the reference scene: the floor (a line in v-disparity) and the nearest object.

The floor of a camera looking along it has disparity growing linearly with the image row below
the horizon (d = B (y - cy) / h); it is the nearest thing in the lower rows, so it is fitted and
removed before the nearest object is sought. The nearest object is the connected region of
largest disparity with at least min_area pixels, and its disparity is a robust statistic (the
median) over that region, not a single pixel. During the run the whole map for the target's
re-measure is matched a band of rows per frame (StripMap), so that no frame of the control loop
pays for all of it.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import cv2
import numpy as np

from host.errors import HostError
from host.stereo.matcher import compute_disparity, numba_threads
from host.stereo.params import MatcherParams

# pixel-disparities matched per frame for the re-measure's map: about 4 ms of SAD on one core,
# so 640x480 with 64 disparities takes four frames and 320x240 one
STRIP_WORK = 5_000_000
ROW_LOCAL = ("sad", "ssd", "ncc")  # matchers whose pixel depends only on the rows of its window


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


def nearest_object(disp: np.ndarray, min_area: int, step: float = 0.5,
                   near: float | None = None) -> Target:
    """The connected region of largest disparity with at least min_area pixels.

    Thresholds sweep down from the largest disparity; the first level at which some connected
    region of pixels at or above it reaches min_area gives the object (speckle never grows to
    that size). Its disparity is the median over the region's pixels within 2 px of the level.
    A lower level only adds pixels, so the largest region never shrinks as the level falls:
    the first level is found by doubling the step from a start, then halving the interval (a
    few labellings of the map instead of one per level). The start is the top, or the level
    nearest `near` (px; the last measure's disparity, where the answer usually is); the result
    is the same from any start.
    """
    clean = cv2.medianBlur(np.nan_to_num(disp, nan=0.0).astype(np.float32), 5)
    clean[~np.isfinite(disp)] = 0.0
    top = float(np.percentile(clean[clean > 0], 99.9)) if (clean > 0).any() else 0.0
    levels = []
    level = top
    while level > step:
        levels.append(level)
        level -= step
    seen: dict[int, tuple] = {}

    def reaches(k: int) -> bool:
        if k not in seen:
            mask = (clean >= levels[k]).astype(np.uint8)
            seen[k] = cv2.connectedComponentsWithStats(mask, connectivity=4)[:3]
        n, _, stats = seen[k]
        return n > 1 and int(stats[1:, cv2.CC_STAT_AREA].max()) >= min_area

    missing = f"no object of at least {min_area} px found in the reference scene"
    if not levels:
        raise HostError(missing)
    last = len(levels) - 1
    start = 0 if near is None else min(last, max(0, round((top - near) / step)))
    jump = 1
    if reaches(start):  # levels[below] does not reach min_area (-1: above the top), levels[k] does
        below, k = start - 1, start
        while below >= 0 and reaches(below):
            k, below, jump = below, max(-1, below - 2 * jump), 2 * jump
    else:
        below, k = start, min(last, start + 1)
        while not reaches(k):
            if k == last:
                raise HostError(missing)
            below, jump = k, 2 * jump
            k = min(last, k + jump)
    while k - below > 1:
        mid = (below + k) // 2
        below, k = (below, mid) if reaches(mid) else (mid, k)
    n, labels, stats = seen[k]
    best = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    region = (labels == best) & (clean < levels[k] + 2.0)
    q1, q2, q3 = np.percentile(clean[region], [25, 50, 75])
    x, y, w, h = (int(v) for v in stats[best, :4])
    return Target(float(q2), int(stats[best, cv2.CC_STAT_AREA]), (x, y, w, h), float(q3 - q1))


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
    sum of absolute differences reads every grey level of difference as mismatch). The map of
    each channel's 256 grey levels is applied as a look-up table."""
    lm, ls = (v.ravel() for v in cv2.meanStdDev(left))
    rm, rs = (v.ravel() for v in cv2.meanStdDev(right))
    scale = ls / np.maximum(rs, 1e-6)
    levels = np.arange(256, dtype=np.float64)[:, None]
    table = np.clip(np.rint((levels - rm) * scale + lm), 0, 255).astype(np.uint8)
    if right.ndim == 2:
        return cv2.LUT(right, table[:, 0])
    return cv2.LUT(right, table[:, None, :])


class StripMap:
    """The whole disparity map of the run's frames, matched one band of rows per frame.

    Each band is matched with the rows its windows (and the median filter) reach above and
    below it, which are then cut off, so every pixel gets the disparity a whole-map match of
    its frame would give. Matchers that are not row-local (SGM, OpenCV's) get the whole map in
    one frame. The matching runs on the calling thread: the control loop's frame budget, not
    the machine's other core. hide: the box (x0, y0, x1, y1) to leave out of this frame's band
    (the robot), NaN in the map.
    """

    def __init__(self, params: MatcherParams, shape: tuple[int, int],
                 work: int | None = None) -> None:
        """work: pixel-disparities to match per frame (default STRIP_WORK)."""
        h, w = shape
        self.params, self.shape = params, (h, w)
        work = work or STRIP_WORK
        n = math.ceil(h * w * params.num_disparities / work) if params.matcher in ROW_LOCAL else 1
        self.strips = max(1, min(n, h // max(1, params.block_size)))
        self.edges = [h * i // self.strips for i in range(self.strips + 1)]
        self.margin = params.block_size // 2 + params.median // 2
        self.next = 0  # the band the next frame matches; == strips: the map is complete
        self._map = np.empty((h, w), np.float32)

    @property
    def busy(self) -> bool:
        """A map has been started and not yet handed out."""
        return self.next > 0

    def reset(self) -> None:
        """Drop the bands matched so far; the next add starts a new map."""
        self.next = 0

    def add(self, left: np.ndarray, right: np.ndarray,
            hide: tuple[int, int, int, int] | None = None) -> np.ndarray | None:
        """Match the next band of this rectified pair; once every band is in, the next call
        matches nothing and returns the whole map (float32 px, NaN = invalid)."""
        if left.shape[:2] != self.shape:
            raise HostError(f"the frames are {left.shape[1]}x{left.shape[0]}, the map "
                            f"{self.shape[1]}x{self.shape[0]}")
        if self.next == self.strips:
            self.next = 0
            done, self._map = self._map, np.empty_like(self._map)
            return done
        h = self.shape[0]
        y0, y1 = self.edges[self.next], self.edges[self.next + 1]
        a, b = max(0, y0 - self.margin), min(h, y1 + self.margin)
        with numba_threads(1):
            band = compute_disparity(left[a:b], right[a:b], self.params)
        self._map[y0:y1] = band[y0 - a:y1 - a]
        if hide is not None:
            x0, hy0, x1, hy1 = hide
            self._map[max(y0, hy0):min(y1, hy1), x0:x1] = np.nan
        self.next += 1
        return None
