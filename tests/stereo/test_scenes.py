"""Scene loaders on small files written here, the default scene, and shared/data when present."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from host.errors import HostError
from host.stereo.pfm import read_pfm, write_pfm
from host.stereo.scenes import default_scene, load_scene, load_scenes


def _img(rng: np.random.Generator, h: int = 12, w: int = 16) -> np.ndarray:
    return rng.integers(0, 256, (h, w, 3), dtype=np.uint8)


def test_pfm_round_trip_keeps_orientation_and_inf(tmp_path: Path) -> None:
    a = np.arange(12, dtype=np.float32).reshape(3, 4)
    a[0, 0] = np.inf
    write_pfm(tmp_path / "a.pfm", a)
    b = read_pfm(tmp_path / "a.pfm")
    np.testing.assert_array_equal(a, b)


def test_pfm_truncated_is_a_clear_error(tmp_path: Path) -> None:
    (tmp_path / "t.pfm").write_bytes(b"Pf\n4 3\n-1.0\n" + b"\0" * 8)
    with pytest.raises(HostError, match="truncated"):
        read_pfm(tmp_path / "t.pfm")


def test_2003_layout_with_scale(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    cv2.imwrite(str(tmp_path / "im2.png"), _img(rng))
    cv2.imwrite(str(tmp_path / "im6.png"), _img(rng))
    gt = np.full((12, 16), 40, np.uint8)
    gt[0, 0] = 0
    cv2.imwrite(str(tmp_path / "disp2.png"), gt)
    s = load_scene(tmp_path)
    assert s.gt is not None and s.gt[1, 1] == 10.0 and np.isnan(s.gt[0, 0])
    assert load_scene(tmp_path, scale=8).gt[1, 1] == 5.0


def test_2005_layout_third_size_has_scale_3(tmp_path: Path) -> None:
    rng = np.random.default_rng(1)
    for name in ("view1.png", "view5.png"):
        cv2.imwrite(str(tmp_path / name), _img(rng, 10, 463))
    cv2.imwrite(str(tmp_path / "disp1.png"), np.full((10, 463), 90, np.uint8))
    s = load_scene(tmp_path)
    assert s.gt is not None and s.gt[5, 5] == 30.0


def test_2014_layout_reads_pfm_and_calib(tmp_path: Path) -> None:
    rng = np.random.default_rng(2)
    cv2.imwrite(str(tmp_path / "im0.png"), _img(rng))
    cv2.imwrite(str(tmp_path / "im1.png"), _img(rng))
    gt = np.full((12, 16), 17.25, np.float32)
    gt[3, 4] = np.inf
    write_pfm(tmp_path / "disp0GT.pfm", gt)
    (tmp_path / "calib.txt").write_text("cam0=[1 0 0; 0 1 0; 0 0 1]\nndisp=40\n")
    s = load_scene(tmp_path)
    assert s.gt is not None and s.gt[0, 0] == 17.25 and np.isnan(s.gt[3, 4])
    assert s.max_disparity == 39.0 and s.num_disparities(16) == 48


def test_ground_truth_of_another_size_is_refused(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    cv2.imwrite(str(tmp_path / "im2.png"), _img(rng))
    cv2.imwrite(str(tmp_path / "im6.png"), _img(rng))
    cv2.imwrite(str(tmp_path / "disp2.png"), np.ones((5, 5), np.uint8))
    with pytest.raises(HostError, match="ground truth 5x5 differs"):
        load_scene(tmp_path)


def test_missing_and_unknown_folders(tmp_path: Path) -> None:
    with pytest.raises(HostError, match="no such scene folder"):
        load_scene(tmp_path / "nope")
    with pytest.raises(HostError, match="not a scene folder"):
        load_scene(tmp_path)


def test_default_scene_is_motorcycle_with_ground_truth() -> None:
    s = default_scene()
    assert s.name == "motorcycle" and s.left.shape == s.right.shape
    assert s.gt is not None and 0.9 < np.isfinite(s.gt).mean() <= 1.0


def test_shared_middlebury_scenes(middlebury: Path) -> None:
    index = json.loads((middlebury / "index.json").read_text())["scenes"]
    scenes = {s.name: s for s in load_scenes([middlebury])}
    assert sorted(scenes) == sorted(e["scene"] for e in index)
    for e in index:
        s = scenes[e["scene"]]
        assert s.left.shape[:2] == (e["height"], e["width"]) and s.gt is not None
        assert {"nonocc", "all"} <= set(s.masks)
        assert s.masks["nonocc"].sum() < s.masks["all"].sum()
    for name in ("cones", "teddy"):
        s = scenes[name]
        assert s.left.shape[:2] == (375, 450)
        assert 50 < np.nanmax(s.gt) <= 55
        assert set(s.masks) == {"nonocc", "all", "disc"}
