"""Sub-pixel fits through the costs at d-1, d, d+1: parabola and equiangular (V) line fit.

An offset is the minimum's position in candidate-index units from the centre sample (positive
toward the next index), in [-0.5, 0.5]; the caller turns it into px (SAD indexes candidates by
descending disparity, so d = d_k - offset; SGM by ascending, d = d_j + offset).
Equiangular fits a V with equal slopes, the model of an L1 cost (SAD, census Hamming) near its
minimum; the parabola is the model of a squared cost (SSD) or a smooth correlation (ZNCC).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

FIT_NONE = 0
FIT_PARABOLA = 1
FIT_EQUIANGULAR = 2
FITS = {"parabola": FIT_PARABOLA, "equiangular": FIT_EQUIANGULAR}
# the fit each own matcher uses when none is asked for: the better by bad at 0.5 px and RMS on
# Cones and Teddy (docs/stereo.md, Sub-pixel). For SAD and SGM the parabola wins there by a
# little although the equiangular fit is the unbiased one (flatter fractional parts).
DEFAULT_FITS = {"sad": "parabola", "ssd": "parabola", "ncc": "parabola", "sgm": "parabola"}


@njit(cache=True, fastmath=True, inline="always")
def fit_offset(cm: float | np.floating[Any], c0: float | np.floating[Any],
               cp: float | np.floating[Any], fit: int) -> float:
    """Offset of the minimum from the centre sample, given costs before, at and after it
    (float32 from the own matchers, whose arithmetic here numba does in float64)."""
    if fit == FIT_PARABOLA:
        den = cm - 2.0 * c0 + cp
        return float(0.5 * (cm - cp) / den) if den > 0.0 else 0.0
    if fit == FIT_EQUIANGULAR:
        slope = max(cm, cp) - c0
        return float(0.5 * (cm - cp) / slope) if slope > 0.0 else 0.0
    return 0.0
