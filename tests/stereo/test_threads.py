"""The own SAD matcher's map does not depend on how many threads numba gives it (a small match
runs on the calling thread alone, a large one in one band of rows per thread)."""

from __future__ import annotations

import numpy as np
import pytest

from host.stereo import MatcherParams, compute_disparity
from host.stereo.matcher import SERIAL_WORK, numba_threads
from host.stereo.synthetic import synthetic_scene


@pytest.mark.parametrize("border", ["invalid", "clip"])
def test_sad_map_is_the_same_on_one_thread_and_on_all(border: str) -> None:
    scene = synthetic_scene(3, 320, 240, max_disp=28)
    params = MatcherParams(num_disparities=32, border=border, lr_check=1.0)
    assert SERIAL_WORK <= 240 * 320 * 32  # the whole map goes to every thread
    whole = compute_disparity(scene.left, scene.right, params)
    with numba_threads(1):
        alone = compute_disparity(scene.left, scene.right, params)
    np.testing.assert_array_equal(alone, whole)
    assert np.isfinite(whole).mean() > 0.5
