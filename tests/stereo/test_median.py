"""postprocess.median: whole-pixel maps filtered as uint16 give the float32 filter's result."""

import cv2
import numpy as np
import pytest

from host.stereo.postprocess import median


def _float_median(disp: np.ndarray, size: int) -> np.ndarray:
    # the filter as it was: NaN counts as 0 in its neighbours' medians and stays NaN
    out = cv2.medianBlur(np.where(np.isnan(disp), 0.0, disp).astype(np.float32), size)
    out[np.isnan(disp)] = np.nan
    return out


def _map(whole: bool, low: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    d = rng.uniform(low, 300.0, (41, 67)).astype(np.float32)  # above uint8's range
    d = np.floor(d) if whole else d
    d[rng.random(d.shape) < 0.2] = np.nan
    return d.astype(np.float32)


@pytest.mark.parametrize("size", [3, 5])
@pytest.mark.parametrize("whole, low", [(True, 0.0), (False, 0.0), (True, -20.0)])
def test_median_equals_the_float_filter_whole_or_not(size, whole, low) -> None:
    d = _map(whole, low, seed=size)
    np.testing.assert_array_equal(median(d, size), _float_median(d, size))
    # a column view (not contiguous) is filtered the same
    np.testing.assert_array_equal(median(d[:, 3:40], size), _float_median(d[:, 3:40], size))
