"""The robot's marker: a dark disc inside a light ring (its radius RING_RATIO discs), printed
on both sides of a card on a mast, so that it shows whether the robot faces the camera or not.
ArUco (DICT_4X4_50, cv2.aruco.ArucoDetector) is the alternative.

Centres are sub-pixel: the intensity-weighted centroid of the disc's darkness. The robot's
disparity is the difference of the matched left and right centres (rectified: same row).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from numba import njit

from host.stereo.grey import to_grey

Window = tuple[int, int, int, int]  # x0, y0, x1, y1: a search window, columns x0:x1, rows y0:y1

RING_RATIO = 1.7  # the printed card: the light ring's outer radius in disc radii


@dataclass(frozen=True)
class Blob:
    u: float  # column, px
    v: float  # row, px
    radius: float  # px (vertical semi-axis of the disc)
    aspect: float = 1.0  # width / height of the disc: |cos| of the card's angle to the camera


@dataclass(frozen=True)
class MarkerPair:
    left: Blob
    right: Blob

    @property
    def disparity(self) -> float:
        return self.left.u - self.right.u


@njit(cache=True)
def _dark_opened(grey: np.ndarray, local: np.ndarray) -> np.ndarray:
    """The mask of the pixels darker than their neighbourhood's mean by 40 (255, else 0),
    opened with a 2x2 square to remove one-pixel specks: what cv2.compare(grey,
    cv2.subtract(local, 40), cv2.CMP_LT) and cv2.morphologyEx(MORPH_OPEN, np.ones((2, 2)))
    give, bit for bit (the kernel's anchor (1, 1): each of the erosion and the dilation takes
    a pixel, its left, upper and upper-left neighbours; outside the image counts for neither),
    in one call instead of four."""
    h, w = grey.shape
    dark = np.empty((h, w), np.uint8)
    for y in range(h):
        for x in range(w):
            dark[y, x] = 255 if np.int32(grey[y, x]) < np.int32(local[y, x]) - 40 else 0
    eroded = np.empty((h, w), np.uint8)
    for y in range(h):
        for x in range(w):
            m = dark[y, x]
            if x > 0:
                m = min(m, dark[y, x - 1])
            if y > 0:
                m = min(m, dark[y - 1, x])
                if x > 0:
                    m = min(m, dark[y - 1, x - 1])
            eroded[y, x] = m
    out = np.empty((h, w), np.uint8)
    for y in range(h):
        for x in range(w):
            m = eroded[y, x]
            if x > 0:
                m = max(m, eroded[y, x - 1])
            if y > 0:
                m = max(m, eroded[y - 1, x])
                if x > 0:
                    m = max(m, eroded[y - 1, x - 1])
            out[y, x] = m
    return out


RECENTRE = 4  # the centroid taken again round itself at most this often (find_discs)
RECENTRE_PX = 0.005  # until it moves less than this
RECENTRE_REACH = 0.15  # radii: a centre re-centred farther than this from the first is not taken


def _centroid(grey: np.ndarray, cx: float, cy: float, r: float, recentre: int = 0
              ) -> tuple[float, float]:
    """Darkness-weighted centroid within 1.3 r (the disc plus a band of ring), sub-pixel;
    then, recentre times at most, the same round the centroid found. The first circle is
    round the mask's bounding box, whose centre is off the disc's by up to a pixel (the dark
    threshold is against the neighbourhood's mean, which the background behind the card
    moves), so the circle cuts the disc's anti-aliased edge on one side and takes more of the
    ring's shading on the other: the centroid is pulled toward the box's centre, differently
    in each view (at 3 m, r ~4 px: up to 0.3 px of disparity, ~10 cm of depth; issue 23).
    Round the centroid itself the circle holds the whole disc symmetrically."""
    u, v = _centroid_of(grey, cx, cy, r, (1.3 * r) ** 2)
    for _ in range(recentre):
        u2, v2 = _centroid_of(grey, u, v, r, (1.3 * r) ** 2)
        moved = max(abs(u2 - u), abs(v2 - v))
        u, v = u2, v2
        if moved < RECENTRE_PX:
            break
    return float(u), float(v)


@njit(cache=True)
def _centroid_of(grey: np.ndarray, cx: float, cy: float, r: float,
                 reach2: float) -> tuple[float, float]:
    """_centroid (reach2: (1.3 r) ** 2 as Python computes it) in one pass, with numpy's
    arithmetic: the weights (the patch's 90th percentile less each level, at least 0, 0
    outside the reach) in the patch's row order, summed as numpy sums them (_numpy_sum)."""
    h, w = grey.shape
    x0, x1 = max(0, int(cx - 1.3 * r) - 1), min(w, int(cx + 1.3 * r) + 2)
    y0, y1 = max(0, int(cy - 1.3 * r) - 1), min(h, int(cy + 1.3 * r) + 2)
    raw = grey[y0:y1, x0:x1]
    top = _p90_of(raw)
    n = raw.size
    weight = np.empty(n)
    wx = np.empty(n)
    wy = np.empty(n)
    i = 0
    for y in range(y0, y1):
        dy = y - cy
        for x in range(x0, x1):
            dx = x - cx
            wt = max(top - np.float64(grey[y, x]), 0.0)
            if not dx * dx + dy * dy <= reach2:
                wt = wt * 0.0
            weight[i], wx[i], wy[i] = wt, wt * np.float64(x), wt * np.float64(y)
            i += 1
    total = _numpy_sum(weight)
    if total <= 0:
        return cx, cy
    return _numpy_sum(wx) / total, _numpy_sum(wy) / total


