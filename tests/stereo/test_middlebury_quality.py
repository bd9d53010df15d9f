"""Quality on real Middlebury data (skipped without shared/data)."""

from __future__ import annotations

from pathlib import Path

from host.stereo import MatcherParams, compute_disparity, evaluate, load_scene


def test_plain_sad_on_cones_scores_below_14_percent(middlebury: Path) -> None:
    scene = load_scene(middlebury / "cones")
    best = min(
        evaluate(compute_disparity(scene.left, scene.right,
                                   MatcherParams(block_size=w, num_disparities=64,
                                                 border="clip")),
                 scene.gt, scene.masks["nonocc"]).bad
        for w in (7, 9, 11, 13))
    assert best < 14.0


def test_opencv_bm_sanity_matches_the_data_readme(middlebury: Path) -> None:
    # shared/data/middlebury/cones/meta.json: StereoBM(64, 9) with OpenCV's defaults on grey,
    # bad over valid pixels = 5.74%, invalid 24.75%
    scene = load_scene(middlebury / "cones")
    disp = compute_disparity(scene.left, scene.right,
                             MatcherParams(matcher="opencv-bm", block_size=9, num_disparities=64,
                                           texture_threshold=10, pre_filter_cap=31,
                                           uniqueness_ratio=15))
    valid = disp == disp
    region = (scene.gt == scene.gt) & valid
    bad = float((abs(disp - scene.gt) > 1.0)[region].mean())
    assert abs(bad - 0.0574) < 0.005
    assert abs((1 - valid.mean()) - 0.2475) < 0.01
