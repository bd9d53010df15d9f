"""host eval / host disparity as a user runs them: exit codes, table, JSON, one-line errors."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import cv2
import numpy as np
import pytest

from host.cli import main
from host.stereo import MatcherParams, compute_disparity, evaluate, load_scene
from host.stereo.metrics import round_submission
from host.stereo.synthetic import synthetic_scene

from .in_process import host


def run(*argv: str) -> subprocess.CompletedProcess[str]:
    return host(*argv)  # in this process: no Python start-up per call


@pytest.fixture()
def pair(tmp_path: Path) -> tuple[Path, Path]:
    s = synthetic_scene(seed=5, width=160, height=120, max_disp=24)
    cv2.imwrite(str(tmp_path / "l.png"), s.left)
    cv2.imwrite(str(tmp_path / "r.png"), s.right)
    return tmp_path / "l.png", tmp_path / "r.png"


def test_disparity_writes_picture_and_raw_map(pair: tuple[Path, Path], tmp_path: Path) -> None:
    out, npy = tmp_path / "d.png", tmp_path / "d.npy"
    assert main(["disparity", str(pair[0]), str(pair[1]), "-o", str(out), "--npy", str(npy),
                 "--num-disparities", "32", "--block-size", "7"]) == 0
    pic = cv2.imread(str(out))
    raw = np.load(npy)
    assert raw.shape == (120, 160) and raw.dtype == np.float32
    assert pic.shape[0] > 120 and pic.shape[1] >= 160  # the map, and the legend below it
    assert (pic[:120, :160][np.isnan(raw)] == 0).all()


def test_eval_json_has_the_documented_keys(middlebury: Path, capsys) -> None:
    assert main(["eval", str(middlebury / "cones"), "--json", "--border", "clip"]) == 0
    out = json.loads(capsys.readouterr().out)
    row = out["scenes"][0]
    assert set(row) == {"scene", "bad", "bad_nonocc", "bad_disc", "rms", "density", "ms"}
    assert row["scene"] == "cones" and 0 < row["bad_nonocc"] < row["bad"] < 100
    assert 0 < row["bad_disc"] < 100


def test_eval_scores_middlebury_regions_by_their_masks(middlebury: Path, capsys) -> None:
    # Venus has all.png: its "all" region is not every pixel with known ground truth
    scene = load_scene(middlebury / "venus")
    argv = ["eval", str(middlebury / "venus"), "--json", "--matcher", "sad", "--block-size", "7",
            "--border", "clip"]
    assert main(argv) == 0
    row = json.loads(capsys.readouterr().out)["scenes"][0]
    p = MatcherParams(matcher="sad", block_size=7, border="clip",
                      num_disparities=scene.num_disparities(1))
    disp = compute_disparity(scene.left, scene.right, p)
    by_mask = {k: evaluate(disp, scene.gt, scene.masks[k]).bad for k in ("nonocc", "all", "disc")}
    assert row["bad"] == pytest.approx(by_mask["all"], abs=1e-9)
    assert row["bad_nonocc"] == pytest.approx(by_mask["nonocc"], abs=1e-9)
    assert row["bad_disc"] == pytest.approx(by_mask["disc"], abs=1e-9)
    assert abs(by_mask["all"] - evaluate(disp, scene.gt).bad) > 0.3  # the mask matters here
    assert by_mask["disc"] > by_mask["all"] > by_mask["nonocc"]
    assert main([*argv, "--round8"]) == 0
    rounded = json.loads(capsys.readouterr().out)["scenes"][0]
    assert rounded["bad"] == pytest.approx(
        evaluate(round_submission(disp, 8.0), scene.gt, scene.masks["all"]).bad, abs=1e-9)
    assert rounded["bad"] != row["bad"]


def test_eval_default_scene_prints_a_table_with_null_nonocc(capsys) -> None:
    assert main(["eval", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["scenes"][0]
    assert row["scene"] == "motorcycle" and row["bad_nonocc"] is None and row["bad_disc"] is None
    assert main(["eval", "--block-size", "11"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1].split() == ["scene", "bad%", "nonocc%", "disc%", "rms", "density%", "ms"]
    assert lines[2].split()[0] == "motorcycle" and lines[2].split()[2:4] == ["-", "-"]
    assert main(["eval", "--round8"]) == 2  # a float (PFM) ground truth has no 8-bit scale
    assert "no 8-bit ground-truth scale" in capsys.readouterr().err


@pytest.mark.parametrize("argv, message", [
    (["--block-size", "8"], "block size must be odd"),
    (["--block-size", "301"], "out of range"),
    (["--num-disparities", "900"], "wider than the image"),
    (["--matcher", "opencv-bm", "--num-disparities", "40"], "divisible by 16"),
])
def test_bad_matcher_options_are_one_line_errors(pair: tuple[Path, Path], tmp_path: Path,
                                                 argv: list[str], message: str) -> None:
    r = run("disparity", str(pair[0]), str(pair[1]), "-o", str(tmp_path / "o.png"), *argv)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and message in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "o.png").exists()


def test_missing_and_mismatched_images(pair: tuple[Path, Path], tmp_path: Path) -> None:
    r = run("disparity", str(tmp_path / "none.png"), str(pair[1]), "-o", str(tmp_path / "o.png"))
    assert r.returncode == 2 and "none.png: no such file" in r.stderr
    small = tmp_path / "small.png"
    cv2.imwrite(str(small), np.zeros((50, 60), np.uint8))
    r = run("disparity", str(pair[0]), str(small), "-o", str(tmp_path / "o.png"))
    assert r.returncode == 2 and "differ in size" in r.stderr
    (tmp_path / "junk.png").write_bytes(b"not an image")
    r = run("disparity", str(tmp_path / "junk.png"), str(pair[1]), "-o", str(tmp_path / "o.png"))
    assert r.returncode == 2 and "not a readable image" in r.stderr


def test_eval_refuses_a_scene_without_ground_truth(tmp_path: Path) -> None:
    for name in ("im0.png", "im1.png"):
        cv2.imwrite(str(tmp_path / name), np.zeros((40, 60), np.uint8))
    r = run("eval", str(tmp_path))
    assert r.returncode == 2 and "no ground truth" in r.stderr


def test_params_file_feeds_eval(tmp_path: Path, capsys) -> None:
    from host.params_file import load_params, save_params
    from host.stereo import MatcherParams

    path = tmp_path / "p.toml"
    save_params(path, MatcherParams(matcher="ncc", block_size=7, lr_check=1.0),
                {"method": "grid", "scenes": ["x"]})
    params, tuning = load_params(path)
    assert params.matcher == "ncc" and params.lr_check == 1.0 and tuning["method"] == "grid"
    assert main(["eval", "--params", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["matcher"]["block_size"] == 7
    path.write_text("[matcher]\nblock_size = 'x'\n")
    assert main(["eval", "--params", str(path)]) == 2


def test_matcher_sgm_alone_gives_its_measured_defaults(middlebury: Path, capsys) -> None:
    tsukuba = str(middlebury / "tsukuba")
    assert main(["eval", tsukuba, "--json", "--matcher", "sgm"]) == 0
    got = json.loads(capsys.readouterr().out)["matcher"]
    assert got == MatcherParams.for_matcher("sgm").to_dict()
    assert got["paths"] == 4 and got["block_size"] == 1 and got["fill"] is True
    assert main(["eval", tsukuba, "--json", "--matcher", "sgm", "--paths", "8", "--lr-check",
                 "off", "--no-fill", "--median", "0"]) == 0
    got = json.loads(capsys.readouterr().out)["matcher"]
    assert got["paths"] == 8 and "lr_check" not in got and got["fill"] is False
    assert got["median"] == 0
    r = run("eval", tsukuba, "--matcher", "sgm", "--paths", "6")
    assert r.returncode == 2 and "--paths" in r.stderr


def test_params_file_without_a_range_keeps_the_scenes_range_policy(middlebury: Path,
                                                                    tmp_path: Path,
                                                                    capsys) -> None:
    cones = str(middlebury / "cones")
    path = tmp_path / "p.toml"
    path.write_text('[matcher]\nmatcher = "sad"\nblock_size = 7\nborder = "clip"\n')
    assert main(["eval", cones, "--json", "--params", str(path)]) == 0
    from_file = json.loads(capsys.readouterr().out)["scenes"][0]["bad"]
    assert main(["eval", cones, "--json", "--block-size", "7", "--border", "clip"]) == 0
    scene_policy = json.loads(capsys.readouterr().out)["scenes"][0]["bad"]
    assert from_file == scene_policy
    # a file that fixes the range keeps it: 16 disparities are far too few for Cones
    path.write_text(path.read_text() + "num_disparities = 16\n")
    assert main(["eval", cones, "--json", "--params", str(path)]) == 0
    assert json.loads(capsys.readouterr().out)["scenes"][0]["bad"] > scene_policy + 20
