"""The coarse range keeps a scene's background: shifted so the background lies at about 1 px,
or cropped so the background fills the view, no more than half a percent of the known nonocc
pixels fall below the range (issue 27 saw 41-42 % below on two held-out scenes; these cases,
built from the shared scenes, are where such a drop would show)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from host.stereo.scenes import load_scene
from host.tuning.disparity_range import coarse_range


def _below(left, right, gt, known) -> float:
    """Share (%) of the known pixels below the coarse range's low end."""
    lo, _ = coarse_range(left, right)
    return float((gt[known] < lo).mean() * 100)


@pytest.mark.parametrize("scene", ["cones", "aloe", "art", "tsukuba"])
def test_a_background_near_zero_disparity_stays_in_the_coarse_range(middlebury: Path,
                                                                    scene: str) -> None:
    s = load_scene(middlebury / scene)
    known = s.masks["nonocc"].astype(bool) & np.isfinite(s.gt)
    k = int(np.floor(np.percentile(s.gt[known], 0.5) - 1.0))  # left cropped by k: d - k
    w = s.left.shape[1]
    assert _below(s.left[:, k:], s.right[:, :w - k], s.gt[:, k:] - k, known[:, k:]) <= 0.5


@pytest.mark.parametrize("scene", ["cones", "teddy", "aloe", "art", "dolls", "wood1"])
def test_a_background_that_fills_the_view_stays_in_the_coarse_range(middlebury: Path,
                                                                    scene: str) -> None:
    s = load_scene(middlebury / scene)
    top = np.s_[: s.gt.shape[0] // 3]  # mostly the far wall or backdrop
    known = s.masks["nonocc"].astype(bool) & np.isfinite(s.gt)
    assert _below(s.left[top], s.right[top], s.gt[top], known[top]) <= 0.5
