"""The own SGM's cost volume: census Hamming plus the capped intensity term, and the cost of a
candidate whose right pixel lies outside the image."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from host.stereo import MatcherParams, compute_disparity, sgm
from host.stereo.cost import census_ad_volume, match_histogram
from host.stereo.params import CENSUS_BITS
from host.stereo.synthetic import synthetic_scene


def _census(img: np.ndarray) -> np.ndarray:
    return sgm.census(cv2.copyMakeBorder(img, sgm.CENSUS_H, sgm.CENSUS_H, sgm.CENSUS_W,
                                         sgm.CENSUS_W, cv2.BORDER_REPLICATE))


@pytest.mark.parametrize(("dmin", "weight", "cap", "outside"),
                         [(0, 0.5, 20, 13), (3, 1.25, 7, 40), (0, 0.0, 20, CENSUS_BITS)])
def test_volume_is_hamming_plus_capped_intensity_and_outside_beyond_the_image(
        dmin, weight, cap, outside) -> None:
    rng = np.random.default_rng(2)
    gl = rng.integers(0, 256, (7, 19), dtype=np.uint8)
    gr = rng.integers(0, 256, (7, 19), dtype=np.uint8)
    cl, cr = _census(gl), _census(gr)
    nd = 9
    got = census_ad_volume(cl, cr, gl[None], gr[None], dmin, weight, cap, outside,
                           np.empty((7, 19, nd), np.uint16))
    for y in range(7):
        for x in range(19):
            for j in range(nd):
                xr = x - dmin - j
                if xr < 0:
                    want = outside
                else:
                    ham = bin(int(cl[y, x]) ^ int(cr[y, xr])).count("1")
                    diff = min(abs(int(gl[y, x]) - int(gr[y, xr])), cap)
                    want = ham + int(np.floor(weight * diff + 0.5))
                assert got[y, x, j] == want, (y, x, j)


def test_colour_term_is_the_mean_of_the_channels_differences() -> None:
    rng = np.random.default_rng(3)
    pl = rng.integers(0, 256, (3, 5, 12), dtype=np.uint8)
    pr = rng.integers(0, 256, (3, 5, 12), dtype=np.uint8)
    none = np.zeros((5, 12), np.uint64)  # equal census: the volume is the intensity term
    got = census_ad_volume(none, none, pl, pr, 0, 0.5, 30, 99, np.empty((5, 12, 4), np.uint16))
    for y, x, j in [(0, 3, 0), (2, 7, 3), (4, 11, 2), (1, 5, 3)]:
        diff = np.abs(pl[:, y, x].astype(int) - pr[:, y, x - j].astype(int)).mean()
        assert got[y, x, j] == int(np.floor(0.5 * min(diff, 30) + 0.5))
    assert got[0, 2, 3] == 99


def test_census_bits_constant_agrees_with_the_matcher() -> None:
    assert CENSUS_BITS == sgm.CENSUS_BITS


def test_census_alone_through_the_volume_equals_the_census_rows() -> None:
    # the same cost by the two routes (inside the aggregation, or a volume: a weight whose
    # term rounds to 0 at every capped difference) gives the same map
    scene = synthetic_scene(seed=4, noise=0.5)
    plain = MatcherParams(matcher="sgm", block_size=1, num_disparities=48, border="clip", p1=8,
                          p2=32)
    rows = compute_disparity(scene.left, scene.right, plain)
    vol = compute_disparity(scene.left, scene.right, plain.replace(intensity_weight=0.01))
    np.testing.assert_array_equal(rows, vol)


def test_intensity_term_keeps_census_indifferent_to_a_gain() -> None:
    # a darker right camera (gain 0.7): the capped intensity term is the same for nearly
    # every candidate, so the map stays what census alone gives on the original pair
    scene = synthetic_scene(seed=5, noise=0.0)
    left = cv2.cvtColor(scene.left, cv2.COLOR_BGR2GRAY) if scene.left.ndim == 3 else scene.left
    right = cv2.cvtColor(scene.right, cv2.COLOR_BGR2GRAY) if scene.right.ndim == 3 \
        else scene.right
    darker = (right.astype(np.float32) * 0.7).astype(np.uint8)
    p = MatcherParams.for_matcher("sgm").replace(num_disparities=48)
    a = compute_disparity(left, right, p)
    b = compute_disparity(left, darker, p)
    truth = scene.gt
    known = np.isfinite(truth)
    bad_a = (np.abs(a - truth) > 1)[known].mean()
    bad_b = (np.abs(b - truth) > 1)[known].mean()
    assert bad_b < bad_a + 0.02, (bad_a, bad_b)


def test_match_histogram_undoes_a_gain_and_a_gamma() -> None:
    rng = np.random.default_rng(7)
    img = cv2.GaussianBlur(rng.integers(0, 256, (60, 80), dtype=np.uint8), (0, 0), 2)
    img = cv2.normalize(img, None, 0, 255, cv2.NORM_MINMAX)
    for changed in ((img * 0.7).astype(np.uint8),
                    (255 * (img / 255.0) ** 1.5).astype(np.uint8)):
        back = match_histogram(changed, img).astype(int)
        assert np.abs(back - img).mean() < 1.5
        assert np.abs(changed.astype(int) - img).mean() > 10
    # the table comes from the samples given: a sample identical to the reference's is identity
    np.testing.assert_array_equal(match_histogram(img, img), img)
