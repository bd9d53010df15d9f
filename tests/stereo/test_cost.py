"""The own SGM's cost volume: census Hamming plus the capped intensity term, and the cost of a
candidate whose right pixel lies outside the image."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from host.stereo import MatcherParams, compute_disparity, sgm
from host.stereo.cost import (
    census_ad_volume,
    integer_term,
    match_histogram,
    reversed_planes,
    term_table,
)
from host.stereo.params import CENSUS_BITS, MATCHER_DEFAULTS
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


def _pair(h: int, w: int, ch: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    # a textured pair shifted by 5..9 px with noise, so the maps have structure to disagree on
    rng = np.random.default_rng(seed)
    base = cv2.GaussianBlur(rng.integers(0, 256, (h, w + 12, ch), dtype=np.uint8), (0, 0), 1.0)
    base = base.reshape(h, w + 12, ch)
    shift = 5 + (np.arange(w) * 4) // w
    left = base[:, :w]
    right = np.stack([base[:, min(x + shift[x], w + 11)] for x in range(w)], axis=1)
    noise = rng.integers(-3, 4, right.shape)
    right = np.clip(right.astype(int) + noise, 0, 255).astype(np.uint8)
    return np.moveaxis(left, 2, 0).copy(), np.moveaxis(right, 2, 0).copy()


FUSED = [  # (channels, paths, dmin, nd, weight, cap, outside, uniqueness, fit, p1, p2)
    (3, 4, 0, 24, 1.0, 20, 23, 30.0, 0, 18, 72),  # the defaults
    (3, 5, 2, 17, 1.25, 7, 40, 0.0, 1, 18, 72),
    (1, 8, 0, 33, 0.5, 20, 13, 10.0, 2, 8, 32),
    (3, 4, 1, 48, 2.0, 255, 62, 0.0, 0, 18, 300),
    (1, 4, 0, 16, 0.0, 20, 23, 30.0, 0, 8, 32),  # the outside cost alone
]


@pytest.mark.parametrize("config", FUSED)
def test_cost_row_by_row_in_the_aggregation_equals_the_cost_volume(config) -> None:
    # the fused path (sgm._cost_row with the planes and integer_term) against the cost volume
    # census_ad_volume fills, the matcher's previous route: the same maps, the same totals
    ch, paths, dmin, nd, weight, cap, outside, uniq, fit, p1, p2 = config
    h, w = 52, 90
    pl, pr = _pair(h, w, ch, seed=nd)
    grey_l, grey_r = pl.mean(axis=0).astype(np.uint8), pr.mean(axis=0).astype(np.uint8)
    cl, cr = _census(grey_l), _census(grey_r)
    crrev = sgm.reversed_right(cr, dmin, nd)
    vol = census_ad_volume(cl, cr, pl, pr, dmin, weight, cap, outside,
                           np.empty((h, w, nd), np.uint16))
    term = integer_term(ch, weight, cap, outside)
    assert term is not None
    args = (dmin, np.uint16(p1), np.uint16(p2), paths, uniq, fit, True, True)
    tot_vol, tot_rows = (np.empty((h, w, nd), np.uint16) for _ in range(2))
    want = sgm.match(cl, crrev, vol, tot_vol, *args)
    got = sgm.match(cl, crrev, sgm.NO_VOLUME, tot_rows, *args, pl,
                    reversed_planes(pr, dmin, nd), term)
    for a, b in zip(want, got):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(tot_vol, tot_rows)
    if paths != 5 and term[5] <= 255:  # each cost row made once, kept (uint8) for the other
        # direction
        kept = sgm.match(cl, crrev, sgm.NO_VOLUME, tot_rows, *args, pl,
                         reversed_planes(pr, dmin, nd), term, np.empty((h, w, nd), np.uint8))
        for a, b in zip(want, kept):
            np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(tot_vol, tot_rows)
    assert np.isfinite(want[0]).mean() > 0.4 and len(np.unique(want[0])) > 3


@pytest.mark.parametrize("ch", [1, 3])
@pytest.mark.parametrize("weight", [0.0, 0.3, 0.5, 1.0, 1.25, 2.0, 3.7, 8.0])
@pytest.mark.parametrize("cap", [0, 7, 20, 100, 255])
def test_integer_term_equals_the_volume_table_at_every_difference(ch, weight, cap) -> None:
    term = integer_term(ch, weight, cap, 23)
    table = term_table(ch, weight, cap)
    if term is None:  # the matcher then builds the volume: only this case here lacks a form
        assert (ch, weight) == (3, 0.3) and cap >= 20, (ch, weight, cap)
        return
    k = np.minimum(np.arange(256 * ch), term[1])
    np.testing.assert_array_equal((k * term[2] + term[3]) >> term[4], table)
    assert term[5] >= sgm.CENSUS_BITS + table.max()


def test_matcher_defaults_take_the_cost_row_by_row() -> None:
    # --matcher sgm's defaults have an integer form: no cost volume is built for them
    p = MatcherParams.for_matcher("sgm")
    assert integer_term(3, p.intensity_weight, p.intensity_cap, p.outside_cost) is not None
    assert integer_term(1, p.intensity_weight, p.intensity_cap, p.outside_cost) is not None


def test_the_defaults_term_takes_the_narrow_16_bit_path() -> None:
    """The own SGM's defaults (MATCHER_DEFAULTS) on three channels give the intensity term at
    sgm.NARROW_SHIFT, within 16 bits: sgm._cost_row's uint16 lanes (_term_row3), not the
    uint32 ones. integer_term tries that shift first, named once (sgm.NARROW_SHIFT); 979f477
    tried a literal 8 first, so a NARROW_SHIFT changed alone would silently leave the defaults
    on the wide path."""
    d = MATCHER_DEFAULTS["sgm"]
    term = integer_term(3, float(d["intensity_weight"]), d["intensity_cap"], d["outside_cost"])
    assert term is not None
    outside, kcap, a, b, shift, _ = (int(v) for v in term)
    assert shift == sgm.NARROW_SHIFT, term
    assert kcap * a + b < 0x10000, term  # the condition sgm._cost_row takes it on
