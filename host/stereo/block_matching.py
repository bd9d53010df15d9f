"""Own block matcher: SSD / zero-mean NCC with running sums, WTA and sub-pixel fit (SAD is
sad.py's kernel, which shares this module's padding and decision helpers).

Conventions: the left image is the reference; a left pixel x matches right pixel x - d; the output
is float32 disparity in pixels with NaN where the matcher gives no disparity. Window sums are kept
as exact integer running sums (over rows, then along the row), so the cost per pixel and per
disparity does not depend on the window size. Candidates whose right window would leave the
image are never considered, and a pixel whose own window leaves the image is invalid.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from host.stereo.subpixel import FIT_NONE, fit_offset

COST_SSD = 1
COST_NCC = 2
COSTS = {"ssd": COST_SSD, "ncc": COST_NCC}


@njit(cache=True, fastmath=True, inline="always")
def _slide(c, a, rn, o, ro, kind, first):
    # One column's sums move a row down: add the entering pixel's costs, drop the leaving one's.
    # c, rn and ro are 1-D views so the loop over k is contiguous and vectorises.
    if kind == COST_SSD:
        if first:
            for k in range(c.size):
                e = a - np.int32(rn[k])
                c[k] += e * e
        else:
            for k in range(c.size):
                e = a - np.int32(rn[k])
                f = o - np.int32(ro[k])
                c[k] += e * e - f * f
    else:  # NCC cross term; means and variances come from box sums
        if first:
            for k in range(c.size):
                c[k] += a * np.int32(rn[k])
        else:
            for k in range(c.size):
                c[k] += a * np.int32(rn[k]) - o * np.int32(ro[k])


@njit(cache=True, fastmath=True)
def _slide_cols(col, left, right_pad, y_new, y_old, base0, nd, kind, first):
    """Column sums of every x from window rows ..y_old] to ..y_new], summed over channels.

    Candidate k of x reads padded right pixel base0 + x + k (disparity dmin + nd-1-k), so the
    right pixels of one x are a contiguous run.
    """
    for ch in range(left.shape[0]):
        l_new = left[ch, y_new]
        l_old = left[ch, y_old]
        r_new = right_pad[ch, y_new]
        r_old = right_pad[ch, y_old]
        for x in range(left.shape[2]):
            b = base0 + x
            _slide(col[x], np.int32(l_new[x]), r_new[b:b + nd], np.int32(l_old[x]),
                   r_old[b:b + nd], kind, first)


@njit(cache=True, fastmath=True, inline="always")
def _slide_window(win, enter, leave):
    for k in range(win.size):
        win[k] = np.int32(win[k] + enter[k] - leave[k])


@njit(cache=True, fastmath=True, inline="always")
def _slide_window_argmin(win, enter, leave, shift):
    """Slide the window sums one column and return the best k in the same pass.

    Costs are packed (cost << shift | k) into int32 so one vectorised min finds value and
    index together; every operation is cast back to int32 to keep 32-bit vector lanes.
    """
    s = np.int32(shift)
    packed = np.int32(0x7FFFFFFF)
    for k in range(win.size):
        v = np.int32(win[k] + enter[k] - leave[k])
        win[k] = v
        packed = np.int32(min(packed, np.int32(np.int32(v << s) | np.int32(k))))
    return packed & ((np.int32(1) << s) - np.int32(1))


@njit(cache=True, fastmath=True)
def _ncc_row(win, y, x, half, h, w, dmin, nd, sum_l, sq_l, sum_r, sq_r, out):
    # ZNCC cost (1 - ncc) from the window cross sum and the (zero-bordered) box sums of each
    # image; n is the window's pixel count inside the image.
    n = ((min(y + half, h - 1) - max(y - half, 0) + 1)
         * (min(x + half, w - 1) - max(x - half, 0) + 1))
    sl = sum_l[y, x]
    var_l = sq_l[y, x] - sl * sl / n
    for k in range(nd):
        xr = x - (dmin + nd - 1 - k)
        if xr < 0:
            out[k] = np.inf
            continue
        sr = sum_r[y, xr]
        var_r = sq_r[y, xr] - sr * sr / n
        den = np.sqrt(max(var_l * var_r, 1e-9))
        out[k] = 1.0 - (win[k] - sl * sr / n) / den


@njit(cache=True, fastmath=True, inline="always")
def _argmin(cost, kmin, nd):
    c0 = cost[kmin]
    for k in range(kmin + 1, nd):
        c0 = min(c0, cost[k])
    best = kmin
    while cost[best] != c0:
        best += 1
    return best


@njit(cache=True, fastmath=True, inline="always")
def _decide(cost, best, kmin, nd, uniqueness, fit):
    """Uniqueness test and sub-pixel offset (k units) of the winner; ok False = rejected."""
    c0 = np.float32(cost[best])
    if uniqueness > 0.0:
        bound = c0 * (1.0 + uniqueness / 100.0)
        for k in range(kmin, nd):
            if (k < best - 1 or k > best + 1) and cost[k] <= bound:
                return 0.0, False
    if fit == FIT_NONE or best <= kmin or best >= nd - 1:
        return 0.0, True
    return fit_offset(np.float32(cost[best - 1]), c0, np.float32(cost[best + 1]), fit), True


@njit(cache=True)
def _pack_shift(kind, nd, size, channels):
    # bits for the candidate index, if the largest window cost leaves room for them in int32
    if kind == COST_NCC:
        return -1
    bits = 0
    while (1 << bits) < nd:
        bits += 1
    top = channels * size * size * 255 * 255  # SSD
    return bits if top < (1 << (31 - bits)) else -1


@njit(cache=True)
def padded_pair(left, right, dmin, nd, half, clip):
    """What both block-matching kernels start from: NaN maps (left, right), the images padded
    (rows of zeros above and below when clip, so clipped window sums are exact: 0 against 0
    costs nothing; room for every candidate left and right of the right view), the right
    view's column offset, the rows of window centres and the columns [x_start, x_end)."""
    nch, h, w = left.shape
    disp_l = np.full((h, w), np.nan, dtype=np.float32)
    disp_r = np.full((h, w), np.nan, dtype=np.float32)
    ro = half if clip else 0
    pad = nd + dmin + 1
    left_p = np.zeros((nch, h + 2 * ro, w), dtype=np.uint8)
    left_p[:, ro:ro + h, :] = left
    right_p = np.zeros((nch, h + 2 * ro, w + 2 * pad), dtype=np.uint8)
    right_p[:, ro:ro + h, pad:pad + w] = right
    rows = h + 2 * ro - 2 * half
    x_start = 0 if clip else half
    x_end = w if clip else w - half
    return disp_l, disp_r, left_p, right_p, pad, rows, x_start, x_end


