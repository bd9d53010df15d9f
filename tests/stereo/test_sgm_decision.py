"""The SGM decision taken in the sweep that adds the last path (sgm._from_the_right_decided):
each pixel's winner, uniqueness test and the right view's entries from the totals packed as
total << bits | candidate, in 16-lane vectors (issue 24). Candidate counts of 16 and more
(the packed sweep's range), with and without a multiple of 16 (the overlapping last vector)."""

from __future__ import annotations

import numpy as np
import pytest

from host.stereo import sgm
from host.stereo.subpixel import FIT_NONE


def _decided(total: np.ndarray, dmin: int, uniqueness: float) -> tuple[np.ndarray, np.ndarray]:
    """The left and right maps of the totals, written out plainly: the first minimum, NaN where
    a candidate other than the winner and its two neighbours costs at most the minimum times
    1 + uniqueness / 100; the right pixel xr's first minimum along its diagonal."""
    h, w, nd = total.shape
    left = np.full((h, w), np.nan, np.float32)
    right = np.full((h, w), np.nan, np.float32)
    for y in range(h):
        for x in range(w):
            s = total[y, x].astype(np.int64)
            best = int(np.argmin(s))
            bound = np.floor(np.float32(s[best]) * (1.0 + uniqueness / 100.0))
            others = [j for j in range(nd) if abs(j - best) > 1 and s[j] <= bound]
            if uniqueness <= 0 or not others:
                left[y, x] = dmin + best
        for xr in range(w - dmin):
            diagonal = [int(total[y, xr + dmin + j, j]) for j in range(min(nd, w - xr - dmin))]
            right[y, xr] = dmin + int(np.argmin(diagonal))
    return left, right


@pytest.mark.parametrize("uniqueness", [0.0, 30.0])
@pytest.mark.parametrize("dmin", [0, 3])
@pytest.mark.parametrize("nd", [16, 23, 40])
@pytest.mark.parametrize("paths", [4, 5])
def test_packed_decision_equals_the_plain_one_on_the_totals(paths, nd, dmin, uniqueness) -> None:
    rng = np.random.default_rng(nd + dmin)
    # few distinct costs: many equal totals, so the first minimum among ties is tested
    cost = rng.integers(0, 8, (5, 47, nd)).astype(np.uint16)
    h, w, _ = cost.shape
    none = np.zeros((h, w), np.uint64)  # census images unused: the cost volume is given
    total = np.empty_like(cost)
    left, right = sgm.match(none, sgm.reversed_right(none, dmin, nd), cost, total, dmin,
                            np.uint16(3), np.uint16(12), paths, uniqueness, FIT_NONE, True,
                            True)
    want_l, want_r = _decided(total, dmin, uniqueness)
    np.testing.assert_array_equal(left, want_l)
    np.testing.assert_array_equal(right, want_r)
