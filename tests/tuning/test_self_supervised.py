"""The self-supervised objective scores disparity from a stereo pair alone."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from host.stereo import MatcherParams
from host.stereo.synthetic import synthetic_scene
from host.tuning.disparity_range import RangePolicy
from host.tuning.ground_truth import GroundTruthScore
from host.tuning.self_supervised import SelfSupervisedScore, score_of, terms_of_maps

from ..in_process import host


@pytest.fixture(scope="module")
def scene():
    return synthetic_scene(seed=5, width=240, height=160, max_disp=24, noise=1.0)


def test_the_true_disparity_scores_better_than_wrong_ones(scene) -> None:
    gt = np.nan_to_num(scene.gt, nan=float(np.nanmin(scene.gt)))
    true = score_of(terms_of_maps(scene.left, scene.right, gt))
    shifted = gt + 3
    assert score_of(terms_of_maps(scene.left, scene.right, shifted)) > true
    noisy = gt.copy()
    rng = np.random.default_rng(0)
    spots = rng.random(gt.shape) < 0.2
    noisy[spots] += rng.uniform(-6, 6, int(spots.sum()))
    t_noisy = terms_of_maps(scene.left, scene.right, noisy)
    t_true = terms_of_maps(scene.left, scene.right, gt)
    assert t_noisy["roughness"] > t_true["roughness"]
    assert t_noisy["hidden"] > t_true["hidden"] + 0.02
    assert score_of(t_noisy) > true
    holes = gt.copy()
    holes[:, ::4] = np.nan
    assert terms_of_maps(scene.left, scene.right, holes)["invalid"] >= 0.25


def test_the_true_disparity_wins_under_an_exposure_change(scene) -> None:
    gt = np.nan_to_num(scene.gt, nan=float(np.nanmin(scene.gt)))
    darker = np.clip(scene.right.astype(np.float32) * 0.6 + 10, 0, 255).astype(np.uint8)
    rng = np.random.default_rng(1)
    noisy = gt + np.where(rng.random(gt.shape) < 0.2, rng.uniform(-6, 6, gt.shape), 0)
    true = score_of(terms_of_maps(scene.left, darker, gt))
    for wrong in (gt + 2, gt - 2, noisy):
        assert score_of(terms_of_maps(scene.left, darker, wrong)) > true + 1


def test_scattered_disparities_leave_holes_in_the_rebuilt_right_view(scene) -> None:
    gt = np.nan_to_num(scene.gt, nan=float(np.nanmin(scene.gt)))
    rng = np.random.default_rng(2)
    noisy = gt + np.where(rng.random(gt.shape) < 0.2, rng.uniform(-6, 6, gt.shape), 0)
    t_true = terms_of_maps(scene.left, scene.right, gt)
    t_noisy = terms_of_maps(scene.left, scene.right, noisy)
    assert t_true["holes"] < 0.05  # only where the left view is occluded
    assert t_noisy["holes"] > t_true["holes"] + 0.05


def test_census_tells_a_flat_patch_from_a_dark_spot() -> None:
    from host.tuning.self_supervised import census

    flat = np.full((9, 9), 100, np.uint8)
    spot = flat.copy()
    spot[4, 4] = 60  # every neighbour brighter than the centre: a two-state census says 0 too
    a, b = census(flat, 3)[4, 4], census(spot, 3)[4, 4]
    assert int(a[0]) == int(a[1]) == 0
    assert int(b[0]) == 0 and int(b[1]) == (1 << 48) - 1


def test_a_map_with_no_disparity_pays_for_it(scene) -> None:
    gt = np.nan_to_num(scene.gt, nan=float(np.nanmin(scene.gt)))
    none = np.full_like(gt, np.nan)
    t = terms_of_maps(scene.left, scene.right, none)
    assert t["invalid"] == 1.0 and t["reconstruction"] == 0 and t["holes"] == 0
    assert score_of(t) > score_of(terms_of_maps(scene.left, scene.right, gt))


def test_reconstruction_is_robust_to_an_exposure_change(scene) -> None:
    gt = np.nan_to_num(scene.gt, nan=float(np.nanmin(scene.gt)))
    darker = np.clip(scene.right.astype(np.float32) * 0.6 + 10, 0, 255).astype(np.uint8)
    same = terms_of_maps(scene.left, scene.right, gt)["reconstruction"]
    dark = terms_of_maps(scene.left, darker, gt)["reconstruction"]
    assert abs(dark - same) < 0.02


def test_self_score_ranks_matchers_like_ground_truth_on_a_synthetic_scene(scene) -> None:
    rng = RangePolicy("coarse", 4).resolve(scene.left, scene.right)
    gt_rng = RangePolicy().resolve(scene.left, scene.right, gt=scene.gt)
    candidates = [MatcherParams(border="clip", block_size=w, lr_check=1.0, fill=True)
                  for w in (3, 9, 25)] + [MatcherParams(border="clip", block_size=9)]
    self_score = SelfSupervisedScore([(scene.left, scene.right)], [rng])
    truth = GroundTruthScore([scene], [gt_rng])
    s = [self_score(p)[0] for p in candidates]
    g = [truth(p)[0] for p in candidates]
    assert g[int(np.argmin(s))] <= min(g) + 0.25, (s, g)  # 3 and 9 px tie within 0.1 pt
    assert int(np.argmax(s)) == int(np.argmax(g)), (s, g)


def test_the_census_is_made_once_per_process_and_never_sent(scene) -> None:
    import pickle

    from host.tuning.backends import make_backend

    rng = RangePolicy("coarse", 4).resolve(scene.left, scene.right)
    score = SelfSupervisedScore([(scene.left, scene.right)], [rng])
    before = len(pickle.dumps(score))
    params = [MatcherParams(border="clip", block_size=w) for w in (5, 9)]
    local = [score(p) for p in params]
    assert len(pickle.dumps(score)) == before  # the census stays behind
    copy = pickle.loads(pickle.dumps(score))  # as a Ray task gets it, once per task
    assert copy.prepared() is score.prepared()  # ... and finds this process's census
    backend = make_backend(score, workers=2)
    try:
        assert backend.map(params) == local
    finally:
        backend.close()


def _tune(*argv: str) -> subprocess.CompletedProcess[str]:
    return host("tune", *argv)


def test_tune_on_replayed_frames_without_ground_truth(tmp_path, scene) -> None:
    import cv2

    from host.params_file import load_disparity_range, load_params

    frames = tmp_path / "frames"
    frames.mkdir()
    for i, seed in enumerate((5, 6)):
        s = synthetic_scene(seed=seed, width=160, height=120, max_disp=20, noise=1.0)
        cv2.imwrite(str(frames / f"left_{i:03d}.png"), s.left)
        cv2.imwrite(str(frames / f"right_{i:03d}.png"), s.right)
    out = tmp_path / "tuned.toml"
    r = _tune("--camera", f"replay:{frames}", "--objective", "self", "--method", "grid",
              "--block-sizes", "5:9", "--border", "clip", "--frames", "2", "--out", str(out))
    assert r.returncode == 0, r.stderr
    assert "self-supervised score" in r.stdout
    params, tuning = load_params(out)
    assert tuning["objective"] == "self-supervised" and tuning["scenes"] == ["replay-0",
                                                                             "replay-1"]
    assert params.block_size in (5, 7, 9)
    assert load_disparity_range(out)["policy"] == "coarse"


def test_tuning_on_a_camera_is_not_misled_by_unequal_sensor_gains(tmp_path) -> None:
    """The servo matches the right view's exposure to the left's before it matches; tuning on
    the camera's frames does the same, so a darker right sensor changes neither the pick nor
    (much) the score."""
    import cv2

    def tune_on(gain: float, name: str) -> tuple[str, float]:
        frames = tmp_path / name
        frames.mkdir()
        s = synthetic_scene(seed=7, width=160, height=120, max_disp=20, noise=1.0)
        right = np.clip(s.right.astype(np.float32) * gain + 12 * (gain != 1), 0, 255)
        cv2.imwrite(str(frames / "left_000.png"), s.left)
        cv2.imwrite(str(frames / "right_000.png"), right.astype(np.uint8))
        r = _tune("--camera", f"replay:{frames}", "--objective", "self", "--method", "grid",
                  "--space", "sad", "--block-sizes", "5:9", "--border", "clip", "--frames", "1",
                  "--json")
        assert r.returncode == 0, r.stderr
        out = json.loads(r.stdout)
        return json.dumps(out["best_params"], sort_keys=True), out["best_bad"]

    same, dark = tune_on(1.0, "same"), tune_on(0.6, "dark")
    assert dark[0] == same[0], (same, dark)
    assert abs(dark[1] - same[1]) < 1.0, (same, dark)


def test_tune_on_the_simulated_camera_with_its_depth_range(tmp_path) -> None:
    out = tmp_path / "tuned.toml"
    r = _tune("--camera", "sim", "--objective", "self", "--method", "random", "--iterations",
              "2", "--block-sizes", "7:11", "--frames", "1", "--range", "depth:0.8:3.5",
              "--out", str(out))
    assert r.returncode == 0, r.stderr
    assert 'policy = "depth:0.8:3.5"' in out.read_text()


@pytest.mark.parametrize("argv, message", [
    (["--camera", "sim"], "use --objective self"),
    (["--camera", "sim", "--objective", "self", "--frames", "0"], "--frames: must be >= 1"),
    (["--camera", "replay:/nonexistent", "--objective", "self"], "no such folder"),
    (["--camera", "replay:/x", "--objective", "self", "--range", "depth:1:3"], "no such"),
    (["--objective", "self", "--range", "depth:1:3"], "needs a calibration"),
    (["--objective", "self", "--range", "ground-truth"], "uses no ground truth"),
])
def test_camera_tuning_input_errors(argv, message) -> None:
    r = _tune(*argv)
    assert r.returncode == 2 and message in r.stderr and r.stderr.count("\n") == 1
