"""Perception of the reference scene: the floor (a line in v-disparity) and the nearest object.

The floor of a camera looking along it has disparity growing linearly with the image row below
the horizon (d = B (y - cy) / h); it is the nearest thing in the lower rows, so it is fitted and
removed before the nearest object is sought. The nearest object is the connected region of
largest disparity with at least min_area pixels, and its disparity is a robust statistic (the
median) over that region, not a single pixel. During the run the whole map for the target's
re-measure is matched a band of rows per frame (StripMap), so that no frame of the control loop
pays for all of it. The object's whole extent at its depth (object_extent) gives the lane's
keep-out; the lane ahead of the robot is watched for a new object within the stopping
distance (lane_window, match_window, lane_obstacle).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from host.camera.geometry import Geometry
from host.errors import HostError
from host.servo.pixel_median import nanmedian0
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


def camera_height(floor: Floor, baseline_m: float) -> float:
    """The camera's optical centre above the floor (m), from the floor fit: a floor point at
    row y shows d = B ((y - cy) cos p + f sin p) / h for a rig at height h pitched down by p,
    so the fit's slope is B cos p / h (h = B / slope within 0.06 % at 2 degrees of pitch). One
    source for the height every lane and fixed-object test measures from: a rig set up at
    another height, or knocked to a new one, is measured, not assumed."""
    return baseline_m / floor.slope


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


def span_overlap(a0: float, a1: float, b0: float, b1: float) -> float:
    """The overlap of intervals [a0, a1) and [b0, b1) as a share of the narrower (0 when
    either is empty): two regions' columns or rows, the same object when it is large."""
    narrower = min(a1 - a0, b1 - b0)
    return max(0.0, min(a1, b1) - max(a0, b0)) / narrower if narrower > 0 else 0.0


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
    seen: dict[int, tuple[int, np.ndarray, np.ndarray]] = {}
    too_few: set[int] = set()  # levels with fewer than min_area pixels in all: no region reaches

    def reaches(k: int) -> bool:
        if k in too_few:
            return False
        if k not in seen:
            mask = (clean >= levels[k]).astype(np.uint8)
            if np.count_nonzero(mask) < min_area:  # not labelled (dev 105: half the labellings)
                too_few.add(k)
                return False
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


def median_map(disps: list[np.ndarray]) -> np.ndarray:
    """The per-pixel median of several disparity maps (px, NaN where every map has none)."""
    stack = np.stack(disps)
    # np.nanmedian(stack, axis=0) to the bit, compiled (pixels invalid in every map stay NaN)
    return nanmedian0(stack) if len(disps) > 1 else stack[0]


def reference_target(disps: list[np.ndarray], min_area: int) -> tuple[Target, Floor | None]:
    """Target from several disparity maps of the scene without the robot (per-pixel median)."""
    median = median_map(disps)
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
        self.matched = 0  # bands matched since it was made (a frame matches at most one)
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
        self.matched += 1
        return None


# ------------------------------------------------------------ the object as it is, the lane


