"""The renderer's anti-aliased marker coverage (renderer._coverage, in numba) is the numpy
computation it replaced, to the bit: every pixel's 4x4 samples counted against each threshold,
with samples landing exactly on a threshold (terms from a coarse grid) and the real marker's
terms."""

from __future__ import annotations

import numpy as np
import pytest

from host.sim import renderer


def _numpy_coverage(qx: np.ndarray, qy: np.ndarray, ts: tuple[float, ...]) -> list[np.ndarray]:
    # every sample counted (the definition; the renderer's shortcut must agree with it)
    samples = qx[None, :, None, :] + qy[:, None, :, None]  # rows, columns, 4, 4
    return [np.count_nonzero(samples <= t, axis=(2, 3)) / 16 for t in ts]


@pytest.mark.parametrize("seed", range(12))
def test_coverage_counts_every_sample_with_ties(seed: int) -> None:
    rng = np.random.default_rng(seed)
    rows, cols = (int(v) for v in rng.integers(1, 30, 2))
    qx = rng.integers(0, 12, (cols, 4)) / 8  # sums land on the thresholds exactly
    qy = rng.integers(0, 12, (rows, 4)) / 8
    ts = (1.0, 1.5 ** 2, 0.75)
    for got, want in zip(renderer._coverage(qx, qy, ts), _numpy_coverage(qx, qy, ts)):
        np.testing.assert_array_equal(got, want)


def test_coverage_of_a_marker() -> None:
    sub = (np.arange(4) + 0.5) / 4 - 0.5
    u, v, rx, ry, ring = 40.3, 22.7, 5.1, 6.2, 1.7
    qy = ((np.arange(10, 36)[:, None] + sub - v) / ry) ** 2
    qx = ((np.arange(28, 53)[:, None] + sub - u) / rx) ** 2
    ts = (ring * ring, 1.0)
    got = renderer._coverage(qx, qy, ts)
    for g, w in zip(got, _numpy_coverage(qx, qy, ts)):
        np.testing.assert_array_equal(g, w)
    assert 0 < got[1].sum() < got[0].sum()