@njit(cache=True)
def _p90_of(patch: np.ndarray) -> float:
    """np.percentile(patch, 90) of a uint8 array, exactly (its linear interpolation between
    the order statistics on each side), from the histogram instead of a partition."""
    n = patch.size
    q = (n - 1) * 0.9
    lo = int(math.floor(q))
    hi = min(lo + 1, n - 1)
    counts = np.zeros(256, np.int64)
    for y in range(patch.shape[0]):
        for x in range(patch.shape[1]):
            counts[patch[y, x]] += 1
    a = b = -1
    seen = 0
    for level in range(256):  # the first level whose cumulative count passes lo (hi)
        seen += counts[level]
        if a < 0 and seen > lo:
            a = level
        if seen > hi:
            b = level
            break
    gamma = q - lo
    diff = float(b) - float(a)
    return b - diff * (1 - gamma) if gamma >= 0.5 else a + diff * gamma


@njit(cache=True)
def _block_sum(a: np.ndarray, lo: int, n: int) -> float:
    # numpy's pairwise sum of a[lo:lo + n], n <= 128 (numpy/_core/src/umath/loops_utils.h)
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    while i < n - n % 8:
        r0 += a[lo + i]
        r1 += a[lo + i + 1]
        r2 += a[lo + i + 2]
        r3 += a[lo + i + 3]
        r4 += a[lo + i + 4]
        r5 += a[lo + i + 5]
        r6 += a[lo + i + 6]
        r7 += a[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return float(res)  # a float64 already: float() only tells mypy


@njit(cache=True)
def _numpy_sum(a: np.ndarray) -> float:
    """a.sum() of a contiguous float64 array as numpy computes it (its identity 0.0 plus the
    pairwise sum: runs over 128 split in two at a multiple of 8, each half summed so, the
    two added): the same float to the last bit. The halving walked with a stack of frames
    (numba's cache does not reload a recursive function)."""
    start = np.empty(64, np.int64)
    size = np.empty(64, np.int64)
    stage = np.empty(64, np.int64)  # 0: left half next, 1: right half next, 2: both done
    first = np.empty(64)  # the left half's sum
    d, start[0], size[0], stage[0] = 0, 0, a.size, 0
    got = 0.0  # the sum of the frame last finished
    while d >= 0:
        lo, n = start[d], size[d]
        if n <= 128:
            got = _block_sum(a, lo, n)
            d -= 1
            continue
        half = n // 2 - (n // 2) % 8
        if stage[d] == 2:
            got = first[d] + got
            d -= 1
            continue
        if stage[d] == 1:
            first[d] = got
        stage[d] += 1
        lo2, n2 = (lo, half) if stage[d] == 1 else (lo + half, n - half)
        d += 1
        start[d], size[d], stage[d] = lo2, n2, 0
    return 0.0 + got


def find_discs(image: np.ndarray, min_radius: float = 2.5, max_radius: float = 80.0,
               window: int = 31, recentre: int = RECENTRE) -> list[Blob]:
    """Dark, round blobs inside a lighter ring; window (px, odd) is the neighbourhood the disc
    is darker than, and must be wider than the disc (find_marker sizes it); recentre: how
    often at most the centroid is taken again round itself (_centroid; 0: once, round the
    mask's box, as before issue 23's mend)."""
    grey = to_grey(image)
    # dark relative to the neighbourhood: the ring makes the disc stand out locally (grey <
    # local - 40; where local < 40 the saturated difference is 0 and nothing is below it)
    mask = _dark_opened(grey, cv2.blur(grey, (window, window)))  # 255: dark
    blobs: list[Blob] = []
    min_area = math.pi * min_radius ** 2
    outlines = _outlines(mask, min_area)
    if not outlines:
        return blobs
    # the cheapest tests first, every outline in one pass (_screen): its bounding box's
    # aspect, its box's room for the area ((w - 1)(h - 1)), its area and its roundness
    sizes = np.fromiter(map(len, outlines), np.intp, len(outlines))
    points = np.concatenate(outlines).reshape(-1, 2)
    for i, x, y, w, h in _screen(points, sizes, min_area, math.pi * max_radius ** 2):
        c = outlines[i]
        r = (w + h) / 4
        u, v = _centroid(grey, x + (w - 1) / 2, y + (h - 1) / 2, r)
        # printed: a uniform light ring round a uniform dark disc (texture is neither)
        ring, disc, ring_sd, disc_sd = _ring_and_disc(grey, u, v, r)
        if ring - disc < 80 or max(ring_sd, disc_sd) > 0.2 * (ring - disc):
            continue
        if recentre:  # the blobs kept as before; a kept disc's centre re-centred (issue 23):
            # re-centred before the ring's test, a blob of texture took a place that passed it
            # (dev 105 #6: a false marker 100 px above the true one). A whole disc's centre
            # moves a few tenths of a pixel; more is no clean disc, whose first one stands
            u2, v2 = _centroid(grey, u, v, r, recentre - 1)
            if math.hypot(u2 - u, v2 - v) <= RECENTRE_REACH * r:
                u, v = u2, v2
        m = cv2.moments(c)
        aspect = math.sqrt(m["mu20"] / m["mu02"]) if m["mu02"] > 0 else 1.0
        blobs.append(Blob(u, v, r, aspect))
    return blobs


def _outlines(mask: np.ndarray, min_area: float) -> list[np.ndarray]:
    """The outer contours of the mask's blobs that find_discs' box tests may keep, and of the
    blobs with such a one in their hole: a textured scene leaves thousands of specks and many
    lines. Those whose box find_discs would drop and whose box holds no other such blob are
    cleared before the contours are traced (_without_dropped), which leaves the others'
    contours as they were. (A closed contour of n points, steps of at most sqrt 2 px, encloses
    at most (n sqrt 2)^2 / (4 pi) px: those shorter than sqrt(2 pi min_area) fail _screen's
    area test, and need no test of their own.)"""
    contours, _ = cv2.findContours(_without_dropped(mask, min_area), cv2.RETR_EXTERNAL,
                                   cv2.CHAIN_APPROX_NONE)
    return list(contours)


@njit(cache=True)
def _screen(points: np.ndarray, sizes: np.ndarray, min_area: float, max_area: float
            ) -> list[tuple[int, int, int, int, int]]:
    """The outlines (their points one after another, sizes points each) that pass find_discs'
    shape tests, as (index, x, y, w, h: the bounding box, cv2.boundingRect's): the box's
    width-to-height ratio within 0.75-1.33, (w - 1)(h - 1) at least min_area, the area
    (cv2.contourArea) within min_area-max_area, and 4 pi area / perimeter^2 (cv2.arcLength,
    closed) at least 0.7. One pass instead of ~10 numpy calls and two OpenCV calls an outline."""
    out = []
    start = 0
    for i in range(sizes.size):
        n = sizes[i]
        x0, y0, bw, bh = _box(points, start, n)
        ratio = bw / bh
        if ratio > 0.75 and ratio < 1.33 and (bw - 1) * (bh - 1) >= min_area:
            area, perimeter = _area_and_perimeter(points, start, n)
            if not (area < min_area or area > max_area or perimeter <= 0
                    or 4 * math.pi * area / perimeter ** 2 < 0.7):
                out.append((i, x0, y0, bw, bh))
        start += n
    return out


@njit(cache=True)
def _box(points: np.ndarray, start: int, n: int) -> tuple[int, int, int, int]:
    """cv2.boundingRect (x, y, w, h) of the outline points[start:start + n] (n >= 1)."""
    x0 = x1 = points[start, 0]
    y0 = y1 = points[start, 1]
    for k in range(start + 1, start + n):
        x0, x1 = min(x0, points[k, 0]), max(x1, points[k, 0])
        y0, y1 = min(y0, points[k, 1]), max(y1, points[k, 1])
    return int(x0), int(y0), int(x1 - x0 + 1), int(y1 - y0 + 1)


@njit(cache=True)
def _area_and_perimeter(points: np.ndarray, start: int, n: int) -> tuple[float, float]:
    """cv2.contourArea and cv2.arcLength (closed) of the integer outline points[start:start +
    n] to the last bit, as OpenCV computes them: the shoelace sum (of integers: exact in
    float64, in any order) halved, its magnitude; each step's length in float32 (from the last
    point round to the first) added in float64 in the outline's order."""
    twice = 0
    perimeter = 0.0
    px, py = points[start + n - 1, 0], points[start + n - 1, 1]
    for k in range(start, start + n):
        qx, qy = points[k, 0], points[k, 1]
        twice += np.int64(px) * qy - np.int64(py) * qx
        dx, dy = np.float32(qx - px), np.float32(qy - py)
        perimeter += np.float64(np.float32(math.sqrt(dx * dx + dy * dy)))
        px, py = qx, qy
    return abs(np.float64(twice)) * 0.5, perimeter


@njit(cache=True, inline="always")
def _root(parent: np.ndarray, i: int) -> int:
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@njit(cache=True)
def _without_dropped(mask: np.ndarray, min_area: float) -> np.ndarray:
    """A copy of the mask (uint8, 0 or not) without the 8-connected blobs whose contours
    find_discs drops by their bounding box (w, h px) alone: the specks, (w - 1)(h - 1) <
    min_area, and those whose aspect w / h is not within 0.75-1.33 (lines, the edges of
    boxes) unless another blob left lies within that box. Clearing them changes no other
    contour: a contour is traced round its own blob, and a blob in one's hole lies strictly
    inside its box, so none is newly outermost; the contours left are those of the whole mask.
    Labelled by runs of a row joined to the runs they touch in the row above (a union-find):
    the contours of thousands of specks cost cv2.findContours more than this."""
    h, w = mask.shape
    cap = h * ((w + 1) // 2) + 1
    run_y = np.empty(cap, np.int32)
    run_x0 = np.empty(cap, np.int32)
    run_x1 = np.empty(cap, np.int32)  # exclusive
    parent = np.empty(cap, np.int32)
    n = 0
    above0 = above1 = 0  # the runs of the row above: [above0, above1)
    for y in range(h):
        row = mask[y]
        first = n
        x = 0
        while x < w:
            if row[x] == 0:
                x += 1
                continue
            x0 = x
            while x < w and row[x] != 0:
                x += 1
            run_y[n], run_x0[n], run_x1[n], parent[n] = y, x0, x, n
            for j in range(above0, above1):  # touching, diagonals included
                if run_x1[j] >= x0 and run_x0[j] <= x:
                    a, b = _root(parent, j), _root(parent, n)
                    parent[max(a, b)] = min(a, b)
            n += 1
        above0, above1 = first, n
    lo_x = np.full(n, w, np.int32)
    hi_x = np.full(n, -1, np.int32)
    lo_y = np.full(n, h, np.int32)
    hi_y = np.full(n, -1, np.int32)
    for i in range(n):
        r = _root(parent, i)
        parent[i] = r
        lo_x[r] = min(lo_x[r], run_x0[i])
        hi_x[r] = max(hi_x[r], run_x1[i] - 1)
        lo_y[r] = min(lo_y[r], run_y[i])
        hi_y[r] = max(hi_y[r], run_y[i])
    drop = np.zeros(n, np.bool_)  # by root
    kept = np.empty(n, np.int32)  # the roots of the blobs not specks
    nk = 0
    for r in range(n):
        if parent[r] == r:
            if (hi_x[r] - lo_x[r]) * (hi_y[r] - lo_y[r]) < min_area:
                drop[r] = True
            else:
                kept[nk] = r
                nk += 1
    for k in range(nk):
        r = kept[k]
        ratio = (hi_x[r] - lo_x[r] + 1) / (hi_y[r] - lo_y[r] + 1)  # as _screen's
        if ratio > 0.75 and ratio < 1.33:
            continue
        holds = False
        for m in range(nk):
            q = kept[m]
            if q != r and lo_x[q] >= lo_x[r] and hi_x[q] <= hi_x[r] \
                    and lo_y[q] >= lo_y[r] and hi_y[q] <= hi_y[r]:
                holds = True
                break
        drop[r] = not holds
    out = mask.copy()
    for i in range(n):
        if drop[parent[i]]:
            out[run_y[i], run_x0[i]:run_x1[i]] = 0
    return out


def _ring_and_disc(grey: np.ndarray, cx: float, cy: float, r: float
                   ) -> tuple[float, float, float, float]:
    """The mean grey level of the ring (1.2 r to 1.45 r from the centre) and of the disc
    (within 0.7 r), and their standard deviations: 0 and 255 for one without pixels."""
    r0, r1, rd = 1.2 * r, 1.45 * r, 0.7 * r
    ring, disc, ring_sd, disc_sd = _ring_and_disc_of(grey, cx, cy, r1, r0 * r0, r1 * r1,
                                                     rd * rd)
    return float(ring), float(disc), float(ring_sd), float(disc_sd)


@njit(cache=True)
def _ring_and_disc_of(grey: np.ndarray, cx: float, cy: float, r1: float, ring_lo2: float,
                      ring_hi2: float, disc2: float) -> tuple[float, float, float, float]:
    """_ring_and_disc with numpy's arithmetic: the pixels by squared distance from one window
    in row order; a mean from the exact integer sum, a deviation as numpy's std computes it
    (the squared differences from that mean summed as numpy sums them)."""
    h, w = grey.shape
    x0, x1 = max(0, int(cx - r1) - 1), min(w, int(cx + r1) + 2)
    y0, y1 = max(0, int(cy - r1) - 1), min(h, int(cy + r1) + 2)
    n = max(0, (y1 - y0) * (x1 - x0))
    ring_px = np.empty(n, np.int64)
    disc_px = np.empty(n, np.int64)
    nr = nd = 0
    for y in range(y0, y1):
        dy = y - cy
        for x in range(x0, x1):
            dx = x - cx
            d2 = dx * dx + dy * dy
            if d2 >= ring_lo2 and d2 <= ring_hi2:
                ring_px[nr] = grey[y, x]
                nr += 1
            if d2 <= disc2:
                disc_px[nd] = grey[y, x]
                nd += 1
    ring, ring_sd = _mean_and_sd(ring_px[:nr])
    disc, disc_sd = _mean_and_sd(disc_px[:nd])
    return ring, disc, ring_sd, disc_sd


@njit(cache=True)
def _mean_and_sd(values: np.ndarray) -> tuple[float, float]:
    # (values' mean, its standard deviation) as numpy's mean and std of them in float64
    n = values.size
    if n == 0:
        return 0.0, 255.0
    mean = values.sum() / n  # an exact integer sum, then one rounding, as numpy's
    sq = np.empty(n)
    for i in range(n):
        e = np.float64(values[i]) - mean
        sq[i] = e * e
    return mean, math.sqrt(_numpy_sum(sq) / n)


def find_aruco(image: np.ndarray) -> list[Blob]:
    detector = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50))
    corners, ids, _ = detector.detectMarkers(to_grey(image))
    out = []
    for c in corners:
        pts = np.asarray(c).reshape(-1, 2)
        out.append(Blob(float(pts[:, 0].mean()), float(pts[:, 1].mean()),
                        float(np.linalg.norm(pts[0] - pts[2]) / 2.8)))
    return out


