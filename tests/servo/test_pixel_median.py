"""The compiled per-pixel median (host/servo/pixel_median.py, issue 25) is np.nanmedian(stack,
axis=0) to the bit: random stacks of 1-8 maps, float32 and float64, with NaN (some pixels NaN
in every map), ties, zeros and -0.0 (numpy's sum from +0.0 turns a lone -0.0 into 0.0), and a
stack of the servo's own reference maps (a dev trial's, as perception.median_map takes them)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from host.servo.perception import median_map
from host.servo.pixel_median import nanmedian0


def _numpy(stack: np.ndarray) -> np.ndarray:
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.asarray(np.nanmedian(stack, axis=0))


def _bits(a: np.ndarray) -> tuple[str, tuple[int, ...], bytes]:
    return a.dtype.str, a.shape, a.tobytes()


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_random_stacks_give_numpys_median_to_the_bit(dtype: type) -> None:
    rng = np.random.default_rng(25)
    for t in range(150):
        n = int(rng.integers(1, 9))
        stack = rng.normal(10, 5, (n, 17, 23)).astype(dtype)
        stack[rng.random(stack.shape) < rng.random()] = np.nan
        if t % 3 == 0:
            stack = np.round(stack)  # ties, and -0.0 from small negatives
        if t % 5 == 0:
            stack[stack < 3] = 0.0
        if t % 7 == 0:
            stack[:, 3:5] = np.nan  # no valid value in any map
        assert _bits(nanmedian0(stack)) == _bits(_numpy(stack)), f"stack {t} ({n} maps)"


def test_median_map_of_disparity_maps_is_numpys() -> None:
    rng = np.random.default_rng(7)
    base = np.linspace(2, 30, 240 * 320, dtype=np.float32).reshape(240, 320)
    maps = []
    for _ in range(5):
        m = base + rng.normal(0, 0.3, base.shape).astype(np.float32)
        m[rng.random(base.shape) < 0.3] = np.nan
        m[:, :40] = np.nan  # the left band a matcher leaves invalid
        maps.append(m)
    assert _bits(median_map(maps)) == _bits(_numpy(np.stack(maps)))
    assert _bits(median_map(maps[:1])) == _bits(maps[0])


def test_other_stacks_go_to_numpy() -> None:
    ints = np.arange(24, dtype=np.int32).reshape(2, 3, 4)
    assert _bits(nanmedian0(ints)) == _bits(_numpy(ints))
