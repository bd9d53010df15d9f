"""Sub-pixel fits: exact on their own cost models, and the equiangular fit unbiased on SAD."""

from __future__ import annotations

import numpy as np
import pytest

from host.stereo import MatcherParams, compute_disparity
from host.stereo.subpixel import FIT_EQUIANGULAR, FIT_NONE, FIT_PARABOLA, fit_offset
from host.stereo.synthetic import Layer, random_texture, render_pair


@pytest.mark.parametrize("x0", [-0.45, -0.2, 0.0, 0.1, 0.37])
def test_each_fit_finds_the_minimum_of_its_own_model(x0: float) -> None:
    v = [3.0 * abs(t - x0) + 5.0 for t in (-1, 0, 1)]  # an L1 (SAD-like) cost
    p = [2.0 * (t - x0) ** 2 + 5.0 for t in (-1, 0, 1)]  # an L2 (SSD-like) cost
    # samples at index -1, 0, +1: the minimum sits at index offset
    assert fit_offset(v[0], v[1], v[2], FIT_EQUIANGULAR) == pytest.approx(x0)
    assert fit_offset(p[0], p[1], p[2], FIT_PARABOLA) == pytest.approx(x0)
    assert fit_offset(v[0], v[1], v[2], FIT_NONE) == 0.0


def test_flat_costs_give_no_offset() -> None:
    assert fit_offset(4.0, 4.0, 4.0, FIT_EQUIANGULAR) == 0.0
    assert fit_offset(4.0, 4.0, 4.0, FIT_PARABOLA) == 0.0


def _mean_error(fit: str, d: float) -> float:
    rng = np.random.default_rng(1)
    tex = random_texture(rng, 90, 240, sigma=1.2)
    scene = render_pair([Layer(d, tex, margin=40)], 160, 90, noise=0.0)
    disp = compute_disparity(scene.left, scene.right, MatcherParams(
        block_size=9, num_disparities=32, border="clip", subpixel_fit=fit))
    return float(np.nanmean(disp[10:-10, 30:-10] - d))


@pytest.mark.parametrize("d", [13.3, 13.7])
def test_equiangular_fit_does_not_pull_sad_to_whole_pixels(d: float) -> None:
    # the parabola on an L1 cost locks toward the nearest integer; the V fit does not
    v = _mean_error("equiangular", d)
    p = _mean_error("parabola", d)
    toward_integer = np.sign(round(d) - d)
    assert abs(v) < 0.05
    assert p * toward_integer > 0.07


@pytest.mark.parametrize("matcher", ["ssd", "ncc"])
def test_block_matchers_use_the_fit_they_are_given(matcher: str) -> None:
    # SSD and NCC go through block_matching's kernel: the fit named in the params is the one
    # applied (equiangular and parabola differ off whole pixels), and none gives whole pixels
    rng = np.random.default_rng(2)
    tex = random_texture(rng, 90, 240, sigma=1.2)
    scene = render_pair([Layer(13.3, tex, margin=40)], 160, 90, noise=0.0)
    maps = {fit: compute_disparity(scene.left, scene.right, MatcherParams(
        matcher=matcher, block_size=9, num_disparities=32, border="clip", subpixel_fit=fit))
        for fit in ("parabola", "equiangular")}
    whole = compute_disparity(scene.left, scene.right, MatcherParams(
        matcher=matcher, block_size=9, num_disparities=32, border="clip", subpixel=False))
    inner = np.s_[10:-10, 30:-10]
    assert not np.allclose(maps["parabola"][inner], maps["equiangular"][inner], equal_nan=True)
    assert np.all(np.isnan(whole[inner]) | (whole[inner] == np.round(whole[inner])))
