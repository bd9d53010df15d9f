"""Own SAD block matcher: banded, row-tiled running sums in narrow integer lanes, WTA, sub-pixel.

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

Two kernels, the same maps bit for bit: uint16 column and window sums (grey and colour up to
window 9, the bench's and the servo's) take _match_u16, written in explicit 16-lane vectors
(sad_lanes.py: the column sums one channel at a time with the candidate loop innermost; the
window's slide, its minimum and the first lane equal to it; the right map's costs), at 0.4-0.6x
the time of _match_any, the loops LLVM vectorises, which every other lane type takes.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, prange

from host.stereo import sad_lanes as V
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


class RightCosts(NamedTuple):
    """A band's working arrays for the right map (_keep_costs, _right_row)."""

    costs: np.ndarray  # (w + 2, nd): row x + 1 holds output x's costs
    low: np.ndarray  # (w + dmin + nd - 1,): at xr + dmin + nd - 1, right pixel xr's lowest
    # cost so far in the row
    at: np.ndarray  # the same shape: the smallest candidate with that cost


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
def _keep_costs(rc, win, x, kmin, nd):
    """Output x's costs of candidates kmin .. nd - 1, for the right map (_right_row): kept
    as they are (rc.costs[x + 1], contiguous), and folded into the running minimum of
    each right pixel they belong to (candidate k of x is right pixel x + k - dmin - nd + 1,
    at rc.low[x + k] / rc.at[x + k]), all contiguous in k. x rises, so a right pixel's
    candidates come in falling k: taking a cost equal to the minimum so far keeps the
    smallest k of the minimum, the one the first-index scan of its costs found."""
    costs = rc.costs[x + 1]
    for k in range(kmin, nd):
        costs[k] = win[k]
    low = rc.low[x:x + nd]
    at = rc.at[x:x + nd]
    for k in range(kmin, nd):
        c = win[k]
        take = c <= low[k]
        low[k] = c if take else low[k]
        at[k] = k if take else at[k]


@njit(cache=True, fastmath=True, inline="always")
def _interior(col, win, floor, idx, rc, out, yi, x_from, x_to, half, dmin, nd, fit,
              want_right):
    """The common case: both window columns inside, every candidate allowed, no uniqueness.

    Reads the column sums by index (no views) and fuses the slide with the minimum.
    """
    for x in range(x_from, x_to):
        best, m = _slide_lowest(win, floor, idx, col, x + half, x - half - 1)
        if want_right:
            _keep_costs(rc, win, x, 0, nd)
        off = 0.0
        if fit != FIT_NONE and 0 < best < nd - 1:
            off = fit_offset(np.float32(win[best - 1]), np.float32(m),
                             np.float32(win[best + 1]), fit)
        out[yi, x] = dmin + nd - 1 - best - off