def object_extent(disp: np.ndarray, target: Target, tol_px: float | None = None,
                  share: float = 0.5, gap_px: int = 4) -> Target:
    """The target with its image region grown to the whole object at its depth.

    nearest_object's region is the part of the object at the first threshold level (on a box
    of uniform disparity, noise puts about half its pixels below it: 44 px wide where the box
    is 104 px). Here the object's columns are those where at least `share` of the target's
    rows hold a disparity within tol_px (default max(1, 6 %) of the target's) of the target's,
    and its extent the run of such columns through the region (gaps up to gap_px bridged);
    its rows likewise within those columns. A run that reaches the map's first or last valid
    column (left of the search range nothing is matched) reaches the image's edge, so the
    region then starts at column 0 (or ends at the last). The floor at the object's depth fills
    only a few rows and does not widen it.

    disp: the map (px, NaN invalid; the floor removed or not, the robot's region NaN); returns a
    Target with the same disparity and spread, the whole object's bbox (x, y, w, h) and its
    area in px (pixels within tol_px inside the bbox). Wiring: the keep-out comes from this
    bbox (loop's _extent(object_extent(map, target))).
    """
    h, w = disp.shape
    d = target.disparity
    tol = tol_px if tol_px is not None else max(1.0, 0.06 * d)
    x, y, bw, bh = target.bbox
    with np.errstate(invalid="ignore"):
        near = np.abs(disp - d) <= tol
    cols = near[y:y + bh].mean(axis=0) >= share
    x0, x1 = _run_through(cols, x, x + bw - 1, gap_px)
    if x0 is None or x1 is None:
        return target
    valid_cols = np.flatnonzero(np.isfinite(disp[y:y + bh]).any(axis=0))
    if valid_cols.size and x0 <= valid_cols[0] + 1:
        x0 = 0
    if valid_cols.size and x1 >= valid_cols[-1] - 1:
        x1 = w - 1
    rows = near[:, x0:x1 + 1].mean(axis=1) >= share
    y0_, y1_ = _run_through(rows, y, y + bh - 1, gap_px)
    y0, y1 = (y, y + bh - 1) if y0_ is None or y1_ is None else (y0_, y1_)
    area = int(near[y0:y1 + 1, x0:x1 + 1].sum())
    return Target(d, area, (int(x0), int(y0), int(x1 - x0 + 1), int(y1 - y0 + 1)),
                  target.spread)


def _run_through(flags: np.ndarray, lo: int, hi: int, gap: int) -> tuple[int, int] | tuple[
        None, None]:
    """The run of True in flags (gaps up to gap bridged) that meets lo..hi: its first and last
    index; (None, None) when no flag in lo..hi is set."""
    inside = np.flatnonzero(flags[lo:hi + 1])
    if inside.size == 0:
        return None, None
    a, b = lo + int(inside[0]), lo + int(inside[-1])
    on = np.flatnonzero(flags)
    while True:  # extend left
        left = on[(on < a) & (on >= a - gap - 1)]
        if left.size == 0:
            break
        a = int(left[0])
    while True:  # extend right
        right = on[(on > b) & (on <= b + gap + 1)]
        if right.size == 0:
            break
        b = int(right[-1])
    return a, b


def stopping_distance_m(speed_mps: float, reaction_s: float = 0.25, tau_s: float = 0.08,
                        margin_m: float = 0.10) -> float:
    """How far ahead of its front the robot must see an object to stop short of it (m): the
    distance run before the STOP acts (reaction_s: a frame, the matching, the link and the
    actuation latency), the motors' run-down (a first-order lag of tau_s coasts speed * tau_s)
    and a margin."""
    v = abs(speed_mps)
    return margin_m + v * (reaction_s + tau_s)


@dataclass(frozen=True)
class LaneWindow:
    """The part of the picture where an object in the robot's lane within reach would be seen:
    the left-image box (x0, y0, x1, y1, end exclusive) and the search range to match it with
    (min_disparity, num_disparities, a multiple of 16): from 0 to beyond both the stretch's
    nearer end and the robot itself, so that what lies nearer or farther than the stretch
    (the robot in front of it, the wall behind) is matched where it is rather than into wrong
    matches inside a cut range."""

    box: tuple[int, int, int, int]
    min_disparity: int
    num_disparities: int
    d_near: float  # px, the disparity at the nearer end of the watched stretch
    d_far: float  # px, at the farther end


