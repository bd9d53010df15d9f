"""Quality on real Middlebury data (skipped without shared/data)."""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest

from host.stereo import MatcherParams, compute_disparity, evaluate, load_scene
from host.stereo.metrics import middlebury


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


# The strongest OpenCV SGBM found on the ten shared scenes (issue 24): HH4, block 1, grey,
# uniqueness 10, speckle 100/2, LR 1, fill, median 5
STRONGEST_SGBM = MatcherParams(matcher="opencv-sgbm", mode="hh4", block_size=1, colour=False,
                               uniqueness_ratio=10, speckle_window_size=100, speckle_range=2,
                               lr_check=1.0, fill=True, median=5)
SEMIGLOB = {"tsukuba": (3.26, 3.96), "venus": (1.00, 1.57), "teddy": (6.02, 12.2),
            "cones": (3.06, 9.75)}  # Hirschmueller's SemiGlob, Middlebury v2 table, nonocc/all


@functools.cache
def _scores(root: str, name: str, params: MatcherParams, noise: float = 0.0
            ) -> tuple[float, float]:
    """(nonocc, all) bad % at 1 px of params on a shared scene, at its ground-truth range;
    noise: Gaussian sigma added to the right image (seed 0)."""
    scene = load_scene(Path(root) / name)
    right = scene.right
    if noise:
        rng = np.random.default_rng(0)
        right = np.clip(right + rng.normal(0, noise, right.shape), 0, 255).astype(np.uint8)
    multiple = 16 if params.matcher.startswith("opencv") else 1
    p = params.replace(num_disparities=scene.num_disparities(multiple))
    s = middlebury(compute_disparity(scene.left, right, p), scene.gt, scene.masks)
    return s["nonocc"].bad, s["all"].bad


def _names(root: Path) -> list[str]:
    return sorted(d.name for d in root.iterdir() if (d / "meta.json").exists())


def test_sgm_defaults_beat_the_strongest_sgbm_by_1_5_points_on_the_ten(middlebury: Path
                                                                          ) -> None:
    names = _names(middlebury)
    assert len(names) == 10
    own = np.mean([_scores(str(middlebury), n, MatcherParams.for_matcher("sgm")) for n in names],
                  axis=0)
    ocv = np.mean([_scores(str(middlebury), n, STRONGEST_SGBM) for n in names], axis=0)
    # measured: own 2.81 / 7.30, SGBM 6.02 / 12.28
    assert own[0] <= ocv[0] - 1.5 and own[1] <= ocv[1] - 1.5, (own, ocv)


def test_sgm_adaptive_p2_beats_a_fixed_p2_on_the_ten(middlebury: Path) -> None:
    # the defaults' P2 falls with the grey step along each path (p2_adapt); it is the fall
    # that helps, not its larger base: measured 2.81 / 7.30 against 2.93 / 7.43 with the fixed
    # P2 72 and 3.17 / 7.65 with a fixed P2 of the base, 128
    names = _names(middlebury)
    p = MatcherParams.for_matcher("sgm")
    own = np.mean([_scores(str(middlebury), n, p) for n in names], axis=0)
    fixed = np.mean([_scores(str(middlebury), n, p.replace(p2_adapt=0.0)) for n in names],
                    axis=0)
    assert own[0] <= fixed[0] - 0.05 and own[1] <= fixed[1] - 0.05, (own, fixed)


def test_sgm_defaults_at_or_below_semiglob_on_the_classic_scenes(middlebury: Path) -> None:
    # measured: Tsukuba 2.59 / 3.74, Venus 0.78 / 1.574, Teddy 4.96 / 11.02, Cones 3.01 / 8.79;
    # the table gives two decimals, so Venus's all is at SemiGlob's 1.57 to its precision
    got = {n: _scores(str(middlebury), n, MatcherParams.for_matcher("sgm")) for n in SEMIGLOB}
    for name, (nonocc, whole) in SEMIGLOB.items():
        assert got[name][0] <= nonocc and got[name][1] < whole + 0.01, (name, got[name])


@pytest.mark.parametrize("name", ["aloe", "art", "cones", "dolls", "teddy"])
def test_sgm_leaves_no_streaks_that_pass_lr_in_the_left_strip(middlebury: Path, name: str
                                                               ) -> None:
    # the strip x < d that the right camera does not see: what survives the LR check there
    # (before fill) must be right; with the census maximum as the outside cost 1.6-3.3 % of
    # it was a wrong disparity that passed, with the former documented setup 4-8.5 %
    scene = load_scene(middlebury / name)
    p = MatcherParams.for_matcher("sgm").replace(num_disparities=scene.num_disparities(1),
                                                 fill=False, median=0)
    disp = compute_disparity(scene.left, scene.right, p)
    x = np.arange(disp.shape[1])[None, :]
    strip = np.isfinite(scene.gt) & (x < scene.gt)
    wrong = np.isfinite(disp) & ~(np.abs(disp - scene.gt) <= 1.0)
    assert strip.sum() > 1000
    assert wrong[strip].mean() < 0.01, wrong[strip].mean()


def test_sgm_defaults_stay_ahead_of_sgbm_under_noise(middlebury: Path) -> None:
    # Gaussian sigma 5 on the right image (seed 0), Cones and Venus
    for name in ("cones", "venus"):
        clean = _scores(str(middlebury), name, MatcherParams.for_matcher("sgm"))
        noisy = _scores(str(middlebury), name, MatcherParams.for_matcher("sgm"), 5.0)
        ocv = _scores(str(middlebury), name, STRONGEST_SGBM, 5.0)
        assert noisy[0] > clean[0]  # the noise is there
        assert noisy[1] < ocv[1] + 1.5, (name, noisy, ocv)


@pytest.mark.parametrize("change", ["gain", "gamma"])
def test_sgm_defaults_keep_census_indifference_to_gain_and_gamma(middlebury: Path,
                                                                 change: str) -> None:
    # a right camera with gain 0.7 or gamma 1.5: the intensity term sees the right image
    # through the histogram table, so the map stays near the clean one (measured on Cones,
    # nonocc: 3.01 clean, 3.11 gain, 3.07 gamma; grey without the table 3.22 clean, 7.2 / 7.3),
    # while the strongest SGBM, which compares intensities, falls apart
    scene = load_scene(middlebury / "cones")
    right = scene.right.astype(np.float32)
    right = (right * 0.7 if change == "gain" else 255 * (right / 255) ** 1.5).astype(np.uint8)

    def bad(params: MatcherParams, image: np.ndarray) -> float:
        multiple = 16 if params.matcher.startswith("opencv") else 1
        p = params.replace(num_disparities=scene.num_disparities(multiple))
        return evaluate(compute_disparity(scene.left, image, p), scene.gt,
                        scene.masks["nonocc"]).bad

    own = MatcherParams.for_matcher("sgm")
    clean, changed = bad(own, scene.right), bad(own, right)
    assert changed < clean + 0.5, (clean, changed)
    assert bad(STRONGEST_SGBM, right) > changed + 5


def test_sgm_defaults_with_subpixel_keep_the_lr_check_meaningful(middlebury: Path) -> None:
    # LR 0 compares whole pixels; a sub-pixel left map is compared by its winner (within half
    # a pixel), not rejected wholesale (it was: 48.6 % bad on Cones, all of it filled)
    whole = _scores(str(middlebury), "cones", MatcherParams.for_matcher("sgm"))
    sub = _scores(str(middlebury), "cones", MatcherParams.for_matcher("sgm").replace(
        subpixel=True))
    assert sub[0] < whole[0] + 0.5, (whole, sub)