def find_markers(left: np.ndarray, right: np.ndarray, kind: str = "disc",
                 max_row_error: float = 2.0, windows: tuple[Window, Window] | None = None,
                 window: int = 31, recentre: int = RECENTRE) -> list[MarkerPair]:
    """Candidate marker pairs in a rectified pair: a left blob and a right blob on the same row
    to its left (positive disparity) with a similar size. windows: ((x0, y0, x1, y1) left,
    (x0, y0, x1, y1) right) to search in, else the whole images. recentre: find_discs'."""
    def find(img: np.ndarray) -> list[Blob]:
        return find_aruco(img) if kind == "aruco" else find_discs(img, window=window,
                                                                  recentre=recentre)

    found: list[list[Blob]] = []
    for img, win in zip((left, right), windows or (None, None)):
        if found and not found[0]:
            return []  # nothing on the left: no pair, whatever the right view holds
        if win is None:
            found.append(find(img))
            continue
        x0, y0, x1, y1 = win
        found.append([Blob(b.u + x0, b.v + y0, b.radius, b.aspect)
                      for b in find(img[y0:y1, x0:x1])])
    pairs = []
    for a in found[0]:
        for b in found[1]:
            if (abs(a.v - b.v) <= max_row_error and a.u - b.u > 0
                    and abs(a.radius - b.radius) <= 0.3 * a.radius + 1):
                pairs.append(MarkerPair(a, b))
    return pairs