def lane_window(geometry: Geometry, size: tuple[int, int], depth_m: float, lateral_m: float,
                direction: int, reach_m: float, *, camera_height_m: float,
                half_width_m: float = 0.12, body_m: float = 0.10, height_m: float = 0.30
                ) -> LaneWindow | None:
    """Where to watch the lane: the stretch from body_m to body_m + reach_m ahead of the robot's
    centre (direction +1: moving away from the camera, -1: toward it), half_width_m each side
    of its line (x = lateral_m), from the floor to height_m. depth_m, lateral_m: the robot's
    (m, from its marker); size: (width, height) of the picture; camera_height_m: the camera's
    optical centre above the floor (camera_height). None when the stretch leaves
    the camera's near range (nearer than 0.25 m) or the picture. Match this box with the
    window's range (match_window), then lane_obstacle on the map."""
    w, h = size
    z_a = depth_m + direction * body_m
    z_b = depth_m + direction * (body_m + reach_m)
    near_z, far_z = min(z_a, z_b), max(z_a, z_b)
    if near_z < 0.25:
        return None
    f, b, cx, cy = geometry.focal_px, geometry.baseline_m, geometry.cx, geometry.cy
    us = [cx + f * (lateral_m + s * half_width_m) / z for s in (-1, 1) for z in (near_z, far_z)]
    vs = [cy + f * (camera_height_m - y) / z for y in (0.0, height_m) for z in (near_z, far_z)]
    x0, x1 = max(0, int(math.floor(min(us)))), min(w, int(math.ceil(max(us))) + 1)
    y0, y1 = max(0, int(math.floor(min(vs)))), min(h, int(math.ceil(max(vs))) + 1)
    if x0 >= x1 or y0 >= y1:
        return None
    d_near, d_far = f * b / near_z, f * b / far_z
    top = max(d_near, f * b / depth_m) + 4
    return LaneWindow((x0, y0, x1, y1), 0, 16 * max(1, math.ceil(top / 16)), d_near, d_far)


def match_window(left: np.ndarray, right: np.ndarray, params: MatcherParams,
                 window: LaneWindow) -> np.ndarray:
    """The disparity map (px, NaN invalid and outside the window) of the window's box, matched
    with its disparity range and a left-right check (1 px: occluded pixels beside the robot
    are invalid, not wrong matches): only its rows, its columns and, to their left, the search
    range in the right view (the loop's marker-window match does the same)."""
    h, w = left.shape[:2]
    x0, y0, x1, y1 = window.box
    pad = params.block_size // 2 + params.median // 2
    a, b = max(0, y0 - pad), min(h, y1 + pad)
    reach = window.min_disparity + window.num_disparities
    c0, c1 = max(0, x0 - reach - pad), min(w, x1 + pad)
    p = params.replace(min_disparity=window.min_disparity,
                       num_disparities=window.num_disparities, lr_check=1.0)
    with numba_threads(1):
        band = compute_disparity(left[a:b, c0:c1], right[a:b, c0:c1], p)
    out = np.full((h, w), np.nan, np.float32)
    out[y0:y1, x0:x1] = band[y0 - a:y1 - a, x0 - c0:x1 - c0]
    return out


@dataclass(frozen=True)
class LaneObstacle:
    depth_m: float  # the object's depth (median over its pixels)
    ahead_m: float  # from the robot's centre, along its motion
    pixels: int


