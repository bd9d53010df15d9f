"""A pair whose left and right views are swapped is told from a correct one, both ways round,
on the shared scenes and the simulated world's frames; a correct pair is never called swapped;
a recording's pairs are looked at without losing one, and swapped back with --swap-check auto."""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest

from host.camera.replay import ReplaySource
from host.camera.swapped import swap_verdict
from host.cli import main
from host.commands.swap_check import check_recorded
from host.errors import HostError
from host.sim.renderer import Renderer
from host.sim.world import World
from host.stereo.scenes import read_image

SCENES = ["aloe", "art", "cloth3", "cones", "dolls", "rocks1", "teddy", "tsukuba", "venus",
          "wood1"]


@pytest.mark.parametrize("scene", SCENES)
def test_a_shared_scene_is_correct_as_given_and_swapped_exchanged(middlebury: Path,
                                                                  scene: str) -> None:
    left = cv2.imread(str(middlebury / scene / "left.png"))
    right = cv2.imread(str(middlebury / scene / "right.png"))
    assert swap_verdict(left, right).conclusive and not swap_verdict(left, right).swapped
    assert swap_verdict(right, left).swapped


@pytest.mark.parametrize("seed, robot, size", [(0, True, (320, 240)), (1, False, (320, 240)),
                                              (2, True, (640, 480)), (3, False, (160, 120))])
def test_the_simulated_worlds_frames_are_correct_as_given_and_swapped_exchanged(
        seed: int, robot: bool, size: tuple[int, int]) -> None:
    pair = Renderer(World.for_size(*size, seed=seed)).frame(with_robot=robot)
    assert not swap_verdict(pair.left, pair.right).swapped
    assert swap_verdict(pair.right, pair.left).swapped


def test_a_pair_at_infinity_or_without_texture_is_never_swapped() -> None:
    rng = np.random.default_rng(0)
    far = rng.integers(0, 255, (240, 320), dtype=np.uint8)
    for left, right in ((far, far), (np.full((240, 320), 90, np.uint8),) * 2,
                        (far, np.roll(far, 1, axis=1)), (far, np.roll(far, 2, axis=1))):
        # all at infinity through a calibration 1 or 2 px the wrong way
        v = swap_verdict(left, right)
        assert not v.swapped, v


def _replay(folder: Path, frames: int, swapped: bool) -> None:
    renderer = Renderer(World.for_size(320, 240))
    folder.mkdir()
    for i in range(frames):
        pair = renderer.frame(with_robot=True)
        a, b = (pair.right, pair.left) if swapped else (pair.left, pair.right)
        cv2.imwrite(str(folder / f"left_{i:03d}.png"), a)
        cv2.imwrite(str(folder / f"right_{i:03d}.png"), b)


@pytest.mark.parametrize("swapped, policy", [(False, "refuse"), (True, "auto"),
                                             (True, "off")])
def test_a_checked_recording_hands_on_every_pair(tmp_path: Path, swapped: bool,
                                                 policy: str) -> None:
    _replay(tmp_path / "r", 4, swapped)
    args = argparse.Namespace(camera=f"replay:{tmp_path / 'r'}", swap_check=policy)
    with check_recorded(args, ReplaySource(tmp_path / "r")) as source:
        got = [f.left for f in source]
    # the left camera's views, in order; with off, the files' left_* as they are
    side = "right" if swapped and policy == "auto" else "left"
    want = [read_image(p) for p in sorted((tmp_path / "r").glob(f"{side}_*"))]
    assert len(got) == 4 and all(np.array_equal(g, w) for g, w in zip(got, want))


def test_a_swapped_recording_is_refused_before_any_pair_is_used(tmp_path: Path) -> None:
    _replay(tmp_path / "r", 2, True)
    args = argparse.Namespace(camera=f"replay:{tmp_path / 'r'}", swap_check="refuse")
    with pytest.raises(HostError, match="left and right look swapped"):
        check_recorded(args, ReplaySource(tmp_path / "r"))


def test_servo_on_a_swapped_replay_with_auto_finds_the_correct_target(tmp_path: Path,
                                                                      capsys) -> None:
    _replay(tmp_path / "ok", 6, False)
    _replay(tmp_path / "sw", 6, True)
    targets = []
    for name, extra in (("ok", []), ("sw", ["--swap-check", "auto"])):
        main(["servo", "--camera", f"replay:{tmp_path / name}", "--port", "emulator", *extra])
        err = capsys.readouterr().err
        targets.append([line for line in err.splitlines() if line.startswith("target:")])
        assert ("swapped them back" in err) == (name == "sw")
    assert targets[0] and targets[0] == targets[1]


def test_tune_self_on_a_swapped_scene_folder_is_refused(tmp_path: Path, middlebury: Path,
                                                        capsys) -> None:
    folder = tmp_path / "cones"
    shutil.copytree(middlebury / "cones", folder)
    (folder / "left.png").rename(folder / "was_left.png")
    (folder / "right.png").rename(folder / "left.png")
    (folder / "was_left.png").rename(folder / "right.png")
    code = main(["tune", str(folder), "--objective", "self", "--method", "grid"])
    err = capsys.readouterr().err
    assert code == 2 and "cones: left and right look swapped" in err, err
    assert err.count("\n") == 1