@njit(cache=True, parallel=True, fastmath=True)
def match_rows(left, right, dmin, nd, half, kind, uniqueness, fit, want_right, clip,
               sum_l, sq_l, sum_r, sq_r):
    """Disparity maps (left, right) for uint8 images shaped (channels, rows, cols).

    The cost of a window is summed over channels (NCC takes one channel). clip: windows at the
    image edge are cropped to the image instead of making the pixel invalid. dmin >= 0. fit: the
    sub-pixel fit (FIT_NONE, FIT_PARABOLA or FIT_EQUIANGULAR).
    """
    nch, h, w = left.shape
    disp_l, disp_r, left_p, right_p, pad, rows, x_start, x_end = padded_pair(left, right, dmin,
                                                                           nd, half, clip)
    ro = half if clip else 0  # the zero rows padded_pair put above the image
    if rows <= 0 or x_end <= x_start:
        return disp_l, disp_r
    shift = _pack_shift(kind, nd, 2 * half + 1, nch)
    nbands = min(rows, 16)
    for band in prange(nbands):
        y0 = half + rows * band // nbands
        y1 = half + rows * (band + 1) // nbands
        col = np.zeros((w, nd), dtype=np.int32)
        win = np.zeros(nd, dtype=np.int32)
        zero = np.zeros(nd, dtype=np.int32)
        rowcost = np.full((w, nd), np.inf, dtype=np.float32)
        fcost = np.empty(nd, dtype=np.float32)
        base0 = pad - dmin - (nd - 1)
        for yy in range(y0 - half, y0 + half + 1):
            _slide_cols(col, left_p, right_p, yy, yy, base0, nd, kind, True)
        for y in range(y0, y1):
            if y > y0:
                _slide_cols(col, left_p, right_p, y + half, y - half - 1, base0, nd, kind, False)
            yi = y - ro  # image row
            win[:] = 0
            for xx in range(max(0, x_start - half), x_start + half):
                _slide_window(win, col[xx], zero)
            for x in range(x_start, x_end):
                enter = col[x + half] if x + half < w else zero
                leave = col[x - half - 1] if x - half - 1 >= 0 else zero
                # the right window of disparity d starts at max(0, x-half) - d: keep it inside
                dmax = max(0, x - half) - dmin
                kmin = max(0, nd - 1 - dmax)
                if kmin == 0 and shift >= 0:
                    k = _slide_window_argmin(win, enter, leave, shift)
                    off, ok = _decide(win, k, 0, nd, uniqueness, fit)
                    if want_right:
                        rowcost[x, :] = win
                    if ok:
                        d = dmin + nd - 1 - k
                        disp_l[yi, x] = d - off
                    continue
                _slide_window(win, enter, leave)
                if dmax < 0:
                    rowcost[x, :] = np.inf
                    continue
                if kind == COST_NCC:
                    _ncc_row(win, yi, x, half, h, w, dmin, nd, sum_l, sq_l, sum_r, sq_r, fcost)
                    k = _argmin(fcost, kmin, nd)
                    off, ok = _decide(fcost, k, kmin, nd, uniqueness, fit)
                else:
                    k = _argmin(win, kmin, nd)
                    off, ok = _decide(win, k, kmin, nd, uniqueness, fit)
                if want_right:
                    for j in range(nd):
                        rowcost[x, j] = np.inf if j < kmin else (
                            fcost[j] if kind == COST_NCC else win[j])
                if ok:
                    d = dmin + nd - 1 - k
                    disp_l[yi, x] = d - off
            if want_right:
                _right_row(rowcost, disp_r, yi, w, x_start, x_end, dmin, nd, fit)
    return disp_l, disp_r


@njit(cache=True, fastmath=True)
def _right_row(rowcost, disp_r, y, w, x_start, x_end, dmin, nd, fit):
    # cost of right pixel xr at disparity d is the left cost at x = xr + d
    col = np.empty(nd, dtype=np.float32)
    for xr in range(w):
        any_valid = False
        for k in range(nd):
            x = xr + dmin + nd - 1 - k
            if x < x_start or x >= x_end:
                col[k] = np.inf
            else:
                col[k] = rowcost[x, k]
                any_valid = any_valid or col[k] < np.inf
        if not any_valid:
            continue
        k = _argmin(col, 0, nd)
        off, _ = _decide(col, k, 0, nd, 0.0, fit)
        if col[k] < np.inf:
            d = dmin + nd - 1 - k
            disp_r[y, xr] = d - off
