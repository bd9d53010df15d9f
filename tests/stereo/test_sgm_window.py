"""The right view's minima in the sweep that adds the path from the right, kept in a window
of lanes moved down one lane a pixel (sgm._from_the_right_decided where the candidates are a
whole number of 16-lane vectors; issue 24): the maps equal the plain decision on the totals
(test_sgm_decision._decided) at two, three and four vectors, where the window's lanes cross
from one vector to the next."""

from __future__ import annotations

import numpy as np
import pytest

from host.stereo import sgm
from host.stereo.subpixel import FIT_NONE
from tests.stereo.test_sgm_decision import _decided


@pytest.mark.parametrize("uniqueness", [0.0, 30.0])
@pytest.mark.parametrize("dmin", [0, 3])
@pytest.mark.parametrize("nd", [32, 48, 64])
@pytest.mark.parametrize("paths", [4, 5])
def test_windowed_right_view_equals_the_plain_one_on_the_totals(paths, nd, dmin,
                                                                 uniqueness) -> None:
    rng = np.random.default_rng(nd + dmin + paths)
    # few distinct costs: many equal totals, so the first minimum among ties is tested
    cost = rng.integers(0, 8, (4, 90, nd)).astype(np.uint16)
    h, w, _ = cost.shape
    none = np.zeros((h, w), np.uint64)  # census images unused: the cost volume is given
    total = np.empty_like(cost)
    left, right = sgm.match(none, sgm.reversed_right(none, dmin, nd), cost, total, dmin,
                            np.uint16(3), np.uint16(12), paths, uniqueness, FIT_NONE, True,
                            True)
    want_l, want_r = _decided(total, dmin, uniqueness)
    np.testing.assert_array_equal(left, want_l)
    np.testing.assert_array_equal(right, want_r)
    # the right view is not one value everywhere: the windows' lanes are what decides it
    assert len(np.unique(right[np.isfinite(right)])) > nd // 4
