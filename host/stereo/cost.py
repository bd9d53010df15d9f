"""SGM matching cost volumes: census Hamming mixed with truncated absolute intensity difference.

The volume is (rows, cols, nd) uint16 with the disparity axis innermost, the layout sgm.match
takes as its box-summed cost. Candidate j of left pixel x is disparity dmin + j, right pixel
x - dmin - j.

- Census (sgm.census bits, Hamming distance) compares each pixel only with its neighbours, so a
  gain or gamma between the cameras changes nothing; it is weak on flat, untextured surfaces,
  where every neighbour is about as bright as the centre and noise decides the bits.
- The intensity term, weight * min(|I_left(x) - I_right(x - d)|, cap), tells apart candidates
  there (AD-census, Mei et al. 2011). Under a gain between the cameras the difference is large
  for every candidate alike, so the cap turns it into a constant and census decides again.
- A candidate whose right pixel lies outside the image (the strip x < d of the left view, which
  the right camera does not see) costs `outside`: near a good match's cost rather than the
  census maximum, so the paths carry the disparity of the visible side into the strip instead
  of preferring any candidate the right view happens to have; the LR check then rejects what
  lands outside the right image and the fill extends the visible side.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from host.stereo.sgm import _popcount


@njit(cache=True, parallel=True)
def census_ad_volume(cl, cr, gl, gr, dmin, weight, cap, outside, out):
    """Fill out (rows, cols, nd) uint16 with round(Hamming(cl[x], cr[x - d]) + weight *
    min(|gl[x] - gr[x - d]|, cap)) for d = dmin + j, and outside where x - d < 0; returns out.

    cl, cr: census images (uint64); gl, gr: the grey images (uint8) they came from.
    """
    h, w = cl.shape
    nd = out.shape[2]
    fout = np.uint16(outside)
    for y in prange(h):
        # the intensity term as a table of |difference| 0..255: no float in the inner loop
        table = np.empty(256, dtype=np.uint16)
        for k in range(256):
            table[k] = np.uint16(weight * min(k, cap) + 0.5)
        lrow = cl[y]
        rrow = cr[y]
        lg = gl[y]
        rg = gr[y]
        for x in range(w):
            a = lrow[x]
            ia = np.int32(lg[x])
            n = min(nd, max(0, x - dmin + 1))
            o = out[y, x]
            for j in range(n):
                xr = x - dmin - j
                diff = abs(ia - np.int32(rg[xr]))
                o[j] = np.uint16(_popcount(a ^ rrow[xr])) + table[diff]
            for j in range(n, nd):
                o[j] = fout
    return out