def lane_obstacle(disp: np.ndarray, geometry: Geometry, depth_m: float, lateral_m: float,
                  direction: int, reach_m: float, reference: np.ndarray | None = None, *,
                  camera_height_m: float, half_width_m: float = 0.12, body_m: float = 0.10,
                  floor_clear_m: float = 0.03, height_m: float = 0.30, tol_px: float = 1.0,
                  min_size_m: float = 0.04, robot_px: int = 4) -> LaneObstacle | None:
    """An object in the robot's lane within reach_m ahead of its front, or None.

    Each valid pixel of disp is a point in the world (x = B (u - cx) / d, z = f B / d, height
    above the floor = camera_height_m - B (v - cy) / d, camera_height_m from the floor fit:
    camera_height). Counted: points in the stretch from body_m to body_m + reach_m ahead of
    the robot's centre (depth_m, direction +1 away from the camera, -1 toward it), within
    half_width_m of its line (lateral_m), higher than floor_clear_m above the floor (the
    floor is never an obstacle, whatever the floor fit says) and below height_m, not within
    robot_px of a pixel at the robot's own disparity (the mismatches along its silhouette),
    and, with a reference map (the scene without the robot, same geometry), nearer than what
    the reference had there by tol_px (the object the robot drives to and the wall are not
    new). The largest connected patch of such pixels, if it covers at least a min_size_m
    square at its depth ((min_size_m f / z)^2 px; at least 25): the obstacle, at its median
    depth. Moving away from the camera the robot hides what is right behind it: a low object
    is seen only beside or above it.

    A result (not None) means: stop now, before it closes; reach_m is the stopping distance at
    the current speed (stopping_distance_m) plus any margin.
    """
    g = geometry
    fb = g.focal_px * g.baseline_m
    # only the box round disp's valid pixels (match_window's box): the same pixels, in the same
    # order, at a fraction of the whole map's CPU
    whole, finite = disp, np.isfinite(disp)
    rows, cols = np.flatnonzero(finite.any(1)), np.flatnonzero(finite.any(0))
    if not rows.size:
        return None
    r0, c0 = int(rows[0]), int(cols[0])
    disp = disp[r0:int(rows[-1]) + 1, c0:int(cols[-1]) + 1]
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(disp) & (disp > 0.5)
        robot = (np.abs(disp - fb / depth_m) < 1.5).astype(np.uint8)
    if robot_px and robot.any():  # nothing of the robot's disparity lies outside the box
        k = 2 * robot_px + 1
        ok &= cv2.dilate(robot, np.ones((k, k), np.uint8)) == 0
    vs, us = np.nonzero(ok)
    if vs.size == 0:
        return None
    d = disp[vs, us].astype(np.float64)
    box_vs, box_us = vs, us
    vs, us = vs + r0, us + c0
    z = fb / d
    x = g.baseline_m * (us - g.cx) / d
    y = camera_height_m - g.baseline_m * (vs - g.cy) / d
    ahead = (z - depth_m) * direction
    keep = ((ahead >= body_m) & (ahead <= body_m + reach_m) & (np.abs(x - lateral_m)
            <= half_width_m) & (y > floor_clear_m) & (y < height_m))
    if reference is not None:
        ref = reference[vs, us]
        with np.errstate(invalid="ignore"):
            keep &= ~(ref >= d - tol_px)  # NaN in the reference: unknown, so new
    if int(keep.sum()) < 25:
        return None
    mask = np.zeros(disp.shape, np.uint8)
    mask[box_vs[keep], box_us[keep]] = 1
    _, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    areas = stats[1:, cv2.CC_STAT_AREA]
    if np.count_nonzero(areas == areas.max()) > 1:
        # patches of the same size: the first in the whole map's numbering is the one taken
        on_whole = np.zeros(whole.shape, np.uint8)
        on_whole[vs[keep], us[keep]] = 1
        _, labels, stats, _ = cv2.connectedComponentsWithStats(on_whole, connectivity=8)
        disp = whole
    best = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    zm = float(np.median(fb / disp[labels == best]))
    area = int(stats[best, cv2.CC_STAT_AREA])
    if area < max(25.0, (min_size_m * g.focal_px / zm) ** 2):
        return None
    return LaneObstacle(zm, (zm - depth_m) * direction, area)


def fixed_cells(disp: np.ndarray, geometry: Geometry, *, camera_height_m: float,
                cell_m: float = 0.02, min_height_m: float = 0.05, floor_clear_m: float = 0.03,
                height_m: float = 0.30) -> np.ndarray:
    """Where the scene's fixed objects stand, seen from above: the (depth, lateral) centres (m)
    of the cell_m x cell_m floor cells that hold an upright face, as an (n, 2) array. A cell's
    points are those of the map between floor_clear_m and height_m above the floor (the
    robot's height; the floor is never an object); it holds a face when they rise at least
    min_height_m, span two image columns or more, and number at least half of what a face
    cell_m wide and min_height_m tall at that depth shows. disp: the reference map (the scene
    without the robot, px, NaN invalid); camera_height_m: from the floor fit (camera_height).
    A box's front face fills each cell it stands on with hundreds of points; a mismatch (the
    near floor beyond the search range, the first valid column) puts a few dozen in a small
    patch or a single column. The target is among them (the controller leaves its extent to
    the keep-out)."""
    g = geometry
    with np.errstate(invalid="ignore"):
        vs, us = np.nonzero(np.isfinite(disp) & (disp > 0.5))
    d = disp[vs, us].astype(np.float64)
    y = camera_height_m - g.baseline_m * (vs - g.cy) / d
    keep = (y > floor_clear_m) & (y < height_m)
    d, y, u = d[keep], y[keep], us[keep]
    if d.size == 0:
        return np.zeros((0, 2))
    z = g.focal_px * g.baseline_m / d
    x = g.baseline_m * (u - g.cx) / d
    cells = np.stack([np.floor(z / cell_m), np.floor(x / cell_m)], axis=1).astype(np.int64)
    found, which, counts = np.unique(cells, axis=0, return_inverse=True, return_counts=True)
    which = which.ravel()
    n = len(found)
    y_lo, y_hi = np.full(n, np.inf), np.full(n, -np.inf)
    u_lo, u_hi = np.full(n, np.inf), np.full(n, -np.inf)
    np.minimum.at(y_lo, which, y)
    np.maximum.at(y_hi, which, y)
    np.minimum.at(u_lo, which, u)
    np.maximum.at(u_hi, which, u)
    zc = (found[:, 0] + 0.5) * cell_m
    face = 0.5 * (g.focal_px * cell_m / zc) * (g.focal_px * min_height_m / zc)
    ok = (y_hi - y_lo >= min_height_m) & (u_hi - u_lo >= 1) & (counts >= face)
    return np.asarray((found[ok] + 0.5) * cell_m, np.float64)