def _window(blob: Blob, shape: tuple[int, ...]) -> Window:
    reach = int(4 * blob.radius) + 24  # room for the frame-to-frame motion
    h, w = shape[:2]
    return (max(0, int(blob.u) - reach), max(0, int(blob.v) - reach),
            min(w, int(blob.u) + reach + 1), min(h, int(blob.v) + reach + 1))


def marker_candidates(left: np.ndarray, right: np.ndarray, kind: str = "disc",
                      radius_m: float | None = None, baseline_m: float | None = None,
                      near: MarkerPair | None = None, whole: bool = False,
                      recentre: int = RECENTRE) -> list[MarkerPair]:
    """Marker pairs whose size fits their distance (a disc of radius_m at disparity d spans
    radius_m * d / baseline_m px; within 35%), best first: nearest to the last sighting `near`
    (searched for around it first, unless whole), else the largest. The neighbourhood the
    disc must be darker than grows with the disc: from the last sighting, or at 31 px and then,
    if nothing is found, 121 px (a marker near the camera). recentre: find_discs'."""
    def fits(p: MarkerPair) -> bool:
        if radius_m is None or baseline_m is None:
            return True
        expected = radius_m * p.disparity / baseline_m
        return abs(p.left.radius - expected) <= 0.35 * expected

    pairs = []
    if near is not None and not whole:
        windows = (_window(near.left, left.shape), _window(near.right, right.shape))
        size = max(31, 2 * int(3 * near.left.radius) + 1)
        pairs = [p for p in find_markers(left, right, kind, windows=windows, window=size,
                                         recentre=recentre) if fits(p)]
    if not pairs:  # the whole views, in grey once for both sizes (pixel by pixel: the same)
        left, right = to_grey(left), to_grey(right)
    for size in (31, 121):
        if pairs:
            break
        pairs = [p for p in find_markers(left, right, kind, window=size, recentre=recentre)
                 if fits(p)]
    if near is not None:
        return sorted(pairs, key=lambda p: abs(p.left.u - near.left.u)
                      + abs(p.left.v - near.left.v) + 10 * abs(p.disparity - near.disparity))
    return sorted(pairs, key=lambda p: -p.left.radius)


