"""The SAD kernel in explicit 16-lane vectors (sad._match_u16, sad_lanes) against the kernel in
LLVM-vectorised loops (sad._match_any), both run with uint16 lanes on the same inputs, and the
lane helpers against numpy (issue 24)."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from host.stereo import sad
from host.stereo import sad_lanes as V

# (channels, dmin, nd, half, clip, uniqueness, fit, want_right, nbands): candidate counts
# below, at and past one and several vectors, the edge columns (nd + half past a tile), the
# right map, two bands, colour, and a uniqueness test (the scalar path inside _match_u16)
CASES = [(1, 0, 1, 1, False, 0.0, 0, True, 1), (1, 0, 5, 2, True, 0.0, 1, True, 1),
         (1, 3, 16, 4, False, 0.0, 1, True, 1), (1, 0, 17, 4, True, 0.0, 2, True, 2),
         (1, 0, 31, 3, False, 0.0, 1, False, 1), (1, 2, 33, 4, True, 0.0, 1, True, 1),
         (1, 0, 48, 1, False, 0.0, 2, True, 2), (1, 0, 64, 4, True, 0.0, 1, True, 1),
         (1, 1, 65, 2, False, 0.0, 1, True, 1), (1, 0, 100, 4, False, 0.0, 1, True, 1),
         (3, 0, 24, 4, True, 0.0, 1, True, 1), (3, 4, 40, 4, False, 0.0, 2, True, 2),
         (1, 0, 32, 4, False, 10.0, 1, True, 1), (3, 0, 20, 2, True, 15.0, 1, True, 1)]


def _pair(channels: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A textured pair 37 rows by 171 columns with two depth steps and flat patches (ties)."""
    rng = np.random.default_rng(seed)
    right = rng.integers(0, 256, (channels, 37, 171 + 40), dtype=np.uint8)
    right[:, 10:20, 60:90] = 128  # a flat patch: equal window sums for many candidates
    shift = np.where(np.arange(171) < 80, 7, 23)
    left = np.stack([right[:, :, 40 + x - s] for x, s in enumerate(shift)], axis=2)
    left = np.clip(left.astype(np.int16) + rng.integers(-3, 4, left.shape), 0, 255)
    return np.ascontiguousarray(left.astype(np.uint8)), np.ascontiguousarray(right[:, :, 40:])


@pytest.mark.parametrize("case", CASES)
def test_vector_kernel_equals_the_loop_kernel(case: tuple) -> None:
    channels, dmin, nd, half, clip, uniq, fit, lr, bands = case
    left, right = _pair(channels, nd)
    args = (left, right, dmin, nd, half, uniq, fit, lr, clip, np.empty(0, np.uint16),
            np.empty(0, np.uint16), 0xFFFF, bands)
    got = sad._match_u16(*args)
    want = sad._match_any(*args)
    assert np.isfinite(want[0]).any() and np.isfinite(want[1]).any() == lr
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)


def test_match_sad_takes_the_vector_kernel_only_for_uint16_sums(monkeypatch) -> None:
    seen = []
    monkeypatch.setattr(sad, "_match_u16", lambda *a: seen.append("u16") or (a[0], a[1]))
    monkeypatch.setattr(sad, "_match_any", lambda *a: seen.append("any") or (a[0], a[1]))
    left, right = _pair(1, 0)
    for cdt, wdt in ((np.uint16, np.uint16), (np.uint16, np.int32), (np.int32, np.int32)):
        sad.match_sad(left, right, 0, 16, 4, 0.0, 1, False, False, np.empty(0, cdt),
                      np.empty(0, wdt), np.iinfo(wdt).max, 1)
    assert seen == ["u16", "any", "any"]


@njit(cache=True)
def _lanes(a, b, bytes_, k, missing):
    out = np.empty((6, 16), np.uint16)
    va, vb = V.load(a, 0), V.load(b, 0)
    V.store(out, 0, V.absdiff(va, vb))
    V.store(out, 16, V.widen(bytes_, 1))
    V.store(out, 32, V.take_le(va, vb, V.iota(k), V.splat(7)))
    V.store(out, 48, V.vsub(V.vadd(va, V.splat(60000)), vb))
    V.store(out, 64, V.vmin(va, V.vor(vb, V.load(a, 16))))
    V.store(out, 80, V.splat(k))
    return out, V.hmin(va), V.first_eq(va, a[5]), V.first_eq(va, missing)


def test_lane_helpers_against_numpy() -> None:
    rng = np.random.default_rng(1)
    a = rng.integers(0, 65536, 32, dtype=np.uint16)
    a[9] = a[5]  # first_eq must give the lower lane
    a[16:] = rng.choice([0, 0xFFFF], 16).astype(np.uint16)
    b = rng.integers(0, 65536, 16, dtype=np.uint16)
    b[3] = a[3]  # take_le on equality
    bytes_ = rng.integers(0, 256, 20, dtype=np.uint8)
    missing = next(v for v in range(65536) if v not in a[:16])
    out, low, first, none = _lanes(a, b, bytes_, 40, missing)
    x, y = a[:16].astype(np.int64), b.astype(np.int64)
    np.testing.assert_array_equal(out[0], np.abs(x - y))
    np.testing.assert_array_equal(out[1], bytes_[1:17])
    np.testing.assert_array_equal(out[2], np.where(x <= y, 40 + np.arange(16), 7))
    np.testing.assert_array_equal(out[3], (x + 60000 - y) % 65536)
    np.testing.assert_array_equal(out[4], np.minimum(x, y | a[16:].astype(np.int64)))
    np.testing.assert_array_equal(out[5], np.full(16, 40))
    assert low == a[:16].min()
    assert first == int(np.argmax(a[:16] == a[5])) == 5
    assert none == 16
