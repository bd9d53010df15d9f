"""host capture: the folder appears only once the camera delivers, a manifest (camera, mode,
times) sits beside the pairs, and a replay of the folder keeps the recorded times."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import pytest

from host.camera import discovery
from host.camera.replay import ReplaySource
from host.camera.source import CameraError
from host.cli import main
from host.stereo.synthetic import synthetic_scene

from .fake_capture import FakeCapture, sensor_controls
from .fake_sysfs import add_minoru

SCENE = synthetic_scene(3)


def _live_minoru(tmp_path: Path, monkeypatch) -> None:
    """A Minoru in a fake sysfs whose sensors are fake captures stamped on a 30 fps clock."""
    add_minoru(tmp_path / "sys", "1-1", first_node=0)
    monkeypatch.setattr(discovery, "SYSFS", tmp_path / "sys")
    views = {"/dev/video2": SCENE.left, "/dev/video0": SCENE.right}
    offset = {"/dev/video2": 0.0, "/dev/video0": 3.0}

    def open_capture(device: str) -> FakeCapture:
        return FakeCapture([views[device]] * 60, sensor_controls(120, 8, 4500),
                           stamp=lambda i: 5000.0 + i * 1000 / 30 + offset[device])

    monkeypatch.setattr("host.camera.live.open_v4l2", open_capture)


def test_capture_writes_pairs_and_a_manifest_of_camera_mode_and_times(tmp_path, monkeypatch,
                                                                       capsys) -> None:
    _live_minoru(tmp_path, monkeypatch)
    out = tmp_path / "shots"
    assert main(["capture", "--camera", "minoru:1-1", "--count", "3", "--interval", "0",
                 "--timestamps", "driver", "--out", str(out)]) == 0
    assert "left/right skew over" in capsys.readouterr().err
    doc = json.loads((out / "manifest.json").read_text())
    cam = doc["camera"]
    assert cam["camera"] == "minoru:1-1" and cam["devices"] == ["/dev/video2", "/dev/video0"]
    assert cam["asked"] == "YUYV 320x240 at 30 fps, 1 buffer"
    assert cam["granted"] == ["YUYV 320x240 at 30 fps, 1 buffer"] * 2
    assert cam["locked"] == {"exposure": 120, "gain": 8, "white balance": 4500}
    assert cam["timestamps"] == ["driver", "driver"] and "monotonic" in doc["clock"]
    assert [p["left"] for p in doc["pairs"]] == ["left_000.png", "left_001.png", "left_002.png"]
    assert all(p["t_right"] - p["t_left"] == pytest.approx(0.003) for p in doc["pairs"])
    # a replay of the folder keeps the recorded times and says what it replays
    replay = ReplaySource(out)
    frames = list(replay)
    assert [f.t_left for f in frames] == [p["t_left"] for p in doc["pairs"]]
    assert replay.describe()["recorded_from"]["camera"] == "minoru:1-1"
    assert (cv2.imread(str(out / "left_000.png"), cv2.IMREAD_GRAYSCALE) == SCENE.left).all()


def test_no_folder_when_the_camera_does_not_open(tmp_path, monkeypatch, capsys) -> None:
    monkeypatch.setattr(discovery, "SYSFS", tmp_path / "empty")
    out = tmp_path / "shots"
    assert main(["capture", "--count", "2", "--out", str(out)]) == 2
    assert "no camera minoru found" in capsys.readouterr().err
    assert not out.exists()


def test_a_folder_that_holds_pairs_is_not_written_over(tmp_path, monkeypatch, capsys) -> None:
    _live_minoru(tmp_path, monkeypatch)
    out = tmp_path / "shots"
    out.mkdir()
    (out / "left_000.png").write_bytes(b"the user's")
    assert main(["capture", "--camera", "minoru", "--count", "1", "--out", str(out)]) == 2
    assert "already holds pairs" in capsys.readouterr().err
    assert (out / "left_000.png").read_bytes() == b"the user's"


def test_a_replay_from_a_capture_of_a_replay(tmp_path: Path) -> None:
    src = tmp_path / "src"
    src.mkdir()
    for i in range(4):
        cv2.imwrite(str(src / f"left_{i:03d}.png"), SCENE.left)
        cv2.imwrite(str(src / f"right_{i:03d}.png"), SCENE.right)
    out = tmp_path / "again"
    assert main(["capture", "--camera", f"replay:{src}", "--count", "2", "--interval", "0",
                 "--out", str(out)]) == 0
    doc = json.loads((out / "manifest.json").read_text())
    assert doc["camera"]["camera"] == f"replay:{src}" and len(doc["pairs"]) == 2
    assert main(["capture", "--camera", f"replay:{src}", "--count", "9", "--interval", "0",
                 "--out", str(tmp_path / "short")]) == 2
    # what was saved before the camera ended stays, with a manifest that lists exactly it
    short = json.loads((tmp_path / "short" / "manifest.json").read_text())
    assert len(short["pairs"]) == 4 == len(list((tmp_path / "short").glob("left_*")))


def test_a_broken_manifest_is_one_line(tmp_path: Path) -> None:
    cv2.imwrite(str(tmp_path / "left_000.png"), SCENE.left)
    cv2.imwrite(str(tmp_path / "right_000.png"), SCENE.right)
    (tmp_path / "manifest.json").write_text("{not json")
    with pytest.raises(CameraError, match=r"manifest.json: not a capture manifest \("):
        ReplaySource(tmp_path)