def fixed_in_path(cells: np.ndarray, depth_m: float, lateral_m: float, direction: int,
                  reach_m: float, half_width_m: float, cell_m: float = 0.02,
                  body_m: float = 0.10, own_m: float = 0.06) -> float | None:
    """How far ahead (m, from the robot's centre) the nearest of a fixed object's floor cells
    (fixed_cells) stands in the stretch the robot's body (half_width_m each side of its line
    at lateral_m) sweeps within body_m + reach_m ahead (direction +1: away from the camera,
    -1: toward it); None when the stretch is clear. A cell within own_m of the robot's
    centre is where the robot itself stands: a fixed object there means the sighting is of
    it (another robot's card, standing in the reference), which the acquisition's probe
    finds out, not an obstacle."""
    if not len(cells):
        return None
    ahead = (cells[:, 0] - depth_m) * direction
    hit = (ahead >= own_m) & (ahead <= body_m + reach_m) & (
        np.abs(cells[:, 1] - lateral_m) < half_width_m + cell_m / 2)
    return float(ahead[hit].min()) if hit.any() else None


def in_view(u: float, v: float, ring_px: float, size: tuple[int, int], scale: float = 1.0,
            cx: float | None = None, cy: float | None = None, margin_px: float = 2.0) -> bool:
    """Whether the marker's whole ring (centre u, v and radius ring_px in the left image) stays
    inside the picture, by margin_px, once the robot's depth has shrunk by the factor 1/scale
    (scale > 1: nearer the camera; image offsets from the centre cx, cy and sizes grow by it)."""
    w, h = size
    cx = (w - 1) / 2 if cx is None else cx
    cy = (h - 1) / 2 if cy is None else cy
    u2, v2, r2 = cx + (u - cx) * scale, cy + (v - cy) * scale, ring_px * scale + margin_px
    return r2 <= u2 <= w - 1 - r2 and r2 <= v2 <= h - 1 - r2


# ------------------------------------------------- the calibration's leftover, by column


BIAS_LIMIT_PX = 0.3  # a column bias this large somewhere is corrected (and said)
BIAS_NOISE_PX = 0.25  # and only by what it has beyond this: the floor's leftover on cameras
# whose calibration is right within 0.08 px reads 0.15-0.17 px (seed 16's camera 5), and
# seed 105's cameras 0, 8, 13 read -0.4..+0.5 at the picture's two ends; seed 16's camera
# 11 +0.61/+0.68 (trials 27, 299) at its left columns, for a true +0.7-1 px


