"""FROZEN ORACLE (issue 25): host/stereo/sad.py as it was at 4db45a1, before the right map's
costs were folded into running minima; tests/stereo/test_sad_right_fold.py checks that the
kernel still gives these maps to the bit. Do not edit.

Own SAD block matcher: banded, row-tiled running sums in narrow integer lanes, WTA, sub-pixel.

Conventions as in block_matching: the left image is the reference, left x matches right x - d,
output is float32 px with NaN where there is no disparity. Candidate k of pixel x is disparity
dmin + nd - 1 - k, so the right pixels of one x form a contiguous run and the k loops vectorise.

Work per pixel and candidate: one column-sum update (a row enters, a row leaves) and one window
slide (a column enters, a column leaves) fused with the minimum. The image is cut into one band
of rows per thread; a band sums its first window once and then only slides. Within a row the
column sums are updated one tile of columns at a time and the window slides over that tile at
once, so the sums it reads are still in L1. Sums are uint16 when the largest window cost fits
(grey up to 15x15), else int32; the arithmetic wraps exactly because every true sum fits.
The columns left of the full range (x < nd + half, where some candidates' right windows leave
the image) slide and take their minimum in the same vector pass as the interior, the candidates
outside masked, instead of one plain loop per candidate.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from host.stereo.block_matching import _argmin, _decide, padded_pair
from host.stereo.subpixel import FIT_NONE, fit_offset

TILE_BYTES = 8192  # column sums updated per tile: well inside a 32 KiB L1 with the pixel rows
# The window's candidate lanes are nd rounded up to a multiple of LANES (a 512-bit vector of
# uint16) and the interior's loops over them run in stretches of at most LANES: with that bound
# known, LLVM makes each stretch one vector, where a loop of unknown length gets a 4-way
# interleaved body of 128 lanes whose 8-lane and scalar remainder took every count below 128
LANES = 32
# The column sums' candidate loop runs over nd rounded up to a multiple of COL_LANES (two such
# vectors): LLVM's main body takes 64 lanes at a time, so 48, 56 or 96 candidates ran part of
# every column in the remainder loop (640 columns: 48 took 7.0-10.1 us a row, 64 5.3-8.0)
COL_LANES = 64


def lane_types(channels: int, size: int) -> tuple[type, type]:
    """(column-sum dtype, window-sum dtype): uint16 where the largest sum fits, else int32."""
    top_col = 255 * channels * size
    top_win = top_col * size
    col = np.uint16 if top_col < 0xFFFF else np.int32
    win = np.uint16 if top_win < 0xFFFF else np.int32
    return col, win


@njit(cache=True, fastmath=True, inline="always")
def _absdiff(a, b):
    return max(a, b) - min(a, b)


@njit(cache=True, fastmath=True)
def _cols_add(col, left, right_p, y, x0, x1, base0, nd):
    # column sums of x in [x0, x1) gain row y (first window of a band)
    for ch in range(left.shape[0]):
        lrow = left[ch, y]
        rrow = right_p[ch, y]
        for x in range(x0, x1):
            a = lrow[x]
            c = col[x]
            r = rrow[base0 + x:base0 + x + nd]
            for k in range(nd):
                c[k] += _absdiff(a, r[k])


@njit(cache=True, fastmath=True, inline="always")
def _cols_slide(col, left, right_p, y_new, y_old, x0, x1, base0, nd):
    # column sums of x in [x0, x1) move one row down: y_new enters, y_old leaves
    for ch in range(left.shape[0]):
        ln = left[ch, y_new]
        lo = left[ch, y_old]
        rn_row = right_p[ch, y_new]
        ro_row = right_p[ch, y_old]
        for x in range(x0, x1):
            a = ln[x]
            o = lo[x]
            c = col[x]
            rn = rn_row[base0 + x:base0 + x + nd]
            ro = ro_row[base0 + x:base0 + x + nd]
            for k in range(nd):
                c[k] = c[k] + _absdiff(a, rn[k]) - _absdiff(o, ro[k])


@njit(cache=True, fastmath=True, inline="always")
def _best_in(win, m, idx, k0):
    # lanes k0 .. k0 + LANES - 1 (those below win.size): a loop bounded by LANES
    none = idx[win.size]
    best = none
    for j in range(min(win.size - k0, LANES)):
        best = min(best, idx[k0 + j] if win[k0 + j] == m else none)
    return best


@njit(cache=True, fastmath=True, inline="always")
def _best(win, m, idx):
    """The smallest candidate whose window sum is m. idx holds 0 .. nd - 1, then nd ("none")
    on the lanes past the real candidates and at idx[win.size]."""
    n = win.size
    best = idx[n]
    for k in range(4 * LANES, n):  # past four stretches: a plain loop
        best = min(best, idx[k] if win[k] == m else idx[n])
    # the stretches' own results, taken apart so they do not wait on each other
    b0 = _best_in(win, m, idx, 0)
    b1 = _best_in(win, m, idx, LANES)
    b2 = _best_in(win, m, idx, 2 * LANES)
    b3 = _best_in(win, m, idx, 3 * LANES)
    return min(best, min(min(b0, b1), min(b2, b3)))


@njit(cache=True, fastmath=True, inline="always")
def _lowest(win, floor, idx):
    """(the smallest candidate of the lowest window sum, that sum).

    floor lifts the lanes past the real candidates to the window dtype's top (as does
    floor[win.size]). Every comparison is between values of the window's own dtype (a uint16
    against an int64 would go through float64 in numba), so the loops run in full vectors.
    """
    m = floor[win.size]
    for k in range(win.size):
        m = min(m, max(win[k], floor[k]))
    return _best(win, m, idx), m


@njit(cache=True, fastmath=True, inline="always")
def _slide_min_in(win, floor, col, e, o, k0):
    # lanes k0 .. k0 + LANES - 1 (those below win.size): a loop bounded by LANES
    m = floor[win.size]
    for j in range(min(win.size - k0, LANES)):
        k = k0 + j
        win[k] = win[k] + col[e, k] - col[o, k]
        m = min(m, max(win[k], floor[k]))
    return m


@njit(cache=True, fastmath=True, inline="always")
def _slide_lowest(win, floor, idx, col, e, o):
    """The window moves one column right (column e enters, column o leaves), its minimum
    taken in the same pass, in stretches of LANES; then as _lowest."""
    n = win.size
    # the stretches' own minima, taken apart so they do not wait on each other
    m0 = _slide_min_in(win, floor, col, e, o, 0)
    m1 = _slide_min_in(win, floor, col, e, o, LANES)
    m2 = _slide_min_in(win, floor, col, e, o, 2 * LANES)
    m3 = _slide_min_in(win, floor, col, e, o, 3 * LANES)
    m = min(min(m0, m1), min(m2, m3))
    for k in range(4 * LANES, n):  # past four stretches: a plain loop
        win[k] = win[k] + col[e, k] - col[o, k]
        m = min(m, max(win[k], floor[k]))
    return _best(win, m, idx), m


@njit(cache=True, fastmath=True, inline="always")
def _slide(win, enter, leave):
    for k in range(win.size):
        win[k] = win[k] + enter[k] - leave[k]


@njit(cache=True, fastmath=True, inline="always")
def _keep_costs(skew, win, x, kmin, nd):
    # output x's costs of candidates kmin .. nd - 1 where the right map reads them (skew)
    for k in range(kmin, nd):
        skew[x + k, k] = win[k]


@njit(cache=True, fastmath=True, inline="always")
def _interior(col, win, floor, idx, skew, out, yi, x_from, x_to, half, dmin, nd, fit,
              want_right):
    """The common case: both window columns inside, every candidate allowed, no uniqueness.

    Reads the column sums by index (no views) and fuses the slide with the minimum.
    """
    for x in range(x_from, x_to):
        best, m = _slide_lowest(win, floor, idx, col, x + half, x - half - 1)
        if want_right:
            _keep_costs(skew, win, x, 0, nd)
        off = 0.0
        if fit != FIT_NONE and 0 < best < nd - 1:
            off = fit_offset(np.float32(win[best - 1]), np.float32(m),
                             np.float32(win[best + 1]), fit)
        out[yi, x] = dmin + nd - 1 - best - off


@njit(cache=True, fastmath=True, inline="always")
def _edge(col, win, floor, idx, efloor, eidx, skew, out, yi, x_from, x_to, half, dmin, nd, fit,
          want_right):
    """Outputs whose right windows leave the image for some candidates (kmin > 0): both window
    columns inside, no uniqueness. As _interior, with the candidates below kmin lifted out by
    efloor / eidx (a copy of floor / idx whose lanes below kmin say top / none; kmin falls by
    one a column, so one lane is let in per column): the same winner as _argmin from kmin."""
    kmin = nd - 1 - (x_from - half - dmin)
    for k in range(idx.size):
        masked = k < kmin
        efloor[k] = floor[win.size] if masked else floor[k]
        eidx[k] = idx[win.size] if masked else idx[k]
    for x in range(x_from, x_to):
        kmin = nd - 1 - (x - half - dmin)
        efloor[kmin] = floor[kmin]
        eidx[kmin] = idx[kmin]
        best, m = _slide_lowest(win, efloor, eidx, col, x + half, x - half - 1)
        if want_right:
            _keep_costs(skew, win, x, kmin, nd)
        off = 0.0
        if fit != FIT_NONE and kmin < best < nd - 1:
            off = fit_offset(np.float32(win[best - 1]), np.float32(m),
                             np.float32(win[best + 1]), fit)
        out[yi, x] = dmin + nd - 1 - best - off


@njit(cache=True, fastmath=True)
def _row_outputs(col, win, zero, floor, idx, efloor, eidx, skew, out, yi, x_from, x_to,
                 x_start, half, w, dmin, nd, uniqueness, fit, want_right):
    """Slide the window over outputs x in [x_from, x_to) of one row, writing out[yi, x] (and,
    want_right, each output's costs into skew for _right_row)."""
    if x_from == x_start:
        win[:] = 0
        for xx in range(max(0, x_start - half), x_start + half):
            _slide(win, col[xx], zero)
    # outputs that need none of the edge rules below
    fast_lo = max(x_from, half + 1, half + dmin + nd - 1)
    fast_hi = min(x_to, w - half)
    # outputs left of those with some candidates' right windows outside (kmin > 0)
    edge_lo = max(x_from, half + 1, half + dmin)
    edge_hi = min(x_to, w - half, half + dmin + nd - 1)
    if uniqueness > 0.0 or fast_hi <= fast_lo:
        fast_lo = fast_hi = x_to
    if uniqueness > 0.0 or edge_hi <= edge_lo:
        edge_lo = edge_hi = x_to
    x = x_from
    while x < x_to:
        if x == edge_lo:
            _edge(col, win, floor, idx, efloor, eidx, skew, out, yi, edge_lo, edge_hi, half,
                  dmin, nd, fit, want_right)
            x = edge_hi
            continue
        if x == fast_lo:
            _interior(col, win, floor, idx, skew, out, yi, fast_lo, fast_hi, half, dmin, nd,
                      fit, want_right)
            x = fast_hi
            continue
        enter = col[x + half] if x + half < w else zero
        leave = col[x - half - 1] if x - half - 1 >= 0 else zero
        # the right window of disparity d starts at max(0, x - half) - d: keep it inside
        dmax = max(0, x - half) - dmin
        kmin = max(0, nd - 1 - dmax)
        x += 1
        _slide(win, enter, leave)
        if kmin == 0:
            k, _ = _lowest(win, floor, idx)
        else:
            if dmax < 0:
                continue
            k = _argmin(win, kmin, nd)
        if want_right:
            _keep_costs(skew, win, x - 1, kmin, nd)
        off, ok = _decide(win, k, kmin, nd, uniqueness, fit)
        if ok:
            out[yi, x - 1] = dmin + nd - 1 - k - off


@njit(cache=True, fastmath=True)
def _right_row(skew, disp_r, y, w, dmin, nd, top, fit):
    """The right map's row y. The cost of right pixel xr at candidate k is the left cost of
    x = xr + dmin + nd - 1 - k, which _keep_costs put at skew[x + k, k]: right pixel xr's
    costs are the one row skew[xr + dmin + nd - 1] (top where that x has no cost: outside the
    outputs' columns, or its right window outside the image)."""
    for xr in range(w):
        c = skew[xr + dmin + nd - 1]
        m = top
        for k in range(nd):
            m = min(m, c[k])
        if m == top:
            continue
        k = 0
        while c[k] != m:
            k += 1
        off, _ = _decide(c, k, 0, nd, 0.0, fit)
        disp_r[y, xr] = dmin + nd - 1 - k - off


@njit(cache=True, parallel=True, fastmath=True)
def match_sad(left, right, dmin, nd, half, uniqueness, fit, want_right, clip, col_proto,
              win_proto, top, nbands):
    """Disparity maps (left, right) for uint8 images shaped (channels, rows, cols).

    The cost sums over channels. clip: windows at the image edge are cropped to the image
    instead of making the pixel invalid. dmin >= 0. col_proto / win_proto: empty arrays whose
    dtypes are the lanes of the column and window sums (see lane_types); top: a window sum
    no real cost reaches (the window dtype's largest value); nbands: bands of rows, one per
    thread (numba.get_num_threads()).
    """
    nch, h, w = left.shape
    disp_l, disp_r, left_p, right_p, pad, rows, x_start, x_end = padded_pair(left, right, dmin,
                                                                           nd, half, clip)
    ro = half if clip else 0  # the zero rows padded_pair put above the image
    if rows <= 0 or x_end <= x_start:
        return disp_l, disp_r
    base0 = pad - dmin - (nd - 1)
    cdt = col_proto.dtype
    wdt = win_proto.dtype
    ndp = -(-nd // LANES) * LANES  # the window's lanes; past nd they never win (floor, idx)
    # the column sums' loop runs over ndc lanes (above LANES candidates, a multiple of
    # COL_LANES): those past nd sum pixels right of the range, which the window never takes
    ndc = nd if nd <= LANES else -(-nd // COL_LANES) * COL_LANES
    tile = max(2 * half + 2, TILE_BYTES // (ndc * col_proto.itemsize))
    short = base0 + w + ndc - 1 - right_p.shape[2]  # the last column's lanes past the view
    if short > 0:  # room for the lanes past nd right of the padded right view
        wider = np.zeros((nch, right_p.shape[1], right_p.shape[2] + short), dtype=np.uint8)
        wider[:, :, :right_p.shape[2]] = right_p
        right_p = wider
    nbands = max(1, min(rows, nbands))
    for band in prange(nbands):
        y0 = half + rows * band // nbands
        y1 = half + rows * (band + 1) // nbands
        col = np.zeros((w, max(ndc, ndp)), dtype=cdt)
        win = np.zeros(ndp, dtype=wdt)
        zero = np.zeros(ndp, dtype=cdt)
        floor = np.zeros(ndp + 1, dtype=wdt)
        floor[nd:] = top
        idx = np.minimum(np.arange(ndp + 1), nd).astype(wdt)
        efloor = floor.copy()
        eidx = idx.copy()
        # the costs the right map reads, skewed (_keep_costs); written at the same places in
        # every row, and never where a candidate has no cost, so top there stays
        skew = np.full((w + dmin + nd - 1 if want_right else 1, nd), top, dtype=wdt)
        for yy in range(y0 - half, y0 + half + 1):
            _cols_add(col, left_p, right_p, yy, 0, w, base0, ndc)
        for y in range(y0, y1):
            yi = y - ro  # image row
            if y == y0:
                _row_outputs(col, win, zero, floor, idx, efloor, eidx, skew, disp_l, yi,
                             x_start, x_end, x_start, half, w, dmin, nd, uniqueness, fit,
                             want_right)
            else:
                done = x_start
                for tx0 in range(0, w, tile):
                    tx1 = min(w, tx0 + tile)
                    _cols_slide(col, left_p, right_p, y + half, y - half - 1, tx0, tx1, base0,
                                ndc)
                    upto = x_end if tx1 == w else min(x_end, tx1 - half)
                    if upto > done:
                        _row_outputs(col, win, zero, floor, idx, efloor, eidx, skew,
                                     disp_l, yi, done, upto, x_start, half, w, dmin, nd,
                                     uniqueness, fit, want_right)
                        done = upto
            if want_right:
                _right_row(skew, disp_r, yi, w, dmin, nd, top, fit)
    return disp_l, disp_r
