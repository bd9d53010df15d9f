"""The fused SGM decision above 64 candidates (issue 24): where a total may not fit beside the
candidate in 16 bits, sgm._from_the_right_decided packs it saturated and takes a pixel whose
every total saturates (and such a right pixel, in _finish_row) from a plain scan. The maps
must be those of the separate passes (sgm._decide_row) that ran there before."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from host.stereo import MatcherParams, compute_disparity, load_scene, sgm
from host.stereo.subpixel import FIT_NONE
from tests.stereo.test_sgm_decision import _decided

# the defaults' maps at these candidate counts, written by the separate passes (b35170c)
WIDE = Path(__file__).with_name("sgm_wide_reference.npz")


@pytest.mark.parametrize("uniqueness", [0.0, 30.0])
@pytest.mark.parametrize("nd", [70, 100, 128])
@pytest.mark.parametrize("paths", [4, 5])
def test_saturated_packing_gives_the_plain_decision(paths, nd, uniqueness) -> None:
    rng = np.random.default_rng(nd)
    h, w = 5, 40 + nd
    cost = rng.integers(0, 40, (h, w, nd)).astype(np.uint16)
    # costs 0 .. 40, every candidate 150 more on the right half: there each pixel's totals all
    # reach the saturation (their minimum at or over 0xFFFF >> bits), and so does each right
    # pixel's diagonal from w / 2 on; on the left half neither
    cost[:, w // 2:] += 150
    none = np.zeros((h, w), np.uint64)
    total = np.empty_like(cost)
    left, right = sgm.match(none, sgm.reversed_right(none, 2, nd), cost, total, 2,
                            np.uint16(10), np.uint16(40), paths, uniqueness, FIT_NONE, True,
                            True)
    top = 0xFFFF >> int(np.ceil(np.log2(nd)))
    least = total.min(axis=2)
    assert (least >= top).any() and (least < top).any()
    assert (least[:, w // 2:] >= top).all()  # and so every right pixel from w / 2 - 2 on
    assert sgm._fused(0, nd, True)  # the fused sweep runs here, not the separate passes
    want_l, want_r = _decided(total, 2, uniqueness)
    np.testing.assert_array_equal(left, want_l)
    np.testing.assert_array_equal(right, want_r)


@pytest.mark.parametrize("name,nd", [("cones", 128), ("teddy", 96)])
def test_defaults_above_64_candidates_keep_the_maps_of_the_separate_passes(middlebury: Path,
                                                                           name, nd) -> None:
    s = load_scene(middlebury / name)
    d = compute_disparity(s.left, s.right, MatcherParams.for_matcher("sgm").replace(
        num_disparities=nd))
    want = np.load(WIDE)[f"{name}{nd}"].astype(np.float32)
    want[want == 255] = np.nan
    np.testing.assert_array_equal(d, want)