@njit(cache=True, fastmath=True, inline="always")
def _edge(col, win, floor, idx, efloor, eidx, rc, out, yi, x_from, x_to, half, dmin, nd, fit,
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
            _keep_costs(rc, win, x, kmin, nd)
        off = 0.0
        if fit != FIT_NONE and kmin < best < nd - 1:
            off = fit_offset(np.float32(win[best - 1]), np.float32(m),
                             np.float32(win[best + 1]), fit)
        out[yi, x] = dmin + nd - 1 - best - off


@njit(cache=True, fastmath=True, inline="always")
def _row_start(col, win, zero, x_from, x_to, x_start, half, w, dmin, nd, uniqueness):
    """A row's outputs [x_from, x_to) begun: the window filled at the row's first output, and
    its runs (fast_lo, fast_hi): outputs that need none of the edge rules, and (edge_lo,
    edge_hi): those left of them with some candidates' right windows outside (kmin > 0); both
    empty (at x_to) with a uniqueness test."""
    if x_from == x_start:
        win[:] = 0
        for xx in range(max(0, x_start - half), x_start + half):
            _slide(win, col[xx], zero)
    fast_lo = max(x_from, half + 1, half + dmin + nd - 1)
    fast_hi = min(x_to, w - half)
    edge_lo = max(x_from, half + 1, half + dmin)
    edge_hi = min(x_to, w - half, half + dmin + nd - 1)
    if uniqueness > 0.0 or fast_hi <= fast_lo:
        fast_lo = fast_hi = x_to
    if uniqueness > 0.0 or edge_hi <= edge_lo:
        edge_lo = edge_hi = x_to
    return fast_lo, fast_hi, edge_lo, edge_hi


@njit(cache=True, fastmath=True, inline="always")
def _one_output(col, win, zero, floor, idx, rc, out, yi, x, half, w, dmin, nd, uniqueness, fit,
                want_right):
    """Output x by the plain rules: the window slid on by a column, the winner among the
    candidates whose right window is inside the image, its uniqueness and fit."""
    enter = col[x + half] if x + half < w else zero
    leave = col[x - half - 1] if x - half - 1 >= 0 else zero
    # the right window of disparity d starts at max(0, x - half) - d: keep it inside
    dmax = max(0, x - half) - dmin
    kmin = max(0, nd - 1 - dmax)
    _slide(win, enter, leave)
    if kmin == 0:
        k, _ = _lowest(win, floor, idx)
    else:
        if dmax < 0:
            return
        k = _argmin(win, kmin, nd)
    if want_right:
        _keep_costs(rc, win, x, kmin, nd)
    off, ok = _decide(win, k, kmin, nd, uniqueness, fit)
    if ok:
        out[yi, x] = dmin + nd - 1 - k - off


@njit(cache=True, fastmath=True)
def _row_outputs(col, win, zero, floor, idx, efloor, eidx, rc, out, yi, x_from, x_to,
                 x_start, half, w, dmin, nd, uniqueness, fit, want_right):
    """Slide the window over outputs x in [x_from, x_to) of one row, writing out[yi, x] (and,
    want_right, each output's costs into rc for _right_row)."""
    fast_lo, fast_hi, edge_lo, edge_hi = _row_start(col, win, zero, x_from, x_to, x_start,
                                                    half, w, dmin, nd, uniqueness)
    x = x_from
    while x < x_to:
        if x == edge_lo:
            _edge(col, win, floor, idx, efloor, eidx, rc, out, yi, edge_lo, edge_hi, half,
                  dmin, nd, fit, want_right)
            x = edge_hi
            continue
        if x == fast_lo:
            _interior(col, win, floor, idx, rc, out, yi, fast_lo, fast_hi, half, dmin, nd,
                      fit, want_right)
            x = fast_hi
            continue
        _one_output(col, win, zero, floor, idx, rc, out, yi, x, half, w, dmin, nd, uniqueness,
                    fit, want_right)
        x += 1


@njit(cache=True, fastmath=True)
def _right_row(rc, disp_r, y, w, dmin, nd, top, fit):
    """The right map's row y. The cost of right pixel xr at candidate k is the left cost of
    x = xr + dmin + nd - 1 - k (top where that x has no cost: outside the outputs' columns,
    or its right window outside the image); _keep_costs folded the row's costs into each
    right pixel's minimum and its smallest k (rc.low / rc.at at xr + dmin + nd - 1),
    and kept them (rc.costs[x + 1]) for the winner's two neighbours. Leaves rc.low at
    top for the next row."""
    for xr in range(w):
        i = xr + dmin + nd - 1
        m = rc.low[i]
        if m == top:
            continue
        k = rc.at[i]
        off = 0.0
        if fit != FIT_NONE and 0 < k < nd - 1:
            x = i - k  # the winner's left pixel; candidate k - 1 is x + 1's, k + 1 is x - 1's
            off = fit_offset(np.float32(rc.costs[x + 2, k - 1]), np.float32(m),
                             np.float32(rc.costs[x, k + 1]), fit)
        disp_r[y, xr] = dmin + nd - 1 - k - off
    rc.low[:] = top


def match_sad(left: np.ndarray, right: np.ndarray, dmin: int, nd: int, half: int,
              uniqueness: float, fit: int, want_right: bool, clip: bool, col_proto: np.ndarray,
              win_proto: np.ndarray, top: int, nbands: int) -> tuple[np.ndarray, np.ndarray]:
    """Disparity maps (left, right) for uint8 images shaped (channels, rows, cols).

    The cost sums over channels. clip: windows at the image edge are cropped to the image
    instead of making the pixel invalid. dmin >= 0. col_proto / win_proto: empty arrays whose
    dtypes are the lanes of the column and window sums (see lane_types); top: a window sum
    no real cost reaches (the window dtype's largest value); nbands: bands of rows, one per
    thread (numba.get_num_threads()). Column and window sums both in uint16 take the kernel
    of explicit 16-lane vectors (_match_u16), any other lanes _match_any.
    """
    kernel = _match_u16 if col_proto.dtype == win_proto.dtype == np.uint16 else _match_any
    maps: tuple[np.ndarray, np.ndarray] = kernel(left, right, dmin, nd, half, uniqueness, fit,
                                                 want_right, clip, col_proto, win_proto, top,
                                                 nbands)
    return maps


@njit(cache=True, parallel=True, fastmath=True)
def _match_any(left, right, dmin, nd, half, uniqueness, fit, want_right, clip, col_proto,
               win_proto, top, nbands):
    """match_sad in any lanes: loops LLVM vectorises (candidates in stretches of LANES)."""
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
        # what the right map reads (_keep_costs, _right_row): the costs are written at the
        # same places in every row, and never where a candidate has no cost, so top there
        # stays; the running minima start each row at top
        wr = w if want_right else 0
        nr = wr + dmin + nd - 1 if want_right else 1
        rc = RightCosts(np.full((wr + 2, nd), top, dtype=wdt), np.full(nr, top, dtype=wdt),
                        np.zeros(nr, dtype=wdt))
        for yy in range(y0 - half, y0 + half + 1):
            _cols_add(col, left_p, right_p, yy, 0, w, base0, ndc)
        for y in range(y0, y1):
            yi = y - ro  # image row
            if y == y0:
                _row_outputs(col, win, zero, floor, idx, efloor, eidx, rc, disp_l, yi,
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
                        _row_outputs(col, win, zero, floor, idx, efloor, eidx, rc,
                                     disp_l, yi, done, upto, x_start, half, w, dmin, nd,
                                     uniqueness, fit, want_right)
                        done = upto
            if want_right:
                _right_row(rc, disp_r, yi, w, dmin, nd, top, fit)
    return disp_l, disp_r


# ---- the kernel of explicit 16-lane vectors (column and window sums both uint16) ----
# Candidates run in ndv = nd rounded up to V.LANES lanes; the lanes past nd sum pixels right
# of the range, and floor lifts them to the top (0xFFFF, as an OR: floor is 0 or 0xFFFF) before
# any minimum, as it lifts the edge's lanes below kmin (efloor). Arrays are read by flat index
# (row * ndv + lane), the right view by (channel * rows + row) * cols + column.


@njit(cache=True, fastmath=True, inline="always")
def _vcols_add(col, left, right_p, y, x0, x1, base0, ndv):
    # column sums of x in [x0, x1) gain row y (first window of a band)
    nr, nc = right_p.shape[1], right_p.shape[2]
    for ch in range(left.shape[0]):
        lrow = left[ch, y]
        r0 = (ch * nr + y) * nc + base0
        for x in range(x0, x1):
            a = V.splat(lrow[x])
            for v in range(0, ndv, V.LANES):
                i = x * ndv + v
                V.store(col, i, V.vadd(V.load(col, i), V.absdiff(a, V.widen(right_p, r0 + x + v))))


@njit(cache=True, fastmath=True, inline="always")
def _vcols_slide(col, left, right_p, y_new, y_old, x0, x1, base0, ndv):
    # column sums of x in [x0, x1) move one row down: y_new enters, y_old leaves
    nr, nc = right_p.shape[1], right_p.shape[2]
    for ch in range(left.shape[0]):
        ln = left[ch, y_new]
        lo = left[ch, y_old]
        rn = (ch * nr + y_new) * nc + base0
        ro = (ch * nr + y_old) * nc + base0
        for x in range(x0, x1):
            a = V.splat(ln[x])
            o = V.splat(lo[x])
            for v in range(0, ndv, V.LANES):
                i = x * ndv + v
                c = V.vadd(V.load(col, i), V.absdiff(a, V.widen(right_p, rn + x + v)))
                V.store(col, i, V.vsub(c, V.absdiff(o, V.widen(right_p, ro + x + v))))


@njit(cache=True, fastmath=True, inline="always")
def _vslide_lowest(win, floor, col, e, o, nd, ndv):
    """The window moves one column right (column e enters, column o leaves); returns (the
    smallest candidate of the lowest lifted sum, that sum), as _slide_lowest."""
    m = V.splat(0xFFFF)
    for v in range(0, ndv, V.LANES):
        s = V.vsub(V.vadd(V.load(win, v), V.load(col, e * ndv + v)), V.load(col, o * ndv + v))
        V.store(win, v, s)
        m = V.vmin(m, V.vor(s, V.load(floor, v)))
    low = V.hmin(m)
    for v in range(0, ndv, V.LANES):
        j = V.first_eq(V.vor(V.load(win, v), V.load(floor, v)), low)
        if j < V.LANES:
            return v + j, low
    return nd, low


@njit(cache=True, fastmath=True, inline="always")
def _vkeep_costs(rc, win, floor, x, ndv):
    """_keep_costs in vectors: every lane, those without a cost (floor) lifted to the top,
    which no right pixel's minimum takes once it has a real cost (and one with only such
    lanes stays at the top: no disparity)."""
    for v in range(0, ndv, V.LANES):
        c = V.vor(V.load(win, v), V.load(floor, v))
        V.store(rc.costs, (x + 1) * ndv + v, c)
        low = V.load(rc.low, x + v)
        V.store(rc.at, x + v, V.take_le(c, low, V.iota(v), V.load(rc.at, x + v)))
        V.store(rc.low, x + v, V.vmin(c, low))


@njit(cache=True, fastmath=True, inline="always")
def _vrun(col, win, floor, rc, out, yi, x_from, x_to, half, dmin, nd, ndv, fit, want_right,
          edge):
    """_interior (edge False) or _edge (True) in vectors: floor lifts the lanes that never
    win; on the edge it is a copy whose lanes below kmin are lifted too, one let in a column."""
    kmin = 0
    if edge:
        kmin = nd - 1 - (x_from - half - dmin)
        for k in range(kmin):
            floor[k] = 0xFFFF
    for x in range(x_from, x_to):
        if edge:
            kmin = nd - 1 - (x - half - dmin)
            floor[kmin] = 0
        best, m = _vslide_lowest(win, floor, col, x + half, x - half - 1, nd, ndv)
        if want_right:
            _vkeep_costs(rc, win, floor, x, ndv)
        off = 0.0
        if fit != FIT_NONE and kmin < best < nd - 1:
            off = fit_offset(np.float32(win[best - 1]), np.float32(m),
                             np.float32(win[best + 1]), fit)
        out[yi, x] = dmin + nd - 1 - best - off


@njit(cache=True, fastmath=True)
def _row_outputs_u16(col, win, zero, floor, idx, efloor, rc, out, yi, x_from, x_to,
                     x_start, half, w, dmin, nd, ndv, uniqueness, fit, want_right):
    """_row_outputs with the interior and the edge in vectors (_vrun)."""
    fast_lo, fast_hi, edge_lo, edge_hi = _row_start(col, win, zero, x_from, x_to, x_start,
                                                    half, w, dmin, nd, uniqueness)
    x = x_from
    while x < x_to:
        if x == edge_lo:
            efloor[:] = floor
            _vrun(col, win, efloor, rc, out, yi, edge_lo, edge_hi, half, dmin, nd, ndv, fit,
                  want_right, True)
            x = edge_hi
            continue
        if x == fast_lo:
            _vrun(col, win, floor, rc, out, yi, fast_lo, fast_hi, half, dmin, nd, ndv, fit,
                  want_right, False)
            x = fast_hi
            continue
        _one_output(col, win, zero, floor, idx, rc, out, yi, x, half, w, dmin, nd, uniqueness,
                    fit, want_right)
        x += 1


@njit(cache=True, parallel=True, fastmath=True)
def _match_u16(left, right, dmin, nd, half, uniqueness, fit, want_right, clip, col_proto,
               win_proto, top, nbands):
    """match_sad with uint16 column and window sums, in explicit 16-lane vectors."""
    nch, h, w = left.shape
    disp_l, disp_r, left_p, right_p, pad, rows, x_start, x_end = padded_pair(left, right, dmin,
                                                                           nd, half, clip)
    ro = half if clip else 0
    if rows <= 0 or x_end <= x_start:
        return disp_l, disp_r
    base0 = pad - dmin - (nd - 1)
    ndv = -(-nd // V.LANES) * V.LANES
    tile = max(2 * half + 2, TILE_BYTES // (ndv * 2))
    short = base0 + w + ndv - 1 - right_p.shape[2]  # the last column's lanes past the view
    if short > 0:
        wider = np.zeros((nch, right_p.shape[1], right_p.shape[2] + short), dtype=np.uint8)
        wider[:, :, :right_p.shape[2]] = right_p
        right_p = wider
    nbands = max(1, min(rows, nbands))
    for band in prange(nbands):
        y0 = half + rows * band // nbands
        y1 = half + rows * (band + 1) // nbands
        col = np.zeros((w, ndv), dtype=np.uint16)
        win = np.zeros(ndv, dtype=np.uint16)
        zero = np.zeros(ndv, dtype=np.uint16)
        floor = np.zeros(ndv + 1, dtype=np.uint16)
        floor[nd:] = 0xFFFF
        idx = np.minimum(np.arange(ndv + 1), nd).astype(np.uint16)
        efloor = floor.copy()
        wr = w if want_right else 0
        nr = wr + dmin + nd - 1 + ndv if want_right else ndv
        rc = RightCosts(np.full((wr + 2, ndv), top, dtype=np.uint16),
                        np.full(nr, top, dtype=np.uint16), np.zeros(nr, dtype=np.uint16))
        for yy in range(y0 - half, y0 + half + 1):
            _vcols_add(col, left_p, right_p, yy, 0, w, base0, ndv)
        for y in range(y0, y1):
            yi = y - ro
            if y == y0:
                _row_outputs_u16(col, win, zero, floor, idx, efloor, rc, disp_l, yi, x_start,
                                 x_end, x_start, half, w, dmin, nd, ndv, uniqueness, fit,
                                 want_right)
            else:
                done = x_start
                for tx0 in range(0, w, tile):
                    tx1 = min(w, tx0 + tile)
                    _vcols_slide(col, left_p, right_p, y + half, y - half - 1, tx0, tx1, base0,
                                 ndv)
                    upto = x_end if tx1 == w else min(x_end, tx1 - half)
                    if upto > done:
                        _row_outputs_u16(col, win, zero, floor, idx, efloor, rc, disp_l, yi,
                                         done, upto, x_start, half, w, dmin, nd, ndv,
                                         uniqueness, fit, want_right)
                        done = upto
            if want_right:
                _right_row(rc, disp_r, yi, w, dmin, nd, top, fit)
    return disp_l, disp_r
