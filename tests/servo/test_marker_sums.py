"""The marker's centroid and ring statistics run in numba with numpy's own arithmetic: a sum of
float64 values is numpy's pairwise sum to the last bit, a deviation numpy's std, on arrays of
every length round the sum's blocks of 8 and 128."""

from __future__ import annotations

import numpy as np
import pytest

from host.servo import marker


@pytest.mark.parametrize("scale", [1e-3, 1.0, 255.0, 1e6])
def test_sum_is_numpys_to_the_last_bit(scale: float) -> None:
    rng = np.random.default_rng(int(scale * 10) % 97)
    for n in [*range(0, 300), 511, 512, 513, 1000, 1023, 1031, 4096, 5003]:
        a = rng.random(n) * scale - 0.3 * scale
        assert marker._numpy_sum(a) == a.sum(), n


def test_mean_and_deviation_are_numpys() -> None:
    rng = np.random.default_rng(11)
    for n in range(1, 700, 3):
        lo, hi = sorted(int(v) for v in rng.integers(0, 256, 2))
        values = rng.integers(lo, hi + 1, n)
        mean, sd = marker._mean_and_sd(values)
        f = values.astype(np.float64)
        assert (mean, sd) == (f.mean(), f.std()), n
    assert marker._mean_and_sd(np.zeros(0, np.int64)) == (0.0, 255.0)