@dataclass(frozen=True)
class ColumnBias:
    """How much too high (px) the rectified pair reads disparity, by column of the right view,
    measured on the floor (floor_column_bias). A calibration whose lens model is wrong where
    its boards did not reach (the image's edges) rectifies one view a fraction of a pixel off
    there: every disparity read at those columns is off by as much, whatever lies there."""

    excess: np.ndarray  # (w,) px, by column of the right view (smoothed; held at the ends)
    measured: int  # columns with floor enough to measure

    def applied(self, noise_px: float = BIAS_NOISE_PX) -> np.ndarray:
        """The excess trusted beyond the measure's noise: each column's shrunk toward 0 by
        noise_px (px)."""
        e = self.excess.astype(np.float32)
        return np.sign(e) * np.maximum(np.abs(e) - np.float32(noise_px), np.float32(0))

    @property
    def largest(self) -> float:
        """The largest excess (px, its sign kept)."""
        k = int(np.argmax(np.abs(self.excess)))
        return float(self.excess[k])

    def describe(self) -> str:
        """One line for the run's notes."""
        k = int(np.argmax(np.abs(self.excess)))
        return (f"the floor reads {self.excess[k]:+.2f} px of disparity off its fit at column "
                f"{k} of the right view (the calibration's lens model is off there): "
                f"disparities corrected by column")


LENS_MIDDLE_PX = 0.15  # a lens error leaves the middle half of the picture within this
# (seed 16's camera 11: 0.06 px there, for +0.53/+0.68 at its left sixteenth)
LENS_GROWTH = 0.1  # and grows toward its edge: each of the outer three sixteenths' means
# exceeds the next one inward by this fraction of the outermost at least (camera 11:
# 0.53, 0.29, 0.11, 0.02 and 0.68, 0.36, 0.20, 0.06 by sixteenth from the left edge)