def find_marker(left: np.ndarray, right: np.ndarray, kind: str = "disc",
                radius_m: float | None = None, baseline_m: float | None = None,
                near: MarkerPair | None = None) -> MarkerPair | None:
    """The best of marker_candidates, None if there is none."""
    pairs = marker_candidates(left, right, kind, radius_m, baseline_m, near)
    return pairs[0] if pairs else None


def block_disparity(disp: np.ndarray, blob: Blob) -> float:
    """Median block-matching disparity over the marker's ring (its textured part), NaN if none."""
    h, w = disp.shape
    r = blob.radius
    x0, x1 = max(0, int(blob.u - 1.6 * r)), min(w, int(blob.u + 1.6 * r) + 1)
    y0, y1 = max(0, int(blob.v - 1.6 * r)), min(h, int(blob.v + 1.6 * r) + 1)
    ys, xs = np.mgrid[y0:y1, x0:x1]
    d2 = (xs - blob.u) ** 2 + (ys - blob.v) ** 2
    sel = (d2 >= (0.7 * r) ** 2) & (d2 <= (1.6 * r) ** 2)
    values = disp[y0:y1, x0:x1][sel]
    values = values[np.isfinite(values)]
    return float(np.median(values)) if values.size else float("nan")


def cut_views(pair: MarkerPair, aspect_tol: float = 0.12, radius_tol: float = 0.15) -> str:
    """Why the pair's two discs are not one whole disc seen twice, "" if they may be. Something
    nearer than the card across it (a box's edge, a post) is shifted against the card between
    the views by the difference of their disparities, so it cuts the disc differently in each:
    the cut view's disc is narrower (its width-to-height ratio, its radius) and its centroid
    moves away from the edge, by a pixel of disparity at 2.7 m (seed 9's trial 419). A cut
    along a row is the same in both views and moves no disparity."""
    a, b = pair.left, pair.right
    if abs(a.aspect - b.aspect) > aspect_tol:
        return f"its two views' discs differ in shape ({a.aspect:.2f} and {b.aspect:.2f} wide)"
    if abs(a.radius - b.radius) > radius_tol * max(a.radius, b.radius) + 0.25:
        return f"its two views' discs differ in size ({a.radius:.2f} and {b.radius:.2f} px)"
    return ""
