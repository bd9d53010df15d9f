"""The per-pixel median of a stack of disparity maps, NaN left out: np.nanmedian(stack, axis=0)
to the bit, compiled (issue 25).

For a stack of fewer than 600 maps numpy takes the masked-array median (np.ma.median of the
stack with its NaNs masked): per pixel the valid values sorted, the two middle ones (the middle
one twice for an odd count) summed in the stack's dtype from +0.0 (a lone -0.0 gives 0.0) and
halved; no valid value gives NaN (with a RuntimeWarning per such pixel: the servo's maps have
thousands). Here the same arithmetic, pixel by pixel, without the masked arrays' temporaries
and the warnings: five 240 x 320 maps 12.7 -> 1.8 ms.
"""

from __future__ import annotations

import warnings

import numpy as np
from numba import njit

import host.stereo  # noqa: F401  (numba's cache made safe between processes)


def nanmedian0(stack: np.ndarray) -> np.ndarray:
    """np.nanmedian(stack, axis=0) for a float32 or float64 stack (maps, rows, columns) of
    fewer than 600 maps; any other stack goes to numpy itself."""
    if (stack.ndim != 3 or stack.dtype not in (np.float32, np.float64)
            or not 0 < stack.shape[0] < 600):
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            return np.asarray(np.nanmedian(stack, axis=0))
    out: np.ndarray = _nanmedian0(np.ascontiguousarray(stack))
    return out


@njit(cache=True)
def _nanmedian0(stack: np.ndarray) -> np.ndarray:
    n, h, w = stack.shape
    out = np.empty((h, w), stack.dtype)
    vals = np.empty(n, stack.dtype)
    zero = np.zeros(1, stack.dtype)[0]  # numpy's sum starts from +0.0 (-0.0 gives 0.0)
    for y in range(h):
        for x in range(w):
            c = 0
            for k in range(n):
                v = stack[k, y, x]
                if not np.isnan(v):
                    # insertion sort: the valid values ascending
                    j = c
                    while j > 0 and vals[j - 1] > v:
                        vals[j] = vals[j - 1]
                        j -= 1
                    vals[j] = v
                    c += 1
            if c == 0:
                out[y, x] = np.nan
            elif c % 2:
                m = vals[c // 2]
                out[y, x] = (zero + m + m) / 2.0  # the sum in the stack's dtype
            else:
                out[y, x] = (zero + vals[c // 2 - 1] + vals[c // 2]) / 2.0
    return out
