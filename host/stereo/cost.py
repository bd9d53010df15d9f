"""SGM matching cost volumes: census Hamming mixed with truncated absolute intensity difference.

The volume is (rows, cols, nd) uint16 with the disparity axis innermost, the layout sgm.match
takes as its box-summed cost. Candidate j of left pixel x is disparity dmin + j, right pixel
x - dmin - j.

- Census (sgm.census bits, Hamming distance) compares each pixel only with its neighbours, so a
  gain or gamma between the cameras changes nothing; it is weak on flat, untextured surfaces,
  where every neighbour is about as bright as the centre and noise decides the bits.
- The intensity term, weight * min(|I_left(x) - I_right(x - d)|, cap) (I: the mean over the
  B, G, R channels where the images have colour, else grey), tells apart candidates there
  (AD-census, Mei et al. 2011). It would lose census's indifference to a gain or gamma
  between the cameras, so the caller first maps each channel of the right image through
  match_histogram onto the left one's levels (a global monotonic change is undone).
- A candidate whose right pixel lies outside the image (the strip x < d of the left view, which
  the right camera does not see) costs `outside`: near a good match's cost rather than the
  census maximum, so the paths carry the disparity of the visible side into the strip instead
  of preferring any candidate the right view happens to have; the LR check then rejects what
  lands outside the right image and the fill extends the visible side.
"""

from __future__ import annotations

import cv2
import numpy as np
from numba import njit, prange

from host.stereo.sgm import CENSUS_BITS, NARROW_SHIFT, _popcount, padded


@njit(cache=True, parallel=True)
def census_ad_volume(cl, cr, pl, pr, dmin, weight, cap, outside, out):
    """Fill out (rows, cols, nd) uint16 with round(Hamming(cl[x], cr[x - d]) + weight *
    min(mean over channels of |pl[x] - pr[x - d]|, cap)) for d = dmin + j, and outside where
    x - d < 0; returns out.

    cl, cr: census images (uint64); pl, pr: (channels, rows, cols) uint8 planes of the images
    (BGR, or grey as one plane).
    """
    h, w = cl.shape
    nd = out.shape[2]
    ch = pl.shape[0]
    fout = np.uint16(outside)
    for y in prange(h):
        # the intensity term as a table of the channels' summed |difference|: no float inside
        table = np.empty(256 * ch, dtype=np.uint16)
        for k in range(256 * ch):
            table[k] = np.uint16(weight * min(k / ch, cap) + 0.5)
        lrow = cl[y]
        rrow = cr[y]
        for x in range(w):
            a = lrow[x]
            n = min(nd, max(0, x - dmin + 1))
            o = out[y, x]
            for j in range(n):
                xr = x - dmin - j
                diff = np.int32(0)
                for c in range(ch):
                    diff += abs(np.int32(pl[c, y, x]) - np.int32(pr[c, y, xr]))
                o[j] = np.uint16(_popcount(a ^ rrow[xr])) + table[diff]
            for j in range(n, nd):
                o[j] = fout
    return out


def term_table(ch: int, weight: float, cap: int) -> np.ndarray:
    """census_ad_volume's intensity term at every summed |difference| 0 .. 255 * ch (int64)."""
    k = np.arange(256 * ch)
    return (weight * np.minimum(k / ch, cap) + 0.5).astype(np.uint16).astype(np.int64)


def integer_term(ch: int, weight: float, cap: int, outside: int) -> np.ndarray | None:
    """The term array of sgm._cost_row, [outside, kcap, a, b, s, largest cost]: the intensity
    term of a summed |difference| k is (min(k, kcap) * a + b) >> s, checked equal to
    term_table at every k (the row-by-row cost then equals census_ad_volume's); None where no
    such integers are found (the caller builds the volume instead). The smallest shift s that
    works is taken, from sgm.NARROW_SHIFT up, so that kcap * a + b mostly fits in 16 bits
    (_cost_row then scales in uint16 lanes, twice as many as uint32, at that shift)."""
    table = term_table(ch, weight, cap)
    kcap = ch * cap if cap < 255 else 255 * ch
    k = np.minimum(np.arange(256 * ch), kcap).astype(np.int64)
    largest = max(CENSUS_BITS + int(table.max()), outside)
    for s in range(NARROW_SHIFT, 21, 2):  # sgm's 16-bit form first (one source)
        a0 = int(round(weight / ch * (1 << s)))
        for a in (a0, a0 - 1, a0 + 1):
            for b in ((1 << s) // 2, (1 << s) // 2 - 1, (1 << s) // 2 + 1):
                if a < 0 or b < 0 or kcap * a + b >= 1 << 32:
                    continue
                if np.array_equal((k * a + b) >> s, table):
                    return np.array([outside, kcap, a, b, s, largest], dtype=np.int64)
    return None


def reversed_planes(planes: np.ndarray, dmin: int, nd: int) -> np.ndarray:
    """(channels, rows, cols) uint8 with each row reversed and dmin + sgm.padded(nd) zeros
    after it, the layout of sgm.reversed_right, so _cost_row reads candidate j of x at w - 1 -
    x + dmin + j (and the padded lanes past the candidates)."""
    c, h, w = planes.shape
    out = np.zeros((c, h, w + dmin + padded(nd)), dtype=np.uint8)
    out[:, :, :w] = planes[:, :, ::-1]
    return out


def match_histogram(img: np.ndarray, ref: np.ndarray, img_sample: np.ndarray | None = None,
                    ref_sample: np.ndarray | None = None) -> np.ndarray:
    """img (uint8) mapped through the monotonic table that gives it ref's grey-level histogram
    (each level goes to the first level of ref whose cumulative share reaches its own).

    A global gain, offset or gamma between the cameras is such a monotonic change, so the
    intensity term compares the right image with the left one as if the sensors were alike;
    between alike sensors the table is close to the identity.
    """
    a = img if img_sample is None else img_sample
    b = ref if ref_sample is None else ref_sample
    ch = np.cumsum(_histogram(a)) / a.size
    cr = np.cumsum(_histogram(b)) / b.size
    table = np.searchsorted(cr, ch - 1e-9).clip(0, 255).astype(np.uint8)
    return cv2.LUT(np.ascontiguousarray(img), table)


def _histogram(img: np.ndarray) -> np.ndarray:
    """Counts of the 256 levels of a uint8 image (OpenCV's: a tenth of np.bincount's time)."""
    return cv2.calcHist([np.ascontiguousarray(img)], [0], None, [256], [0, 256]).reshape(-1).astype(
        np.int64)
