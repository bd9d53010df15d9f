"""Each own matcher's left-right check removes the occluded pixels and keeps the visible."""
from __future__ import annotations

import numpy as np
import pytest

from host.stereo import MatcherParams, compute_disparity
from host.stereo.synthetic import synthetic_scene

# (matcher, share of occluded pixels the plain map fills, share of visible pixels the
# checked map keeps): SGM's paths fill nearly every occluded pixel and keep more of the visible
CASES = [
    (MatcherParams(block_size=7, num_disparities=48), 0.8, 0.85),
    (MatcherParams(matcher="sgm", block_size=1, num_disparities=48, border="clip"), 0.95, 0.9),
]


@pytest.mark.parametrize("base,filled,kept", CASES, ids=["sad", "sgm"])
def test_lr_check_removes_occluded_pixels(base: MatcherParams, filled: float,
                                          kept: float) -> None:
    scene = synthetic_scene(seed=3, noise=0.5)
    plain = compute_disparity(scene.left, scene.right, base)
    checked = compute_disparity(scene.left, scene.right, base.replace(lr_check=1.0))
    occluded = scene.masks["all"] & ~scene.masks["nonocc"]
    assert occluded.sum() > 200
    assert np.isfinite(plain[occluded]).mean() > filled
    assert np.isnan(checked[occluded]).mean() > 0.6
    visible = scene.masks["nonocc"] & np.isfinite(plain)
    assert np.isfinite(checked[visible]).mean() > kept
