"""The disparity range is derived from each scene by a policy, which params files store."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from host.cli import main
from host.errors import HostError
from host.params_file import load_disparity_range, load_params
from host.stereo import MatcherParams
from host.stereo.scenes import load_scene
from host.stereo.synthetic import synthetic_scene
from host.tuning.disparity_range import RangePolicy, _support, apply_range


def test_ground_truth_policy_covers_the_known_disparities_with_the_margin() -> None:
    gt = np.full((10, 200), np.nan, np.float32)
    gt[2:5, 10:20] = 12.3
    gt[6:8, 30:40] = 40.6
    lo, num = RangePolicy("ground-truth", 4).resolve(gt, gt, gt=gt)
    assert lo == 8 and lo + num - 1 == 45  # floor(12.3 - 4) .. ceil(40.6 + 4)


def test_ground_truth_range_is_robust_to_stray_pixels_and_uses_the_nonocc_region() -> None:
    rng = np.random.default_rng(0)
    gt = rng.uniform(21, 70, (100, 200)).astype(np.float32)
    gt[50, 50] = 3.7  # one stray known pixel widened a 21-70 px scene to 0-71
    lo, num = RangePolicy("ground-truth", 4).resolve(gt, gt, gt=gt)
    assert 16 <= lo <= 17 and 73 <= lo + num - 1 <= 74
    gt[:, :10] = 2.0  # known but occluded: outside the nonocc mask
    nonocc = np.ones(gt.shape, bool)
    nonocc[:, :10] = False
    lo, num = RangePolicy("ground-truth", 4).resolve(gt, gt, gt=gt, nonocc=nonocc)
    assert 16 <= lo <= 17


def test_depth_policy_maps_metres_to_pixels() -> None:
    img = np.zeros((10, 400), np.uint8)
    # focal 426 px, baseline 0.06 m: 0.5 m -> 51.1 px, 4 m -> 6.4 px
    lo, num = RangePolicy.parse("depth:0.5:4", 2).resolve(img, img, focal_baseline=426 * 0.06)
    assert lo == 4 and lo + num - 1 == 54


def test_fixed_policy_and_opencv_rounding() -> None:
    img = np.zeros((10, 400), np.uint8)
    assert RangePolicy.parse("fixed:40").resolve(img, img) == (0, 40)
    p = apply_range(MatcherParams(matcher="opencv-bm"), (3, 40))
    assert (p.min_disparity, p.num_disparities) == (3, 48)


def test_coarse_pass_finds_the_range_of_a_synthetic_scene() -> None:
    scene = synthetic_scene(seed=3, width=320, height=240, max_disp=30, noise=1.0)
    lo, num = RangePolicy("coarse", 2).resolve(scene.left, scene.right)
    true_lo, true_hi = np.nanmin(scene.gt), np.nanmax(scene.gt)
    assert lo <= true_lo and lo + num - 1 >= true_hi
    assert num < true_hi - true_lo + 30  # much tighter than the whole coarse search


def test_coarse_pass_covers_real_scenes_of_very_different_ranges(middlebury: Path) -> None:
    for name in ("tsukuba", "cones", "art"):
        scene = load_scene(middlebury / name)
        lo, num = RangePolicy("coarse", 4).resolve(scene.left, scene.right)
        valid = scene.gt[scene.masks["nonocc"] & np.isfinite(scene.gt)]
        lo_gt, hi_gt = np.percentile(valid, (0.5, 99.5))
        assert lo <= lo_gt and lo + num - 1 >= hi_gt, (name, lo, num, lo_gt, hi_gt)
        # tight at both ends: speckles of wrong matches and the border do not widen it
        assert lo >= lo_gt - 12 and num <= hi_gt - lo_gt + 16, (name, lo, num, lo_gt, hi_gt)


def test_confident_matches_need_the_support_of_their_neighbours() -> None:
    disp = np.tile(np.linspace(10, 20, 40, dtype=np.float32), (30, 1))  # a slanted plane
    disp[10, 10] = 55.0  # a speckle
    disp[20, 30] = np.nan
    support = _support(disp)
    assert support[10, 10] == 0
    assert support[15, 20] == 24 and support[10, 12] == 23  # beside the speckle
    assert support[20, 30] == 0 and support[20, 31] == 23


@pytest.mark.parametrize("text, message", [("nope", "unknown disparity range"),
                                           ("depth:4:1", "near < far"),
                                           ("fixed:x", "fixed:N"), ("fixed:0", "N > 0")])
def test_bad_policies_are_refused(text: str, message: str) -> None:
    with pytest.raises(HostError, match=message):
        RangePolicy.parse(text)


def _write_scene(d: Path, seed: int, max_disp: int) -> None:
    s = synthetic_scene(seed=seed, width=160, height=120, max_disp=max_disp, noise=2.0)
    d.mkdir()
    cv2.imwrite(str(d / "left.png"), s.left)
    cv2.imwrite(str(d / "right.png"), s.right)
    cv2.imwrite(str(d / "disp_left.png"), np.nan_to_num(s.gt * 4).astype(np.uint16))
    (d / "meta.json").write_text(json.dumps({"scene": d.name, "scale": 4}))


def test_params_file_stores_the_policy_and_eval_applies_it(tmp_path: Path, capsys) -> None:
    _write_scene(tmp_path / "near", 1, 30)
    _write_scene(tmp_path / "far", 2, 10)
    out = tmp_path / "p.toml"
    assert main(["tune", str(tmp_path), "--method", "grid", "--block-sizes", "5:9",
                 "--border", "clip", "--out", str(out), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    (lo_far, n_far), (lo_near, n_near) = result["ranges"]["far"], result["ranges"]["near"]
    assert lo_near + n_near > lo_far + n_far + 10  # each scene its own range
    assert "num_disparities" not in out.read_text()
    assert load_disparity_range(out) == {"policy": "ground-truth", "margin_px": 4.0}
    assert load_params(out)[0].block_size == result["best_params"]["block_size"]
    assert main(["eval", str(tmp_path), "--params", str(out), "--json"]) == 0
    bads = {r["scene"]: r["bad"] for r in json.loads(capsys.readouterr().out)["scenes"]}
    assert bads["near"] < 30  # the near scene's disparities above 10 px were searched


def test_leave_one_out_scores_each_scene_with_parameters_tuned_on_the_others(
        tmp_path: Path, capsys) -> None:
    for i, d in enumerate((30, 20, 12)):
        _write_scene(tmp_path / f"s{i}", i, d)
    assert main(["tune", str(tmp_path), "--method", "grid", "--block-sizes", "5:9",
                 "--border", "clip", "--cv", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    folds = result["leave_one_out"]
    assert sorted(folds) == ["s0", "s1", "s2"]
    for fold in folds.values():
        assert 0 <= fold["bad"] <= 100 and fold["params"]["block_size"] in (5, 7, 9)
    # s2 left out: the window tuned on s0 and s1 scores on s2 what eval says it does
    capsys.readouterr()
    assert main(["eval", str(tmp_path / "s2"), "--border", "clip", "--block-size",
                 str(folds["s2"]["params"]["block_size"]), "--num-disparities",
                 str(sum(result["ranges"]["s2"])), "--min-disparity",
                 str(result["ranges"]["s2"][0]), "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["scenes"][0]
    assert row["bad"] == pytest.approx(folds["s2"]["bad"], abs=1e-6)
