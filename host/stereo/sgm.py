"""Own semi-global matcher: census Hamming cost, 4-, 5- or 8-path aggregation, WTA.

Cost: a 9x7 census of the grey images (62 bits, replicated border) compared by Hamming distance
(plus, with planes, the intensity term), made row by row where it is used (the census rows too,
from the padded grey images: no census image is kept), or a box-summed volume when
block_size > 1. The LR check can run row by row as each row is decided (no right map kept).
Aggregation (Hirschmueller's recurrence): 5 paths in one pass from the top (_down); 8 paths as two
directions that each store their sums for half the image (_sweep); 4 paths, the defaults, in
blocks of K rows from a stored row of the path from the bottom every K rows, with no volume
(_vertical, _four). Path costs, sums and penalties are uint16 with the disparity axis
innermost, so every per-disparity loop runs in 16-bit lanes. P2 is taken per path step from a
table indexed by the left image's grey step along it (penalty_table: adaptive, or one value).

Candidate j is disparity dmin + j; the left pixel x matches right pixel x - d. A candidate
whose right pixel falls outside the image costs the most a census can differ (CENSUS_BITS).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, prange, types
from numba.extending import intrinsic

from host.stereo import lanes as L
from host.stereo.postprocess import lr_row
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


def _lane_op(op):
    """A per-lane operation on two lanes.u16x16 values (as lanes.vmin: wrapping like uint16)."""
    @intrinsic
    def fn(typingctx, a, b):
        if not (a == L.u16x16 and b == L.u16x16):
            return None

        def codegen(context, builder, sig, args):
            return op(builder, args[0], args[1])
        return L.u16x16(a, b), codegen
    return fn


_vshl = _lane_op(lambda b, x, y: b.shl(x, y))  # lane by lane x << y (y < 16)
_vor = _lane_op(lambda b, x, y: b.or_(x, y))


@intrinsic
def _select_ule(typingctx, a, k, x, y):
    """Lane by lane x where a <= k (unsigned), else y."""
    if not all(v == L.u16x16 for v in (a, k, x, y)):
        return None

    def codegen(context, builder, sig, args):
        return builder.select(builder.icmp_unsigned("<=", args[0], args[1]), args[2], args[3])
    return L.u16x16(a, k, x, y), codegen


@njit(cache=True)
def census_row(img, y, out, b):
    """Row y of the 9x7 census of img into out (cols uint64): bit set where a neighbour is
    darker than the centre, neighbour k (row by row, the centre left out) at bit 61 - k.

    img is padded (CENSUS_H rows, CENSUS_W columns, replicated border), so the loop over x has
    no clamping and runs in vector lanes. The bits are gathered eight neighbours to a byte in
    b (8, cols) uint8 (four times the lanes of uint32: half the time of two uint32 rows), then
    joined: byte g holds neighbours 8g .. 8g + 7 (the last one 56 .. 61).
    """
    w = out.shape[0]
    b[:, :] = 0
    centre = img[y + CENSUS_H, CENSUS_W:CENSUS_W + w]
    k = 0
    for dy in range(2 * CENSUS_H + 1):
        nb_row = img[y + dy]
        for dx in range(2 * CENSUS_W + 1):
            if dy == CENSUS_H and dx == CENSUS_W:
                continue
            nb = nb_row[dx:dx + w]
            acc = b[k // 8]
            for x in range(w):
                acc[x] = (acc[x] << np.uint8(1)) | np.uint8(nb[x] < centre[x])
            k += 1
    for x in range(w):
        v = np.uint64(b[CENSUS_BITS // 8, x])
        for g in range(CENSUS_BITS // 8):
            v |= np.uint64(b[g, x]) << np.uint64(CENSUS_BITS - 8 - 8 * g)
        out[x] = v


@njit(cache=True, parallel=True)
def census(img):
    """9x7 census of a padded uint8 image (census_row at every row)."""
    hp, wp = img.shape
    h, w = hp - 2 * CENSUS_H, wp - 2 * CENSUS_W
    out = np.empty((h, w), dtype=np.uint64)
    for y in prange(h):
        b = np.empty((8, w), dtype=np.uint8)
        census_row(img, y, out[y], b)
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


PAD = np.uint16(0x3FFF)  # path cost beyond the disparity range: never the minimum
ROW_LANES = 16  # the 4-path pass's cost rows hold a multiple of this many candidates


@njit(cache=True, inline="always")
def padded(nd):
    """nd rounded up to a multiple of ROW_LANES: the width of the 4-path pass's cost rows and
    of the reversed right rows and planes (_cost_row), so the cost loops run over a multiple
    of 16 lanes, not into a scalar remainder: 640x480 took longer at 56 candidates than at 64.
    (Padded to 32, 640x480/48 took 1.05-1.13x the unpadded time, load 15-17.)"""
    return (nd + ROW_LANES - 1) // ROW_LANES * ROW_LANES


@njit(cache=True, fastmath=True, inline="always")
def _cost_row(cl, crrev, gl, gr, vol, pl, prrev, term, y, dmin, crow, cs):
    """Row y of the cost into crow (cols, nd): vol's row when a volume is given (box-summed
    cost), else the census Hamming distances of the census rows (cl[y], crrev[y], or where the
    padded grey images gl, gr are given, made from them into the scratch cs: _census_rows),
    plus (pl has channels) the intensity term, with term[0] where the right pixel is outside
    the image.

    crrev holds each right census row reversed and zero-padded, so candidate j of left x reads
    it forwards from w - 1 - x + dmin: a contiguous load, one vector popcount per 8 lanes (the
    loop over views vectorises; the same loop over 2-D indices does not). prrev holds the right
    image's planes the same way. The intensity term of a summed |difference| k over the
    channels is (min(k, term[1]) * term[2] + term[3]) >> term[4] (integer_term: the same as
    cost.census_ad_volume's table at every k), in uint16 lanes for three channels where the
    form is 16 bits at NARROW_SHIFT (_term_row3), else in uint32 (_term_row). The term and
    the Hamming distances run as two loops: joined, the uint64 popcount set the vector width
    of both (8 lanes), and the row took twice as long.
    """
    w, nd = crow.shape
    if vol.shape[0] > 0:
        crow[:, :vol.shape[2]] = vol[y]
        return
    if gl.shape[0] > 0:
        _census_rows(gl, gr, y, cs)
        lrow, rrev = cs[0], cs[1]
    else:
        lrow, rrev = cl[y], crrev[y]
    far = np.uint16(term[0])
    ch = pl.shape[0]
    # crow may be wider than the candidates (padded: the 4-path pass); the lanes past them
    # are made as far as the reversed rows reach and never read (_step reads nd lanes)
    nd = min(nd, rrev.shape[0] - (w - 1 + dmin))
    if ch > 0:
        nd = min(nd, prrev.shape[2] - (w - 1 + dmin))
    kcap = np.uint16(min(term[1], 0xFFFF))
    narrow = ch == 3 and term[4] == NARROW_SHIFT and term[1] * term[2] + term[3] < 0x10000
    ta, tb = np.uint16(term[2] & 0xFFFF), np.uint16(term[3] & 0xFFFF)
    # one loop over x per case, each with only its own inner loops: with the three cases'
    # loops in one x loop the defaults' row took 13.4 ms a 640x480/64 image, alone 7 ms
    if ch == 0:
        for x in range(w):
            _hamming(lrow, rrev, x, dmin, crow[x], nd, far, False)
    elif narrow:
        for x in range(w):
            _term_row3(pl, prrev, y, x, w - 1 - x + dmin, crow[x], nd, kcap, ta, tb)
            _hamming(lrow, rrev, x, dmin, crow[x], nd, far, True)
    else:
        for x in range(w):
            _term_row(pl, prrev, y, x, w - 1 - x + dmin, crow[x], nd, kcap, term)
            _hamming(lrow, rrev, x, dmin, crow[x], nd, far, True)


@njit(cache=True, fastmath=True, inline="always")
def _hamming(lrow, rrev, x, dmin, c, nd, far, add):
    """The census Hamming distances of left pixel x's nd candidates into c (added to it: add),
    far where the right pixel is outside the image (see _cost_row)."""
    a = lrow[x]
    base = lrow.shape[0] - 1 - x + dmin
    r = rrev[base:base + nd]
    if add:
        for j in range(nd):
            c[j] = c[j] + np.uint16(_popcount(a ^ r[j]))
    else:
        for j in range(nd):
            c[j] = np.uint16(_popcount(a ^ r[j]))
    for j in range(max(0, x - dmin + 1), nd):
        c[j] = far


@njit(cache=True, fastmath=True, inline="always")
def _term_row(pl, prrev, y, x, base, c, nd, kcap, term):
    """The intensity term of left pixel x's candidates into c (see _cost_row), uint32 lanes:
    each channel's |difference| as max - min of the uint8 levels, summed, capped, scaled."""
    q0 = prrev[0, y, base:base + nd]
    q1 = prrev[min(1, pl.shape[0] - 1), y, base:base + nd]
    q2 = prrev[min(2, pl.shape[0] - 1), y, base:base + nd]
    l0 = pl[0, y, x]
    l1 = pl[min(1, pl.shape[0] - 1), y, x] if pl.shape[0] == 3 else np.uint8(0)
    l2 = pl[min(2, pl.shape[0] - 1), y, x] if pl.shape[0] == 3 else np.uint8(0)
    n3 = np.uint8(255) if pl.shape[0] == 3 else np.uint8(0)
    wa, wb, ws = np.uint32(term[2]), np.uint32(term[3]), np.uint32(term[4])
    for j in range(nd):
        k = min(np.uint32(max(l0, q0[j]) - min(l0, q0[j]))
                + np.uint32(max(l1, q1[j] & n3) - min(l1, q1[j] & n3))
                + np.uint32(max(l2, q2[j] & n3) - min(l2, q2[j] & n3)), np.uint32(kcap))
        c[j] = np.uint16((k * wa + wb) >> ws)


@njit(cache=True, fastmath=True, inline="always")
def _term_row3(pl, prrev, y, x, base, c, nd, kcap, ta, tb):
    """_term_row for three channels in uint16 lanes, where the term is (min(k, kcap) * ta +
    tb) >> 8 in 16 bits (NARROW_SHIFT; the defaults' form): a constant shift and one loop
    alone in its branch, which LLVM vectorises at 32 lanes (with the general loop beside it
    the row took twice as long)."""
    q0 = prrev[0, y, base:base + nd]
    q1 = prrev[1, y, base:base + nd]
    q2 = prrev[2, y, base:base + nd]
    l0 = pl[0, y, x]
    l1 = pl[1, y, x]
    l2 = pl[2, y, x]
    for j in range(nd):
        k = min(np.uint16(np.uint16(max(l0, q0[j]) - min(l0, q0[j]))
                          + np.uint16(max(l1, q1[j]) - min(l1, q1[j]))
                          + np.uint16(max(l2, q2[j]) - min(l2, q2[j]))), kcap)
        c[j] = np.uint16(np.uint16(k * ta) + tb) >> np.uint16(NARROW_SHIFT)


NARROW_SHIFT = 8  # the shift of the intensity term's 16-bit form (cost.integer_term)


@njit(cache=True)
def _census_rows(gl, gr, y, cs):
    """Census row y of the padded grey images into cs[0] (left) and cs[1] (right, reversed,
    the zeros after it left as they are: the layout of reversed_right's row); cs[2], cs[3]:
    scratch (a row, census_row's bytes)."""
    lrow, rrev, tmp, b = cs
    census_row(gl, y, lrow, b)
    census_row(gr, y, tmp, b)
    w = tmp.shape[0]
    for x in range(w):
        rrev[x] = tmp[w - 1 - x]


@njit(cache=True)
def _census_scratch(gl, dmin, nd):
    """The rows _census_rows fills (empty where no grey images are given: census images)."""
    w = gl.shape[1] - 2 * CENSUS_W if gl.shape[0] > 0 else 0
    return (np.empty(w, dtype=np.uint64), np.zeros(w + dmin + padded(nd) if w else 0,
                                                   dtype=np.uint64),
            np.empty(w, dtype=np.uint64), np.empty((8, w), dtype=np.uint8))


@njit(cache=True, inline="always")
def _size(cl, gl):
    """(rows, cols) of the images: the padded grey ones' less the padding, else the census's."""
    if gl.shape[0] > 0:
        return gl.shape[0] - 2 * CENSUS_H, gl.shape[1] - 2 * CENSUS_W
    return cl.shape[0], cl.shape[1]


@njit(cache=True, fastmath=True, inline="always")
def _step(src, m, dst, c, p1, p2, nd):
    """One step of a path: dst[1:nd + 1] = L from the previous L' = src[1:nd + 1] (both padded
    by PAD at each end; m = min L') and the cost c; returns min L.
    L[j] = C[j] + min(L'[j], L'[j-1] + P1, L'[j+1] + P1, min L' + P2) - min L'.

    In 16-lane vectors (lanes.py) when nd >= 16: ceil(nd / 16) steps, the last one overlapping
    the one before where nd is not a multiple of 16 (it writes the same values again, and the
    minimum does not change). Below 16 candidates, a plain loop.
    """
    if nd < L.LANES:
        return _step_plain(src, m, dst, c, p1, p2, nd)
    jump = L.splat(np.uint16(m + p2))
    mv = L.splat(m)
    p1v = L.splat(p1)
    lo = L.splat(np.uint16(0xFFFF))
    j = 0
    while j < nd:
        b = min(j, nd - L.LANES)
        v = _lanes_step(src, b, c, mv, p1v, jump)
        L.store(dst, b + 1, v)
        lo = L.vmin(lo, v)
        j += L.LANES
    return L.hmin(lo)


@njit(cache=True, fastmath=True, inline="always")
def _lanes_step(src, b, c, mv, p1v, jump):
    """Lanes b .. b + 16 of one path step (see _step) as a vector."""
    near = L.vadd(L.vmin(L.load(src, b), L.load(src, b + 2)), p1v)
    best = L.vmin(L.vmin(L.load(src, b + 1), near), jump)
    return L.vsub(L.vadd(L.load(c, b), best), mv)


@njit(cache=True, fastmath=True, inline="always")
def _step_plain(src, m, dst, c, p1, p2, nd):
    """_step in a plain loop (every intermediate cast back to uint16: 16-bit lanes)."""
    jump = np.uint16(m + p2)
    lo = np.uint16(0xFFFF)
    for j in range(nd):
        near = np.uint16(min(src[j], src[j + 2]) + p1)
        v = np.uint16(c[j] + min(src[j + 1], near, jump) - m)
        dst[j + 1] = v
        lo = min(lo, v)
    return lo


@njit(cache=True, inline="always")
def _pen(T, G, y, x, yy, xx):
    """P2 of the path step from pixel (yy, xx) to (y, x): T indexed by the left image's grey
    step between them (penalty_table; the same P2 everywhere when not adaptive). G is the grey
    image padded as census takes it (CENSUS_H rows, CENSUS_W columns: the layout of gl)."""
    a = np.int32(G[y + CENSUS_H, x + CENSUS_W])
    return T[abs(a - np.int32(G[yy + CENSUS_H, xx + CENSUS_W]))]


@njit(cache=True, fastmath=True, inline="always")
def _start(dst, c, nd):
    """A path's first pixel: L = C; returns min L."""
    if nd < L.LANES:
        lo = np.uint16(0xFFFF)
        for j in range(nd):
            dst[j + 1] = c[j]
            lo = min(lo, c[j])
        return lo
    lo = L.splat(np.uint16(0xFFFF))
    j = 0
    while j < nd:
        b = min(j, nd - L.LANES)
        v = L.load(c, b)
        L.store(dst, b + 1, v)
        lo = L.vmin(lo, v)
        j += L.LANES
    return L.hmin(lo)


@njit(cache=True, fastmath=True, inline="always")
def _sum_into(o, s, a1, a2, a3, a4, nd, with_min):
    """o[j] = s[j] + a1[j+1] + a2[j+1] + a3[j+1] + a4[j+1] (s may be o itself: the overlapping
    last vector keeps the lanes already summed); returns min o when with_min, else 0. A path
    left out is passed as a row of zeros (nd + 2)."""
    if nd < L.LANES:
        lo = np.uint16(0xFFFF)
        for j in range(nd):
            v = np.uint16(s[j] + a1[j + 1] + a2[j + 1] + a3[j + 1] + a4[j + 1])
            o[j] = v
            lo = min(lo, v)
        return lo if with_min else np.uint16(0)
    lo = L.splat(np.uint16(0xFFFF))
    j = 0
    while j < nd:
        b = min(j, nd - L.LANES)
        old = L.load(s, b)
        v = L.vadd(L.vadd(old, L.load(a1, b + 1)), L.vadd(L.load(a2, b + 1), L.vadd(
            L.load(a3, b + 1), L.load(a4, b + 1))))
        v = L.select_ge(j - b, v, L.load(o, b))
        L.store(o, b, v)
        lo = L.vmin(lo, v)
        j += L.LANES
    return L.hmin(lo) if with_min else np.uint16(0)


@njit(cache=True, fastmath=True, inline="always")
def _first_min(s, m, idx, n):
    """(smallest j with s[j] == m, the minimum of s[:n], found as the row was summed; m): a
    vectorised min reduction (idx = 0 .. len(s) in s's dtype, its last entry the largest)."""
    big = idx[idx.size - 1]
    best = big
    for j in range(n):
        best = min(best, idx[j] if s[j] == m else big)
    return np.int64(best), np.float32(m)


@njit(cache=True, inline="always")
def _scan_min(s, n):
    """(smallest j with s[j] the minimum of s[:n], that minimum): a plain loop."""
    best = 0
    m = s[0]
    for j in range(1, n):
        if s[j] < m:
            m = s[j]
            best = j
    return np.int64(best), m


@njit(cache=True, fastmath=True, inline="always")
def _close(s, c0, uniqueness, best, nd):
    """Whether a candidate other than best and its two neighbours costs at most c0 * (1 +
    uniqueness / 100) (the uniqueness test). The costs are whole numbers, so the bound is
    floored and the costs counted in uint16 lanes (no float compare per candidate); best
    itself always counts, so do its neighbours under the bound."""
    bound = c0 * (1.0 + uniqueness / 100.0)
    ib = np.uint16(min(np.floor(bound), 65535.0))
    n = np.uint16(0)
    for j in range(nd):
        n = np.uint16(n + np.uint16(s[j] <= ib))
    for j in range(max(best - 1, 0), min(best + 2, nd)):
        n = np.uint16(n - np.uint16(s[j] <= ib))
    return n > 0


@njit(cache=True, fastmath=True)
def _decide_row(tot, mins, y, dmin, uniqueness, fit, want_right, disp_l, disp_r, acc, acc16,
                sh, idx, jj, fb, rr, lr):
    """Left (and right) disparities of row y from its total path costs tot (cols, nd) and
    their minima per pixel, mins.

    The smallest candidate among equal costs wins. The right view's candidates are tot's
    diagonals (right pixel xr at candidate j is left pixel xr + dmin + j): each left pixel x
    lowers acc[cols - x + j] to its cost << 16 | j if that is smaller (the same candidate
    order, idx and jj = 0 .. nd in uint16 and uint32), so entry cols - dmin - xr ends as xr's
    best; when sh > 0 every total fits in 16 - sh bits and acc16 takes cost << sh | j instead
    (twice the vector lanes). The right view gets whole pixels (the LR check compares within a
    pixel; its sub-pixel fit cost time and changed Cones and Teddy by under 0.1 %) and no
    uniqueness test.
    The left winners and their neighbours' costs go into fb (4, cols) float32 first, so the
    sub-pixel fits run as one vector loop per row. The right row goes into rr (cols, NaN from
    cols - dmin on), then into disp_r[y] where disp_r has rows; with lr >= 0 the left row is
    checked against it there (postprocess.lr_row), so no right map need be kept.
    """
    w, nd = tot.shape
    for x in range(w):
        s = tot[x]
        best, c0 = _first_min(s, mins[x], idx, nd)
        fb[0, x] = best
        fb[2, x] = c0
        inner = 0 < best < nd - 1
        fb[1, x] = s[best - 1] if inner else c0  # no neighbours: a flat fit, offset 0
        fb[3, x] = s[best + 1] if inner else c0
        if uniqueness > 0.0 and _close(s, c0, uniqueness, best, nd):
            fb[0, x] = np.nan
    _fit_row(fb, disp_l[y], dmin, fit, w)
    if not want_right:
        return
    _right_row(tot, dmin, acc, acc16, sh, idx, jj, rr)
    if disp_r.shape[0] > 0:
        disp_r[y] = rr
    if lr >= 0.0:
        lr_row(disp_l[y], rr, lr)


@njit(cache=True, fastmath=True, inline="always")
def _right_row(tot, dmin, acc, acc16, sh, idx, jj, row):
    """The right view's whole-pixel disparities of a row (see _decide_row) into row[:cols -
    dmin]."""
    w, nd = tot.shape
    if sh > 0:
        acc16[:] = np.uint16(0xFFFF)
        for x in range(w):
            s = tot[x]
            a = acc16[w - x:w - x + nd]
            for j in range(nd):
                a[j] = min(a[j], np.uint16((s[j] << sh) | idx[j]))
        mask = np.uint16((1 << sh) - 1)
        for xr in range(w - dmin):
            row[xr] = dmin + (acc16[w - dmin - xr] & mask)
        return
    acc[:] = np.uint32(0xFFFFFFFF)
    for x in range(w):
        s = tot[x]
        a = acc[w - x:w - x + nd]
        for j in range(nd):
            a[j] = min(a[j], np.uint32((np.uint32(s[j]) << np.uint32(16)) | jj[j]))
    for xr in range(w - dmin):
        row[xr] = dmin + (acc[w - dmin - xr] & np.uint32(0xFFFF))


@njit(cache=True, fastmath=True, inline="always")
def _fit_row(fb, out, dmin, fit, n):
    """out[:n] = dmin + winner + sub-pixel offset from fb (winner, cost before, at, after)."""
    if fit == FIT_NONE:
        for x in range(n):
            out[x] = dmin + fb[0, x]
    else:
        for x in range(n):
            out[x] = dmin + fb[0, x] + fit_offset(fb[1, x], fb[2, x], fb[3, x], fit)


@njit(cache=True, fastmath=True)
def _sweep(cl, crrev, gl, gr, vol, pl, prrev, term, S, C, P, M, crow, tot, forward, i0, i1, p1,
           T, G, diagonals, finish, dmin, uniqueness, fit, want_right, disp_l, disp_r, acc, acc16,
           sh, keep, lr):
    """Rows i0 .. i1 - 1 (counted from the top when forward, else from the bottom) of one
    direction's paths: path 0 from behind in the row, 2 from the row before at the same x,
    and (diagonals) 1 and 3 from the row before at x - step and x + step.

    P (2 row parities, 4 path slots, cols, nd + 2) and M (2, 4, cols) carry the path costs from
    row to row, so one direction can stop at a row and go on from it in a later call. Without
    finish the row's path sum goes into S; with finish it is added to S's row (the other
    direction's sum) into tot and decided (and, with keep, stored back into S). C (rows, cols,
    nd) uint8, when not empty, takes each cost row made without finish, and a row with finish
    reads its cost from there (the other direction made it), so each row's cost is made once.
    """
    h, w = _size(cl, gl)
    nd = S.shape[2]
    cs = _census_scratch(gl, dmin, nd)
    step = 1 if forward else -1
    idx, jj, fb, mins, Z, _, rr = _row_scratch(w, nd)
    reuse = C.shape[0] > 0
    for i in range(i0, i1):
        y = i if forward else h - 1 - i
        if reuse and finish:
            for x in range(w):
                cx = C[y, x]
                r = crow[x]
                for j in range(nd):
                    r[j] = np.uint16(cx[j])
        else:
            _cost_row(cl, crrev, gl, gr, vol, pl, prrev, term, y, dmin, crow, cs)
            if reuse:
                for x in range(w):
                    cx = C[y, x]
                    r = crow[x]
                    for j in range(nd):
                        cx[j] = np.uint8(r[j])
        b = i % 2
        a = 1 - b
        for t in range(w):
            x = t if forward else w - 1 - t
            c = crow[x]
            h0 = P[b, 0, x]
            v2 = P[b, 2, x]
            if t == 0:
                M[b, 0, x] = _start(h0, c, nd)
            else:
                M[b, 0, x] = _step(P[b, 0, x - step], M[b, 0, x - step], h0, c, p1,
                                   _pen(T, G, y, x, y, x - step), nd)
            if i == 0:
                M[b, 2, x] = _start(v2, c, nd)
            else:
                M[b, 2, x] = _step(P[a, 2, x], M[a, 2, x], v2, c, p1, _pen(T, G, y, x, y - step, x),
                                   nd)
            if diagonals:
                d1 = P[b, 1, x]
                d3 = P[b, 3, x]
                if i == 0 or t == 0:
                    M[b, 1, x] = _start(d1, c, nd)
                else:
                    M[b, 1, x] = _step(P[a, 1, x - step], M[a, 1, x - step], d1, c, p1,
                                       _pen(T, G, y, x, y - step, x - step), nd)
                if i == 0 or t == w - 1:
                    M[b, 3, x] = _start(d3, c, nd)
                else:
                    M[b, 3, x] = _step(P[a, 3, x + step], M[a, 3, x + step], d3, c, p1,
                                       _pen(T, G, y, x, y - step, x + step), nd)
                if finish:
                    mins[x] = _sum_into(tot[x], S[y, x], h0, d1, v2, d3, nd, True)
                else:
                    _sum_into(S[y, x], Z, h0, d1, v2, d3, nd, False)
            elif finish:
                mins[x] = _sum_into(tot[x], S[y, x], h0, v2, Z, Z, nd, True)
            else:
                _sum_into(S[y, x], Z, h0, v2, Z, Z, nd, False)
        if finish:
            _decide_row(tot, mins, y, dmin, uniqueness, fit, want_right, disp_l, disp_r, acc,
                        acc16, sh, idx, jj, fb, rr, lr)
            if keep:
                S[y] = tot


@njit(cache=True, inline="always")
def _row_scratch(w, nd):
    """What a pass that decides rows one at a time keeps beside them: the decision's candidate
    indices (uint16, uint32) and sub-pixel rows, a row of minima, a zero row and the path
    along the row's two pixel parities H (nd + 2, PAD at both ends) and the right view's row
    rr (_decide_row)."""
    idx = np.arange(nd + 1).astype(np.uint16)
    jj = np.arange(nd + 1).astype(np.uint32)
    fb = np.empty((4, w), dtype=np.float32)
    mins = np.empty(w, dtype=np.uint16)
    Z = np.zeros(nd + 2, dtype=np.uint16)
    H = np.empty((2, nd + 2), dtype=np.uint16)
    H[:, 0] = PAD
    H[:, nd + 1] = PAD
    rr = np.full(w, np.nan, dtype=np.float32)
    return idx, jj, fb, mins, Z, H, rr


@njit(cache=True, fastmath=True, inline="always")
def _from_the_right(crow, H, tot, mins, Z, p1, T, G, y, nd):
    """The path from the right, swept back along the row (its previous pixel in H): added to
    the row's totals, each pixel's minimum total into mins."""
    w = crow.shape[0]
    m4 = np.uint16(0)
    for t in range(w):
        x = w - 1 - t
        c = crow[x]
        h4 = H[t % 2]
        m4 = _start(h4, c, nd) if t == 0 else _step(H[1 - t % 2], m4, h4, c, p1,
                                                     _pen(T, G, y, x, y, x + 1), nd)
        mins[x] = _sum_into(tot[x], tot[x], h4, Z, Z, Z, nd, True)


@njit(cache=True, fastmath=True, inline="always")
def _from_the_right_decided(crow, H, tot, fb, acc16, sh, sat, idx, p1, T, G, y, nd,
                            uniqueness):
    """_from_the_right with the decision's passes over each pixel's totals in the same sweep,
    where every total fits with the candidate's bits below it (sh > 0), nd >= 16 and the right
    view is wanted: each total vector, as it is summed, is packed as total << sh | j, whose
    smallest lane is the winner (the smallest candidate among equal totals, as _first_min) and
    the right view's entry (as _right_row's acc16); the uniqueness test (as _close) then runs
    in lanes over the pixel's totals while they are in the cache. fb gets what _decide_row
    puts there; acc16 the right view's packed minima (_finish_row reads them). The separate
    passes (winner, uniqueness, right view) took 3.7, 3.6 and 3.1 ms of a 640x480 image at
    16 to 64 candidates, whatever the count (issue 24).

    Where a total may not fit beside the candidate (65 to 128 candidates at the defaults: a
    total needs 10 bits, 128 candidates 7), each total is packed saturated at top = 0xFFFF >>
    sh: a packed minimum under top is the exact one; a pixel whose every total reaches top
    (its minimum reads top) takes its winner from a plain scan of its totals instead, and so
    does a right pixel in _finish_row. So the maps are those of the separate passes. sat:
    whether a total can saturate (else the packing and checks are left out: at 64 candidates
    they cost 3-4 % of the call)."""
    w = crow.shape[0]
    m4 = np.uint16(0)
    shv = L.splat(np.uint16(sh))
    mask = np.uint16((1 << sh) - 1)
    top = np.uint16(0xFFFF >> sh)
    topv = L.splat(top)
    big = L.splat(np.uint16(0xFFFF))
    two = L.splat(np.uint16(2))
    acc16[:] = np.uint16(0xFFFF)
    for t in range(w):
        x = w - 1 - t
        c = crow[x]
        h4 = H[t % 2]
        m4 = _start(h4, c, nd) if t == 0 else _step(H[1 - t % 2], m4, h4, c, p1,
                                                     _pen(T, G, y, x, y, x + 1), nd)
        o = tot[x]
        lo = big
        j = 0
        while j < nd:
            b = min(j, nd - L.LANES)
            old = L.load(o, b)
            # the overlapping last vector keeps the lanes already summed (as _sum_into)
            v = L.select_ge(j - b, L.vadd(old, L.load(h4, b + 1)), old)
            L.store(o, b, v)
            if sat:
                v = L.vmin(v, topv)
            pk = _vor(_vshl(v, shv), L.load(idx, b))
            lo = L.vmin(lo, pk)
            a = w - x + b
            L.store(acc16, a, L.vmin(L.load(acc16, a), pk))
            j += L.LANES
        packed = L.hmin(lo)
        best = np.int64(packed & mask)
        c0 = np.float32(packed >> np.uint16(sh))
        if sat and packed >> np.uint16(sh) == top:  # all saturated: the plain first minimum
            best, m = _scan_min(o, nd)
            c0 = np.float32(m)
        fb[0, x] = best
        fb[2, x] = c0
        inner = 0 < best < nd - 1
        fb[1, x] = o[best - 1] if inner else c0  # no neighbours: a flat fit, offset 0
        fb[3, x] = o[best + 1] if inner else c0
        if uniqueness > 0.0:
            bound = c0 * (1.0 + uniqueness / 100.0)
            ib = np.uint16(min(np.floor(bound), 65535.0))
            # lanes best - 1 .. best + 1 left out: idx - (best - 1) <= 2, wrapping
            near = L.splat(np.uint16((best + 0xFFFF) & 0xFFFF))
            lo = big
            j = 0
            while j < nd:
                b = min(j, nd - L.LANES)
                lo = L.vmin(lo, _select_ule(L.vsub(L.load(idx, b), near), two, big,
                                            L.load(o, b)))
                j += L.LANES
            if L.hmin(lo) <= ib:
                fb[0, x] = np.nan


@njit(cache=True, fastmath=True, inline="always")
def _finish_row(fb, tot, y, dmin, fit, disp_l, disp_r, acc16, sh, sat, rr, lr):
    """The rest of _decide_row after _from_the_right_decided: the left row from fb, the right
    row from acc16's packed minima (a saturated one, at top: from a plain scan of its diagonal
    in tot), the LR check."""
    w = fb.shape[1]
    nd = tot.shape[1]
    _fit_row(fb, disp_l[y], dmin, fit, w)
    mask = np.uint16((1 << sh) - 1)
    top = np.uint16(0xFFFF >> sh)
    if not sat:
        for xr in range(w - dmin):
            rr[xr] = dmin + (acc16[w - dmin - xr] & mask)
    for xr in range(w - dmin if sat else 0):
        e = acc16[w - dmin - xr]
        if e >> np.uint16(sh) == top:
            x0 = xr + dmin
            bj = 0
            m = tot[x0, 0]
            for j in range(1, min(nd, w - x0)):
                if tot[x0 + j, j] < m:
                    m = tot[x0 + j, j]
                    bj = j
            rr[xr] = dmin + bj
        else:
            rr[xr] = dmin + (e & mask)
    if disp_r.shape[0] > 0:
        disp_r[y] = rr
    if lr >= 0.0:
        lr_row(disp_l[y], rr, lr)


@njit(cache=True, inline="always")
def _fused(sh, nd, want_right):
    """The candidate's bits in _from_the_right_decided's packing, or 0 where the passes take the
    separate decision (_decide_row): below 16 candidates, without the right view, and above
    FUSED_MAX candidates unless every total fits beside the candidate (sh > 0)."""
    bits = 0
    while (1 << bits) < nd:
        bits += 1
    if nd < L.LANES or not want_right or not (sh > 0 or nd <= FUSED_MAX):
        return 0
    return bits


FUSED_MAX = 128  # saturated totals keep 9 bits at 128 candidates (top 511)


OVERLAP = 24  # rows the lower stripe of the 5-path pass starts above its first row


@njit(cache=True, fastmath=True)
def _down(cl, crrev, gl, gr, vol, pl, prrev, term, S, P, M, crow, tot, y0, y1, warm, p1, T, G, dmin,
          uniqueness, fit, want_right, disp_l, disp_r, acc, acc16, sh, keep, lr):
    """The 5-path pass over rows y0 .. y1 - 1, top to bottom: paths 1-3 from the top-left,
    top and top-right and 0 from the left in one sweep along the row (x rising), which leaves
    their sum in tot; then 4 from the right in a sweep back, which adds it and takes each
    pixel's minimum; then the row is decided (with keep, stored in S). The three paths from
    above start warm rows above y0 (those rows are not decided).

    Only the paths from above keep whole rows (P[., 1 .. 3]); the two along the row keep just
    the previous pixel, in H (2 pixel parities, nd + 2), so no row of them is written and read
    back. Each sweep steps a chain along the row (each step waits for the one before) beside
    independent work (the three paths from above; the sums), which the processor overlaps.
    """
    h, w = _size(cl, gl)
    nd = crow.shape[1]
    cs = _census_scratch(gl, dmin, nd)
    idx, jj, fb, mins, Z, H, rr = _row_scratch(w, nd)
    fsh = _fused(sh, nd, want_right)
    for i in range(y1 - y0 + warm):
        y = y0 - warm + i
        decided = i >= warm
        _cost_row(cl, crrev, gl, gr, vol, pl, prrev, term, y, dmin, crow, cs)
        b = i % 2
        a = 1 - b
        m0 = np.uint16(0)
        for x in range(w):
            c = crow[x]
            d1 = P[b, 1, x]
            v2 = P[b, 2, x]
            d3 = P[b, 3, x]
            if i == 0 or x == 0:
                M[b, 1, x] = _start(d1, c, nd)
            else:
                M[b, 1, x] = _step(P[a, 1, x - 1], M[a, 1, x - 1], d1, c, p1,
                                   _pen(T, G, y, x, y - 1, x - 1), nd)
            if i == 0:
                M[b, 2, x] = _start(v2, c, nd)
            else:
                M[b, 2, x] = _step(P[a, 2, x], M[a, 2, x], v2, c, p1, _pen(T, G, y, x, y - 1, x),
                                   nd)
            if i == 0 or x == w - 1:
                M[b, 3, x] = _start(d3, c, nd)
            else:
                M[b, 3, x] = _step(P[a, 3, x + 1], M[a, 3, x + 1], d3, c, p1,
                                   _pen(T, G, y, x, y - 1, x + 1), nd)
            if not decided:
                continue
            h0 = H[x % 2]
            m0 = _start(h0, c, nd) if x == 0 else _step(H[1 - x % 2], m0, h0, c, p1,
                                                         _pen(T, G, y, x, y, x - 1), nd)
            _sum_into(tot[x], Z, h0, d1, v2, d3, nd, False)
        if not decided:
            continue
        if fsh:
            _from_the_right_decided(crow, H, tot, fb, acc16, fsh, sh == 0, idx, p1, T, G, y,
                                    nd, uniqueness)
            _finish_row(fb, tot, y, dmin, fit, disp_l, disp_r, acc16, fsh, sh == 0, rr, lr)
        else:
            _from_the_right(crow, H, tot, mins, Z, p1, T, G, y, nd)
            _decide_row(tot, mins, y, dmin, uniqueness, fit, want_right, disp_l, disp_r, acc,
                        acc16, sh, idx, jj, fb, rr, lr)
        if keep:
            S[y] = tot


@njit(cache=True, fastmath=True)
def _vertical(cl, crrev, gl, gr, vol, pl, prrev, term, forward, rows, K, ck, ckm, p1, T, G, dmin):
    """The path from the bottom (not forward: rows h - 1 up to h - rows) or from the top
    (forward: rows 0 .. rows - 1) alone, keeping two rows of it. Going up, the path's row y is
    stored in ck[y // K - 1] (ckm: its minima) at every y that is a multiple of K above 0
    (the row below each block of the 4-path pass but the last); going down, its last row in
    ck[0]. ck is uint8 where every path cost fits (_four_path_layout), else uint16."""
    h, w = _size(cl, gl)
    nd = ck.shape[2]
    cs = _census_scratch(gl, dmin, nd)
    P = np.empty((2, w, nd + 2), dtype=np.uint16)
    P[:, :, 0] = PAD
    P[:, :, nd + 1] = PAD
    M = np.empty((2, w), dtype=np.uint16)
    crow = np.empty((w, padded(nd)), dtype=np.uint16)
    for i in range(rows):
        y = i if forward else h - 1 - i
        _cost_row(cl, crrev, gl, gr, vol, pl, prrev, term, y, dmin, crow, cs)
        b = i % 2
        for x in range(w):
            if i == 0:
                M[b, x] = _start(P[b, x], crow[x], nd)
            else:
                M[b, x] = _step(P[1 - b, x], M[1 - b, x], P[b, x], crow[x], p1,
                                 _pen(T, G, y, x, y - 1 if forward else y + 1, x), nd)
        if forward:
            store = i == rows - 1
            k = 0
        else:
            store = y > 0 and y % K == 0
            k = y // K - 1
        if store:
            for x in range(w):
                ckm[k, x] = M[b, x]
                src = P[b, x]
                dst = ck[k, x]
                for j in range(nd):
                    dst[j] = src[j + 1]


@njit(cache=True, fastmath=True)
def _four(cl, crrev, gl, gr, vol, pl, prrev, term, S, y0, y1, K, ck, ckm, top, topm, BB, CB, p1,
          T, G, dmin, uniqueness, fit, want_right, disp_l, disp_r, sh, keep, lr):
    """The 4-path pass (left, right, top, bottom) over rows y0 .. y1 - 1 in blocks of K rows,
    without a volume: for each block, the path from the bottom is taken up through it again
    from the stored row below it (ck, ckm: _vertical; at the image's last row it starts),
    keeping its K rows (BB) and, where every cost fits in a byte, the block's cost rows (CB);
    then the rows go down: the path from the top (two rows, carried from block to block; at
    y0 > 0 it starts from top, topm: the path's row y0 - 1), the paths along the row as in
    _down, the sum with the stored bottom row, the decision. Every path cost is the one a
    whole-image pass gives, so the maps do not depend on K or on where a stripe starts.
    """
    h, w = _size(cl, gl)
    nd = ck.shape[2]
    cs = _census_scratch(gl, dmin, nd)
    idx, jj, fb, mins, Z, H, rr = _row_scratch(w, nd)
    fsh = _fused(sh, nd, want_right)
    P = np.empty((2, w, nd + 2), dtype=np.uint16)
    P[:, :, 0] = PAD
    P[:, :, nd + 1] = PAD
    M = np.empty((2, w), dtype=np.uint16)
    MB = np.empty((2, w), dtype=np.uint16)
    below = np.empty(nd + 2, dtype=np.uint16)
    below[0] = PAD
    below[nd + 1] = PAD
    crow = np.empty((w, padded(nd)), dtype=np.uint16)
    tot = np.empty((w, nd), dtype=np.uint16)
    acc = np.empty(w + nd, dtype=np.uint32)
    acc16 = np.empty(w + nd, dtype=np.uint16)
    BB[:, :, 0] = PAD
    BB[:, :, nd + 1] = PAD
    kept = CB.shape[0] > 0
    if y0 > 0:
        b = (y0 - 1) % 2
        for x in range(w):
            M[b, x] = topm[x]
            src = top[x]
            dst = P[b, x]
            for j in range(nd):
                dst[j + 1] = src[j]
    for b0 in range(y0, y1, K):
        b1 = min(b0 + K, y1)
        for y in range(b1 - 1, b0 - 1, -1):
            r = y - b0
            _cost_row(cl, crrev, gl, gr, vol, pl, prrev, term, y, dmin, crow, cs)
            if kept:
                for x in range(w):
                    cx = CB[r, x]
                    c = crow[x]
                    for j in range(nd):
                        cx[j] = np.uint8(c[j])
            b = y % 2
            for x in range(w):
                c = crow[x]
                dst = BB[r, x]
                if y == h - 1:
                    MB[b, x] = _start(dst, c, nd)
                elif y == b1 - 1:
                    src = ck[b1 // K - 1, x]
                    for j in range(nd):
                        below[j + 1] = src[j]
                    MB[b, x] = _step(below, ckm[b1 // K - 1, x], dst, c, p1,
                                      _pen(T, G, y, x, y + 1, x), nd)
                else:
                    MB[b, x] = _step(BB[r + 1, x], MB[1 - b, x], dst, c, p1,
                                      _pen(T, G, y, x, y + 1, x), nd)
        for y in range(b0, b1):
            r = y - b0
            if kept:
                for x in range(w):
                    cx = CB[r, x]
                    c = crow[x]
                    for j in range(nd):
                        c[j] = np.uint16(cx[j])
            else:
                _cost_row(cl, crrev, gl, gr, vol, pl, prrev, term, y, dmin, crow, cs)
            b = y % 2
            a = 1 - b
            m0 = np.uint16(0)
            for x in range(w):
                c = crow[x]
                v = P[b, x]
                if y == 0:
                    M[b, x] = _start(v, c, nd)
                else:
                    M[b, x] = _step(P[a, x], M[a, x], v, c, p1, _pen(T, G, y, x, y - 1, x), nd)
                h0 = H[x % 2]
                m0 = _start(h0, c, nd) if x == 0 else _step(H[1 - x % 2], m0, h0, c, p1,
                                                            _pen(T, G, y, x, y, x - 1), nd)
                _sum_into(tot[x], Z, h0, v, BB[r, x], Z, nd, False)
            if fsh:
                _from_the_right_decided(crow, H, tot, fb, acc16, fsh, sh == 0, idx, p1, T,
                                        G, y, nd, uniqueness)
                _finish_row(fb, tot, y, dmin, fit, disp_l, disp_r, acc16, fsh, sh == 0, rr, lr)
            else:
                _from_the_right(crow, H, tot, mins, Z, p1, T, G, y, nd)
                _decide_row(tot, mins, y, dmin, uniqueness, fit, want_right, disp_l, disp_r,
                            acc, acc16, sh, idx, jj, fb, rr, lr)
            if keep:
                S[y] = tot


@njit(cache=True)
def _buffers(n, w, nd):
    """n sets of the state one direction or stripe carries: rows of path costs P (2 row
    parities, 4 path slots, cols, nd + 2, PAD at both ends) and their minima M, a cost row, a
    row of totals, and the right view's minima (uint32 and uint16 packings)."""
    P = np.empty((n, 2, 4, w, nd + 2), dtype=np.uint16)
    P[:, :, :, :, 0] = PAD
    P[:, :, :, :, nd + 1] = PAD
    M = np.zeros((n, 2, 4, w), dtype=np.uint16)
    crow = np.empty((n, w, nd), dtype=np.uint16)
    tot = np.empty((n, w, nd), dtype=np.uint16)
    acc = np.empty((n, w + nd), dtype=np.uint32)
    acc16 = np.empty((n, w + nd), dtype=np.uint16)
    return P, M, crow, tot, acc, acc16


@njit(cache=True, parallel=True)
def _match(cl, crrev, gl, gr, vol, pl, prrev, term, S, C, dmin, p1, T, G, paths, uniqueness, fit,
           want_right, keep, K, ck, ckm, top, topm, BB, CB, lr):
    """Semi-global matching of census images cl and crrev, or (gl has rows) of the census
    rows made from the padded grey images gl, gr where a pass needs them (see _cost_row):
    disparity maps of the left and (want_right) right view in px, NaN where the uniqueness
    test rejects. With lr >= 0 (and want_right) the left map is LR-checked row by row at
    tolerance lr and the right map is not kept (an empty (0, cols) one is returned).

    vol: box-summed cost (rows, cols, nd), or an empty volume to take the cost row by row from
    the census rows and the planes pl, prrev (_cost_row; term[5]: the largest cost).
    S (rows, cols, nd) uint16 holds one direction's path sums: the forward
    direction (paths from the left and, with 8 paths, top-left, top, top-right; with 4, top)
    sweeps the upper half while the backward one sweeps the lower half from the bottom, each
    storing its sums; then each goes on into the other's half, adds its own paths to the
    stored sums and decides the row. So each half of S is written once and read once, every
    cost row is made where it is used, and with two threads the two directions run at once.
    With 5 paths (left, right, top-left, top, top-right) one pass from the top decides each
    row as it goes and S is not used: the image is cut into an upper and a lower stripe (one
    per thread), and the lower stripe's paths from above start OVERLAP rows above it, the same
    whatever the thread count, so results do not depend on it.
    keep: leave the total path costs in S (rows, cols, nd; for tests).
    T, G: P2 of each path step, T[|G[p] - G[p - r]|] (penalty_table; G the left image's grey
    levels padded as gl is, see _pen); every kernel below takes them in place of one P2.
    """
    h, w = _size(cl, gl)
    nd = S.shape[2]
    # a path cost is at most the largest cost + P2, so every total is under paths times that:
    # if it fits with the candidate's bits below it, the right view's minimum runs in uint16
    bits = 0
    while (1 << bits) < nd:
        bits += 1
    cmax = int(term[5]) if vol.shape[0] == 0 else int(vol.max())
    sh = bits if bits > 0 and (paths * (cmax + int(T.max())) + 1) << bits <= 0xFFFF else 0
    disp_l = np.full((h, w), np.nan, dtype=np.float32)
    disp_r = np.full((h if lr < 0.0 else 0, w), np.nan, dtype=np.float32)
    upper = (h + 1) // 2
    if paths == 5:
        for k in prange(2):
            # each stripe's rows of path costs are its own: on one thread the second stripe
            # reuses the first one's memory, so the peak holds one set
            P, M, crow, tot, acc, acc16 = _buffers(1, w, nd)
            y0, y1 = (0, upper) if k == 0 else (upper, h)
            _down(cl, crrev, gl, gr, vol, pl, prrev, term, S, P[0], M[0], crow[0], tot[0], y0, y1,
                  0 if k == 0 else min(OVERLAP, upper), p1, T, G, dmin, uniqueness, fit,
                  want_right, disp_l, disp_r, acc[0], acc16[0], sh, keep, lr)
        return disp_l, disp_r
    if paths == 4:
        # the path from the bottom alone first, storing its row below every block; with two
        # stripes (BB holds two blocks) the path from the top meanwhile goes down to the
        # lower stripe's first row
        stripes = BB.shape[0]
        nblocks = (h + K - 1) // K
        mid = (nblocks + 1) // 2 * K if stripes == 2 else h
        for k in prange(2):
            if k == 0:
                _vertical(cl, crrev, gl, gr, vol, pl, prrev, term, False, max(h - K, 0), K, ck, ckm,
                          p1, T, G, dmin)
            elif stripes == 2:
                _vertical(cl, crrev, gl, gr, vol, pl, prrev, term, True, mid, K, top, topm, p1,
                          T, G, dmin)
        for k in prange(2):
            if k < stripes:
                y0, y1 = (0, mid) if k == 0 else (mid, h)
                _four(cl, crrev, gl, gr, vol, pl, prrev, term, S, y0, y1, K, ck, ckm, top[0],
                      topm[0], BB[k], CB[k], p1, T, G, dmin, uniqueness, fit, want_right, disp_l,
                      disp_r, sh, keep, lr)
        return disp_l, disp_r
    P, M, crow, tot, acc, acc16 = _buffers(2, w, nd)  # the directions go on from row to row
    diagonals = paths == 8
    for phase in range(2):
        for k in prange(2):
            forward = k == 0
            if phase == 0:
                i0, i1 = 0, upper if forward else h - upper
            else:
                i0, i1 = upper if forward else h - upper, h
            _sweep(cl, crrev, gl, gr, vol, pl, prrev, term, S, C, P[k], M[k], crow[k], tot[k],
                   forward, i0, i1, p1, T, G, diagonals, phase == 1, dmin, uniqueness, fit,
                   want_right, disp_l, disp_r, acc[k], acc16[k], sh, keep, lr)
    return disp_l, disp_r


NO_PLANES = np.zeros((0, 1, 1), dtype=np.uint8)
NO_VOLUME = np.empty((0, 0, 0), dtype=np.uint16)
NO_COSTS = np.empty((0, 0, 0), dtype=np.uint8)
NO_GREY = np.empty((0, 0), dtype=np.uint8)
NO_CENSUS = np.empty((0, 0), dtype=np.uint64)


def census_term(outside: int = CENSUS_BITS) -> np.ndarray:
    """The term array of _cost_row for census alone: outside beyond the image, no intensity."""
    return np.array([outside, 0, 0, 0, 0, max(CENSUS_BITS, outside)], dtype=np.int64)


def match(cl: np.ndarray, crrev: np.ndarray, vol: np.ndarray, S: np.ndarray, dmin: int,
          p1: np.uint16, p2: np.uint16, paths: int, uniqueness: float, fit: int,
          want_right: bool, keep: bool, pl: np.ndarray = NO_PLANES,
          prrev: np.ndarray = NO_PLANES, term: np.ndarray | None = None,
          costs: np.ndarray = NO_COSTS, four: FourPath | None = None,
          gl: np.ndarray = NO_GREY, gr: np.ndarray = NO_GREY, lr: float = -1.0,
          p2_adapt: float = 0.0, grey: np.ndarray = NO_GREY) -> tuple[np.ndarray, np.ndarray]:
    """_match with the cost from vol, or (vol empty) from the census rows plus, where pl has
    channels, the intensity term of the planes pl and prrev (cost.reversed_planes) as
    term says (cost.integer_term; default: census alone, CENSUS_BITS outside the image).
    costs: with 8 paths and every cost under 256, a (rows, cols, nd) uint8 buffer in which
    each cost row is kept for the second direction (see _sweep), else NO_COSTS.
    four: the 4-path buffers (FourPath; made here for one stripe when not given).
    S: (rows, cols, nd) with 8 paths or keep (the totals are left in it), else (0, 0, nd).
    gl, gr: the grey images padded as census takes them, the census rows then made where they
    are used (cl, crrev: NO_CENSUS); lr: the LR check's tolerance, done row by row (no right
    map is kept: the second map returned has no rows), or negative: no check, the right map
    returned. p2_adapt > 0: each path step's P2 falls with the left image's grey step along it
    (penalty_table; grey: the left image's grey levels padded as gl, which is taken when grey
    is not given), else P2 is p2."""
    term = census_term() if term is None else term
    h, w = (gl.shape[0] - 2 * CENSUS_H, gl.shape[1] - 2 * CENSUS_W) if gl.shape[0] else cl.shape
    nd = S.shape[2]
    T = penalty_table(int(p1), int(p2), p2_adapt)
    G = grey if grey.shape[0] else gl
    if not G.shape[0]:  # T is one value then: any grey levels do
        G = np.zeros((h + 2 * CENSUS_H, w + 2 * CENSUS_W), dtype=np.uint8)
    if G.shape != (h + 2 * CENSUS_H, w + 2 * CENSUS_W):
        raise ValueError(f"grey is {G.shape}, the images {(h, w)} padded by the census")
    if four is None:
        four = FourPath.make(h, w, nd, largest_cost(vol, term), int(p2), vol.shape[0] == 0,
                             1 if paths == 4 else 0)
    disp_l: np.ndarray
    disp_r: np.ndarray
    disp_l, disp_r = _match(cl, crrev, gl, gr, vol, pl, prrev, term, S, costs, dmin, p1, T, G,
                            paths, uniqueness, fit, want_right, keep, four.K, four.ck, four.ckm,
                            four.top, four.topm, four.BB, four.CB, float(lr))
    return disp_l, disp_r


def penalty_table(p1: int, p2: int, adapt: float) -> np.ndarray:
    """P2 of a path step by the left image's grey step k = 0 .. 255 along it (uint16): p2
    everywhere when adapt <= 0, else p2 / (1 + k / adapt) rounded, at least P1 + 1 (at most
    p2): a smaller jump penalty where the image has an edge, where depth edges lie, and a
    larger one on flat surfaces (Hirschmueller 2008 takes P2 / |step|)."""
    k = np.arange(256, dtype=np.float64)
    if adapt <= 0:
        return np.full(256, p2, dtype=np.uint16)
    t = np.floor(p2 / (1.0 + k / adapt) + 0.5)
    return np.clip(t, min(p1 + 1, p2), p2).astype(np.uint16)


def largest_cost(vol: np.ndarray, term: np.ndarray) -> int:
    """The largest cost a row can hold: the volume's largest, or term's (_cost_row)."""
    return int(vol.max()) if vol.shape[0] else int(term[5])


class FourPath(NamedTuple):
    """The 4-path pass's memory (_match, _vertical, _four): the bottom path's row below each
    block of K rows (ck, its minima ckm), the top path's row above the lower stripe (top,
    topm; two stripes only), and per stripe one block's bottom path rows (BB) and cost rows
    (CB, uint8; empty where a cost can reach 256 or a volume holds the costs). top is one row
    with one stripe too (not used: a row of memory against an empty view's index)."""
    K: int
    ck: np.ndarray
    ckm: np.ndarray
    top: np.ndarray
    topm: np.ndarray
    BB: np.ndarray
    CB: np.ndarray

    @staticmethod
    def make(h: int, w: int, nd: int, cmax: int, p2: int, rows_made: bool,
             stripes: int, K: int | None = None) -> FourPath:
        """Buffers for rows x cols x nd with costs up to cmax and penalty p2 (no path cost
        exceeds cmax + p2: a step adds a cost to at most the previous minimum + P2, less that
        minimum); stripes 0 gives empty ones (5 or 8 paths). K: the block's rows (default:
        the least memory, block_rows)."""
        small = cmax + p2 <= 0xFF
        keep_costs = rows_made and cmax <= 0xFF
        K = K or block_rows(h, 1 if small else 2, 1 if keep_costs else 0)
        nck = (h + K - 1) // K - 1 if stripes else 0
        cdt = np.uint8 if small or not stripes else np.uint16
        n = stripes
        return FourPath(K, np.empty((nck, w, nd), cdt), np.empty((nck, w), np.uint16),
                        np.empty((1 if n else 0, w, nd), cdt), np.empty((1 if n else 0, w),
                                                                         np.uint16),
                        np.empty((n, K if n else 0, w, nd + 2), np.uint16),
                        np.empty((n, K if n and keep_costs else 0, w, nd), np.uint8))


def block_rows(h: int, ck_bytes: int, cost_bytes: int) -> int:
    """Rows K of a 4-path block with the least memory: ceil(h / K) - 1 stored rows of ck_bytes
    a cost and K of 2 + cost_bytes (bottom path, kept cost)."""
    return min(range(1, h + 1),
               key=lambda k: ((h + k - 1) // k - 1) * ck_bytes + k * (2 + cost_bytes))


def reversed_right(cr: np.ndarray, dmin: int, nd: int) -> np.ndarray:
    """The right census with each row reversed and dmin + padded(nd) zeros after it (see
    _cost_row)."""
    h, w = cr.shape
    out = np.zeros((h, w + dmin + padded(nd)), dtype=np.uint64)
    out[:, :w] = cr[:, ::-1]
    return out