def lens_shaped(bias: ColumnBias, middle_px: float = LENS_MIDDLE_PX,
                growth: float = LENS_GROWTH) -> bool:
    """Whether the excess has a lens error's shape: about 0 over the middle half of the
    picture (within middle_px) and growing toward the left or right edge over the outer
    quarter (each sixteenth's mean, toward the edge, at least growth x the outermost's above
    the one inside it). A flat layer on the floor (a mat, a board) reads as a plateau over
    its columns, not a growth: its excess is the scene's, not the calibration's, and a
    correction by it would read what stands on it farther than it is."""
    e = bias.excess.astype(np.float64)
    w = len(e)
    n = w // 16
    if n < 1 or np.abs(e[w // 4:w - w // 4]).max() > middle_px:
        return False
    side = e if abs(e[:n].mean()) >= abs(e[w - n:].mean()) else e[::-1]
    b = np.array([side[i * n:(i + 1) * n].mean() for i in range(4)])
    b *= np.sign(b[0]) if b[0] != 0 else 0.0
    return bool(b[0] > 0 and np.all(b[:3] - b[1:] >= growth * b[0]))


def bias_shrunk(before: ColumnBias, after: ColumnBias | None,
                noise_px: float = BIAS_NOISE_PX) -> bool:
    """Whether the leftover measured again on the corrected pair (after) is smaller than the
    one corrected (before) by half of the correction at least (at the column where before
    was largest; a correction that did not take the leftover out, or no floor measured
    after, is dropped)."""
    if after is None:
        return False
    k = int(np.argmax(np.abs(before.excess)))
    cut = float(np.abs(before.applied(noise_px)[k]))
    return bool(abs(float(after.excess[k])) <= abs(float(before.excess[k])) - cut / 2)


def floor_column_bias(disp: np.ndarray, floor: Floor | None, tol_px: float = 1.0,
                      min_pixels: int = 6, smooth_px: int = 21,
                      min_columns: int | None = None, edge_px: int = 6
                      ) -> ColumnBias | None:
    """The floor's leftover after its fit, by column of the right view (u - d): the median of
    disp - floor(y) less its row's median over the floor's pixels (within tol_px of the line,
    in the lowest 40 % of rows, a quarter of the row floor at least) that reach that column,
    then a running mean over smooth_px columns; columns
    without min_pixels of floor take the nearest measured one's. The fit is a line through
    each row's most common disparity, so a bias common to all columns goes into its offset
    and what is left is how the columns differ from the most of them: what a lens model
    wrong at the image's edges does. None without a floor or with fewer than min_columns
    (default a third of the width) measured."""
    if floor is None:
        return None
    h, w = disp.shape
    y0 = int(h * 0.6)
    rows = np.arange(y0, h, dtype=np.float64)[:, None]
    band = disp[y0:].astype(np.float64)
    with np.errstate(invalid="ignore"):
        resid = band - floor.disparity(rows)
        on = np.isfinite(band) & (np.abs(resid) < tol_px)
    # each row's leftover taken from its own (the line leaves a little in some rows, and the
    # rows that reach a column differ from column to column)
    counts_row = on.sum(axis=1)
    level = np.zeros(len(band))
    for i in np.flatnonzero(counts_row >= w // 4):
        level[i] = float(np.median(resid[i][on[i]]))
    on &= (counts_row >= w // 4)[:, None]
    vs, us = np.nonzero(on)
    right_col = np.rint(us - band[vs, us]).astype(np.int64)
    # not where a view's border cuts the matcher's window (edge_px from either edge of either)
    inside = (right_col >= edge_px) & (right_col < w - edge_px) & (us >= edge_px) & (
        us < w - edge_px)
    right_col, r = right_col[inside], (resid[vs, us] - level[vs])[inside]
    order = np.argsort(right_col, kind="stable")
    right_col, r = right_col[order], r[order]
    cols, starts, counts = np.unique(right_col, return_index=True, return_counts=True)
    med = np.full(w, np.nan)
    for c, s, n in zip(cols, starts, counts):
        if n >= min_pixels:
            med[c] = float(np.median(r[s:s + n]))
    known = np.flatnonzero(np.isfinite(med))
    if known.size < (w // 3 if min_columns is None else min_columns):
        return None
    filled = np.interp(np.arange(w), known, med[known])  # held flat beyond the ends
    k = max(1, smooth_px)
    padded = np.pad(filled, (k // 2, k - 1 - k // 2), mode="edge")
    smooth = np.convolve(padded, np.ones(k) / k, mode="valid")
    return ColumnBias(smooth.astype(np.float32), int(known.size))


def _bias_runs(applied: np.ndarray) -> list[tuple[int, int]]:
    """The runs [a, b) of columns where applied is non-zero."""
    on = np.concatenate(([False], applied != 0, [False]))
    edges = np.flatnonzero(on[1:] != on[:-1])
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]


_MAPS: dict[tuple[bytes, int, int, float], list[tuple[int, int, np.ndarray, np.ndarray]]] = {}


def _band_maps(bias: ColumnBias, h: int, w: int, noise_px: float
               ) -> list[tuple[int, int, np.ndarray, np.ndarray]]:
    """corrected_right's maps, only for the runs of columns with a correction, built once for
    a bias and size (the servo corrects every frame by the one bias)."""
    applied = bias.applied(noise_px)[:w]
    key = (applied.tobytes(), h, w, float(noise_px))
    maps = _MAPS.get(key)
    if maps is None:
        map_x = np.arange(w, dtype=np.float32) - applied
        maps = []
        for a, b in _bias_runs(applied):
            mx = np.ascontiguousarray(np.broadcast_to(map_x[a:b], (h, b - a)))
            my = np.ascontiguousarray(np.broadcast_to(
                np.arange(h, dtype=np.float32)[:, None], (h, b - a)))
            maps.append((a, b, mx, my))
        if len(_MAPS) > 8:
            _MAPS.clear()
        _MAPS[key] = maps
    return maps


def corrected_right(right: np.ndarray, bias: ColumnBias, noise_px: float = BIAS_NOISE_PX
                    ) -> np.ndarray:
    """The right view with each column's disparity excess beyond noise_px taken out
    (ColumnBias.applied): the pixel at column x taken from x - excess[x] (a view read too far
    left by e reads disparity e too high), so every disparity matched or measured on the pair
    afterwards (maps, the marker, a face's alignment) is as the bias-free pair's, within
    noise_px. Only the columns with a correction are resampled (the rest are the view's own:
    a whole-picture remap cost 0.8-1 ms a frame at 320x240), by maps built once."""
    h, w = right.shape[:2]
    maps = _band_maps(bias, h, w, noise_px)
    if not maps:
        return right
    out = right.copy()
    for a, b, mx, my in maps:
        out[:, a:b] = cv2.remap(right, mx, my, cv2.INTER_LINEAR,
                                borderMode=cv2.BORDER_REPLICATE)
    return out
