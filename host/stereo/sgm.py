"""Own semi-global matcher: census Hamming cost, 8-path aggregation in two streaming passes, WTA.

Cost: a 9x7 census of the grey images (62 bits, replicated border) compared by Hamming
distance, summed over a block_size x block_size box when block_size > 1. Aggregation
(Hirschmueller's recurrence) along 8 directions: a forward pass (rows top to bottom, x left to
right) carries the paths from the left, top-left, top and top-right; the backward pass the four
opposite ones. The passes are independent, so with two threads they run at once, each into its
own sum volume; each keeps only two rows of path costs. Path costs, sums and penalties are
uint16 with the disparity axis innermost, so every per-disparity loop runs in 16-bit lanes.

Candidate j is disparity dmin + j; the left pixel x matches right pixel x - d. A candidate
whose right pixel falls outside the image costs the most a census can differ (CENSUS_BITS).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange, types
from numba.extending import intrinsic

from host.stereo.subpixel import FIT_NONE, fit_offset

CENSUS_H = 3  # half height of the census window (7 rows)
CENSUS_W = 4  # half width (9 columns)
CENSUS_BITS = (2 * CENSUS_H + 1) * (2 * CENSUS_W + 1) - 1

@intrinsic
def _popcount(typingctx, v):
    """Set bits of a uint64 (LLVM's ctpop: one vector instruction where the CPU has it)."""
    def codegen(context, builder, signature, args):
        return builder.ctpop(args[0])
    return types.uint64(types.uint64), codegen


@njit(cache=True, parallel=True)
def census(img):
    """9x7 census of a uint8 image: bit set where a neighbour is darker than the centre.

    img is padded by the caller (CENSUS_H rows, CENSUS_W columns, replicated border), so the
    loop over x has no clamping and runs in vector lanes.
    """
    hp, wp = img.shape
    h, w = hp - 2 * CENSUS_H, wp - 2 * CENSUS_W
    out = np.zeros((h, w), dtype=np.uint64)
    for y in prange(h):
        row = out[y]
        centre = img[y + CENSUS_H, CENSUS_W:CENSUS_W + w]
        for dy in range(2 * CENSUS_H + 1):
            nb_row = img[y + dy]
            for dx in range(2 * CENSUS_W + 1):
                if dy == CENSUS_H and dx == CENSUS_W:
                    continue
                nb = nb_row[dx:dx + w]
                for x in range(w):
                    row[x] = (row[x] << np.uint64(1)) | np.uint64(nb[x] < centre[x])
    return out


@njit(cache=True, parallel=True)
def hamming_volume(cl, cr, dmin, out):
    """Fill out (rows, cols, nd) uint16 with the census Hamming distance of x and x - dmin - j.
    """
    h, w = cl.shape
    nd = out.shape[2]
    far = np.uint16(CENSUS_BITS)
    for y in prange(h):
        lrow = cl[y]
        # right census reversed: candidates j = 0.. read it forwards from w - 1 - x + dmin
        rrev = cr[y, ::-1].copy()
        for x in range(w):
            a = lrow[x]
            n = min(nd, max(0, x - dmin + 1))
            base = w - 1 - x + dmin
            for j in range(n):
                out[y, x, j] = np.uint16(_popcount(a ^ rrev[base + j]))
            for j in range(n, nd):
                out[y, x, j] = far
    return out


@njit(cache=True, parallel=True)
def box_sum(raw, box):
    """Sum of a (rows, cols, nd) uint16 volume over box x box pixels (cropped at the edges)."""
    h, w, nd = raw.shape
    r = box // 2
    out = np.empty_like(raw)
    for y in prange(h):
        acc = np.zeros((w + 2 * r + 1, nd), dtype=np.uint16)
        for yy in range(max(0, y - r), min(h, y + r + 1)):
            for x in range(w):
                for j in range(nd):
                    acc[x + r + 1, j] += raw[yy, x, j]
        # prefix sums along x, then each window is a difference of two
        for x in range(1, w + 2 * r + 1):
            for j in range(nd):
                acc[x, j] += acc[x - 1, j]
        for x in range(w):
            hi = min(x + r + 1, w) + r
            lo = max(x - r, 0) + r
            for j in range(nd):
                out[y, x, j] = acc[hi, j] - acc[lo, j]
    return out


@njit(cache=True, fastmath=True, inline="always")
def _path_step(buf, mins, src, dst, cost, y, x, p1, p2, nd):
    """One step of a path into slot dst from slot src of buf (a slot holds one path's costs,
    padded by a large value at each end; mins[slot] is its minimum):
    L[j] = C[j] + min(L'[j], L'[j-1] + P1, L'[j+1] + P1, min L' + P2) - min L'.

    Indices, not views (a view costs two atomic reference counts); every intermediate is cast
    back to uint16 so the loop runs in 16-bit lanes. One output per loop: more would alias.
    """
    m = mins[src]
    jump = np.uint16(m + p2)
    lo = np.uint16(0xFFFF)
    for j in range(nd):
        near = np.uint16(min(buf[src, j], buf[src, j + 2]) + p1)
        v = np.uint16(cost[y, x, j] + min(buf[src, j + 1], near, jump) - m)
        buf[dst, j + 1] = v
        lo = min(lo, v)
    mins[dst] = lo


@njit(cache=True, fastmath=True)
def _pass(cost, total, forward, p1, p2):
    """Aggregate the 4 paths entering from one side into total (rows, cols, nd).

    buf slots: 0 all zero (a path starting there: its step gives L = C), 1-2 the horizontal
    path (previous and current pixel), then for each of the two row parities and each of the
    3 paths from the row above (from x + step, x, x - step), one slot per column.
    """
    h, w, nd = cost.shape
    buf = np.full((3 + 6 * w, nd + 2), np.uint16(0x3FFF), dtype=np.uint16)
    buf[0, 1:nd + 1] = 0
    mins = np.zeros(3 + 6 * w, dtype=np.uint16)
    step = 1 if forward else -1
    for i in range(h):
        y = i if forward else h - 1 - i
        cur0 = 3 + (i % 2) * 3 * w
        prev0 = 3 + ((i + 1) % 2) * 3 * w
        for t in range(w):
            x = t if forward else w - 1 - t
            hd = 1 + (t + 1) % 2
            _path_step(buf, mins, 0 if t == 0 else 1 + t % 2, hd, cost, y, x, p1, p2, nd)
            for j in range(nd):
                total[y, x, j] = buf[hd, j + 1]
            for r in range(3):
                xs = x + step * (1 - r)  # r = 0, 1, 2: from x + step, x, x - step above
                dst = cur0 + r * w + x
                src = prev0 + r * w + xs if i > 0 and 0 <= xs < w else 0
                _path_step(buf, mins, src, dst, cost, y, x, p1, p2, nd)
                for j in range(nd):
                    total[y, x, j] += buf[dst, j + 1]
    return total


@njit(cache=True, parallel=True)
def aggregate(cost, sums, p1, p2):
    """Fill sums (2, rows, cols, nd) with the forward and backward 4-path sums, in parallel."""
    for k in prange(2):
        _pass(cost, sums[k], k == 0, p1, p2)
    return sums


@njit(cache=True, fastmath=True, inline="always")
def _wta(s, idx, n, uniqueness, fit):
    """Best candidate of s[:n] (the smallest j among equal sums) and its sub-pixel offset in
    px; -1 when the uniqueness test rejects it. idx = 0 .. nd in s's dtype."""
    m = s[0]
    for j in range(n):
        m = min(m, s[j])
    best = idx[idx.size - 1]
    for j in range(n):
        best = min(best, idx[j] if s[j] == m else idx[idx.size - 1])
    best = np.int64(best)
    c0 = np.float32(m)
    if uniqueness > 0.0:
        bound = c0 * (1.0 + uniqueness / 100.0)
        for j in range(n):
            if (j < best - 1 or j > best + 1) and s[j] <= bound:
                return -1, 0.0
    off = 0.0
    if fit != FIT_NONE and 0 < best < n - 1:
        # candidates ascend in d here: the minimum lies at best + offset
        off = fit_offset(np.float32(s[best - 1]), c0, np.float32(s[best + 1]), fit)
    return best, off


@njit(cache=True, parallel=True, fastmath=True)
def decide(sums, dmin, uniqueness, fit, want_right):
    """Left (and right) disparity maps in px, NaN where the uniqueness test rejects.

    Each row's total (forward + backward) is formed once in a row buffer; the right view's
    candidates are that buffer's diagonals (right pixel xr at disparity d is left x = xr + d).
    """
    _, h, w, nd = sums.shape
    disp_l = np.full((h, w), np.nan, dtype=np.float32)
    disp_r = np.full((h, w), np.nan, dtype=np.float32)
    for y in prange(h):
        row = np.empty((w, nd), dtype=np.uint16)
        s = np.empty(nd, dtype=np.uint16)
        idx = np.arange(nd + 1).astype(np.uint16)
        for x in range(w):
            for j in range(nd):
                row[x, j] = sums[0, y, x, j] + sums[1, y, x, j]
            for j in range(nd):
                s[j] = row[x, j]
            best, off = _wta(s, idx, nd, uniqueness, fit)
            if best >= 0:
                disp_l[y, x] = dmin + best + off
        if want_right:
            for xr in range(w):
                n = min(nd, w - xr - dmin)
                if n <= 0:
                    continue
                for j in range(n):
                    s[j] = row[xr + dmin + j, j]
                best, off = _wta(s, idx, n, 0.0, fit)
                disp_r[y, xr] = dmin + best + off
    return disp_l, disp_r
