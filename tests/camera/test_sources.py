"""Replay and Minoru sources: pairing, skew, sizes and errors, on files the tests write."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from host.camera import discovery
from host.camera.minoru import MinoruSource
from host.camera.replay import ReplaySource
from host.camera.source import CameraError


def _video(path: Path, fps: float, n: int, size=(320, 240)) -> None:
    out = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), fps, size)
    for i in range(n):
        img = np.full((size[1], size[0], 3), (i * 7) % 255, np.uint8)
        cv2.putText(img, str(i), (20, 100), cv2.FONT_HERSHEY_SIMPLEX, 2, (255, 255, 255), 3)
        out.write(img)
    out.release()


def _files(left: Path, right: Path):
    paths = {"L": str(left), "R": str(right)}
    return lambda device: cv2.VideoCapture(paths[device])


def test_minoru_grabs_both_then_retrieves_and_pairs_in_time(tmp_path: Path) -> None:
    _video(tmp_path / "l.avi", 30, 30)
    _video(tmp_path / "r.avi", 30, 30)
    src = MinoruSource(devices=("L", "R"), open_capture=_files(tmp_path / "l.avi",
                                                               tmp_path / "r.avi"),
                       lock=False, stamps="driver")  # the files' times stand in for the driver's
    frames = [src.read() for _ in range(30)]
    with pytest.raises(CameraError, match="stopped delivering"):  # a camera never just ends
        src.read()
    assert src.dropped == 0
    assert all(f.skew_ms < 1 for f in frames)
    assert frames[1].t_left - frames[0].t_left == pytest.approx(1 / 30)


def test_minoru_drops_pairs_whose_skew_exceeds_the_bound(tmp_path: Path) -> None:
    _video(tmp_path / "l.avi", 30, 40)
    _video(tmp_path / "r.avi", 15, 20)  # the right sensor delivers half as often
    src = MinoruSource(devices=("L", "R"), open_capture=_files(tmp_path / "l.avi",
                                                               tmp_path / "r.avi"),
                       lock=False, stamps="driver")  # the files' times stand in for the driver's
    frames = []
    with pytest.raises(CameraError):  # the left stream ends first: a clean error, not a hang
        for f in src:
            frames.append(f)
    assert len(frames) >= 15 and src.dropped >= 15
    assert all(f.skew_ms <= src.max_skew_ms for f in frames)


def test_minoru_swap_exchanges_the_devices(tmp_path: Path) -> None:
    _video(tmp_path / "l.avi", 30, 3, (320, 240))
    _video(tmp_path / "r.avi", 30, 3, (320, 240))
    src = MinoruSource(devices=("L", "R"), swap=True,
                       open_capture=_files(tmp_path / "l.avi", tmp_path / "r.avi"), lock=False)
    assert src.devices == ("R", "L")


def test_minoru_not_found_and_unsupported_mode(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setattr(discovery, "SYSFS", tmp_path)
    with pytest.raises(CameraError, match="no camera minoru found"):
        MinoruSource()
    with pytest.raises(CameraError, match="not 640x360"):
        MinoruSource((640, 360), devices=("a", "b"))


def test_a_vanished_camera_is_a_clear_error() -> None:
    class Gone:
        def get(self, prop: int) -> float:
            return -1.0

        def set(self, prop: int, value: float) -> bool:
            return False

        def grab(self) -> bool:
            return False

        def release(self) -> None:
            pass

    src = MinoruSource(devices=("/dev/video0", "/dev/video2"), open_capture=lambda d: Gone(),
                       lock=False)
    with pytest.raises(CameraError, match="/dev/video0 stopped delivering frames"):
        src.read()


def test_replay_folder_of_pairs_and_mismatched_sizes(tmp_path: Path) -> None:
    for i in range(3):
        cv2.imwrite(str(tmp_path / f"left_{i:03d}.png"), np.zeros((24, 32, 3), np.uint8))
        cv2.imwrite(str(tmp_path / f"right_{i:03d}.png"), np.zeros((24, 32, 3), np.uint8))
    frames = list(ReplaySource(tmp_path, fps=10))
    assert len(frames) == 3 and max(frames[2].t_left, frames[2].t_right) == pytest.approx(0.2)
    cv2.imwrite(str(tmp_path / "right_001.png"), np.zeros((12, 16, 3), np.uint8))
    with pytest.raises(CameraError, match="differ in size: 32x24 vs 16x12"):
        list(ReplaySource(tmp_path))
    (tmp_path / "right_002.png").unlink()
    with pytest.raises(CameraError, match="no matching right_002.png"):
        ReplaySource(tmp_path)


def test_replay_two_videos(tmp_path: Path) -> None:
    _video(tmp_path / "left.avi", 30, 5)
    _video(tmp_path / "right.avi", 30, 5)
    assert len(list(ReplaySource(tmp_path))) == 5
