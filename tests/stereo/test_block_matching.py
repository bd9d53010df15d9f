"""The own block matcher: accuracy on exact shifts, border rules, LR check, uniqueness."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from host.stereo import MatcherParams, compute_disparity
from host.stereo.synthetic import Layer, random_texture, render_pair
from tests.stereo import sad_reference, sgm_reference


def shifted_pair(d: float, width: int = 160, height: int = 90, seed: int = 1):
    rng = np.random.default_rng(seed)
    tex = random_texture(rng, height, width + 80, sigma=1.2)
    return render_pair([Layer(d, tex, margin=40)], width, height, noise=0.0)


@pytest.mark.parametrize("matcher", ["sad", "ssd", "ncc"])
@pytest.mark.parametrize("d", [7.0, 12.25, 20.5, 31.75])
def test_subpixel_recovers_known_shift(matcher: str, d: float) -> None:
    scene = shifted_pair(d)
    disp = compute_disparity(scene.left, scene.right,
                             MatcherParams(matcher=matcher, block_size=9, num_disparities=40))
    # pixels whose true match lies inside the right image with a full window
    region = np.zeros(disp.shape, bool)
    region[4:-4, int(np.ceil(d)) + 5:-4] = True
    valid = np.isfinite(disp) & region
    assert valid.sum() == region.sum()
    err = np.abs(disp[valid] - d)
    assert (err <= 0.25).mean() >= 0.99, f"{matcher} d={d}: {np.percentile(err, 99):.3f} px"


def _naive_sad(left: np.ndarray, right: np.ndarray, nd: int, size: int) -> np.ndarray:
    # reference: explicit window loops, integer WTA with the smallest cost (ties -> larger d)
    h, w = left.shape
    r = size // 2
    out = np.full((h, w), np.nan, np.float32)
    L, R = left.astype(np.int64), right.astype(np.int64)
    for y in range(r, h - r):
        for x in range(r, w - r):
            best, best_d = None, None
            for d in range(min(nd - 1, x - r), -1, -1):
                c = np.abs(L[y - r:y + r + 1, x - r:x + r + 1]
                           - R[y - r:y + r + 1, x - d - r:x - d + r + 1]).sum()
                if best is None or c < best:
                    best, best_d = c, d
            out[y, x] = best_d
    return out


@pytest.mark.parametrize("size", [3, 5, 9])
def test_running_sums_equal_explicit_windows(size: int) -> None:
    rng = np.random.default_rng(size)
    left = rng.integers(0, 256, (20, 40), dtype=np.uint8)
    right = rng.integers(0, 256, (20, 40), dtype=np.uint8)
    got = compute_disparity(left, right, MatcherParams(block_size=size, num_disparities=12,
                                                       subpixel=False))
    want = _naive_sad(left, right, 12, size)
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
    np.testing.assert_array_equal(got[np.isfinite(got)], want[np.isfinite(want)])


@pytest.mark.parametrize("i", range(len(sad_reference.CONFIGS)))
def test_sad_maps_equal_the_reference_written_before_the_speed_rework(i: int) -> None:
    # sad_reference.npz holds sad.match_sad's maps at commit 85cf046 for every configuration
    # (candidate counts 16..128, grey and colour, uint16 and int32 lanes, both borders, fits,
    # uniqueness, LR's right map, one band or three)
    sgm_reference.assert_frozen(sad_reference.FILE, sad_reference.CONFIGS, sad_reference.run, i)


def test_border_invalid_never_uses_pixels_outside_the_image() -> None:
    scene = shifted_pair(15.0)
    disp = compute_disparity(scene.left, scene.right, MatcherParams(block_size=11,
                                                                    num_disparities=32))
    half = 5
    assert np.isnan(disp[:half]).all() and np.isnan(disp[-half:]).all()
    assert np.isnan(disp[:, :half]).all() and np.isnan(disp[:, -half:]).all()
    # a right window never starts left of column 0: d <= x - half
    ys, xs = np.nonzero(np.isfinite(disp))
    assert (np.rint(disp[ys, xs]) <= xs - half).all()


def test_border_clip_gives_a_dense_map_without_wrapping() -> None:
    scene = shifted_pair(15.0)
    p = MatcherParams(block_size=11, num_disparities=32, border="clip")
    disp = compute_disparity(scene.left, scene.right, p)
    inside = disp[:, 15 + 5:]
    assert np.isfinite(inside).all()
    assert (np.abs(inside - 15.0) <= 0.25).mean() > 0.99
    # columns left of d can not see their match; they must not pick a wrapped-around one
    assert (disp[:, :15] <= np.arange(15)[None, :] + 0.5).all()


def test_uniqueness_rejects_ambiguous_matches() -> None:
    # vertical stripes with a period of 8 px: every 8th disparity matches equally well
    period = np.array([128, 198, 228, 198, 128, 57, 28, 57], np.uint8)
    img = np.tile(period, (40, 15))
    p = MatcherParams(block_size=5, num_disparities=32, uniqueness_ratio=10)
    disp = compute_disparity(img, img, p)
    # beyond x = 8 + half at least two periods fit in the range: all ambiguous
    assert np.isnan(disp[:, 16:]).all()
    plain = compute_disparity(img, img, p.replace(uniqueness_ratio=0))
    assert np.isfinite(plain[2:-2, 16:-2]).all()


@pytest.mark.parametrize("matcher", ["opencv-bm", "opencv-sgbm"])
def test_opencv_backends_return_pixels_with_nan_for_invalid(matcher: str) -> None:
    scene = shifted_pair(12.5, width=200)
    p = MatcherParams(matcher=matcher, block_size=9, num_disparities=32)
    disp = compute_disparity(scene.left, scene.right, p)
    assert disp.dtype == np.float32
    valid = np.isfinite(disp)
    assert 0.4 < valid.mean() < 1.0  # the left strip (no full range) is invalid
    assert np.median(np.abs(disp[valid] - 12.5)) < 0.25
    assert not (disp[valid] < p.min_disparity).any()


def test_colour_and_grey_input_are_both_accepted() -> None:
    scene = shifted_pair(10.0)
    colour = [cv2.cvtColor(v, cv2.COLOR_GRAY2BGR) for v in (scene.left, scene.right)]
    p = MatcherParams(block_size=7, num_disparities=24)
    a = compute_disparity(scene.left, scene.right, p)
    b = compute_disparity(*colour, p)
    assert np.nanmedian(np.abs(a - 10)) < 0.1 and np.nanmedian(np.abs(b - 10)) < 0.1
