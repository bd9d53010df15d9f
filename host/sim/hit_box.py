"""Which pixels of a remapped view a changed box of its source reaches: the tight box round the
pixels whose source point lies strictly inside given limits, in one compiled pass (the lens of
the renderer and the trials' rectifier share it)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def hit_of(row_lo: np.ndarray, row_hi: np.ndarray, col_lo: np.ndarray, col_hi: np.ndarray,
           mx: np.ndarray, my: np.ndarray, lo_x: float, hi_x: float, lo_y: float, hi_y: float
           ) -> tuple[int, int, int, int]:
    """The rows y0:y1 and columns x0:x1 round the pixels whose source (mx, my) lies strictly
    inside (lo_x, hi_x) x (lo_y, hi_y); y0 = -1: none. Such a pixel is in a row whose source
    rows (row_lo..row_hi) reach into (lo_y, hi_y) and a column whose source columns (col_lo..
    col_hi) reach into (lo_x, hi_x): it is looked for in those rows and columns alone."""
    ra, rb, ca, cb = -1, -1, -1, -1
    for y in range(row_lo.size):
        if row_hi[y] > lo_y and row_lo[y] < hi_y:
            ra = y if ra < 0 else ra
            rb = y + 1
    for x in range(col_lo.size):
        if col_hi[x] > lo_x and col_lo[x] < hi_x:
            ca = x if ca < 0 else ca
            cb = x + 1
    y0, y1, x0, x1 = -1, -1, col_lo.size, -1
    if ra < 0 or ca < 0:
        return y0, y1, x0, x1
    # each row's first pixel inside from the left and its last from the right: the pixels
    # between need no look (the box takes only its rows' extremes), so a row costs its
    # pixels outside the box, not all of them
    for y in range(ra, rb):
        first = -1
        for x in range(ca, cb):
            sx, sy = mx[y, x], my[y, x]
            if sx > lo_x and sx < hi_x and sy > lo_y and sy < hi_y:
                first = x
                break
        if first < 0:
            continue
        last = first
        for x in range(cb - 1, first, -1):
            sx, sy = mx[y, x], my[y, x]
            if sx > lo_x and sx < hi_x and sy > lo_y and sy < hi_y:
                last = x
                break
        y0 = y if y0 < 0 else y0
        y1 = y + 1
        x0, x1 = min(x0, first), max(x1, last + 1)
    return y0, y1, x0, x1
