"""--record on host capture and host view: every pair the camera gave, as it gave it; a file
that exists is never overwritten."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

pytest.importorskip("rosbags")

from rosbags.highlevel import AnyReader  # noqa: E402

from host.sim.renderer import Renderer  # noqa: E402
from host.sim.world import World  # noqa: E402

from ..in_process import host  # noqa: E402


@pytest.fixture(scope="module")
def src(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Three rendered pairs, the robot nearer in each, as a folder for --camera replay:."""
    folder = tmp_path_factory.mktemp("src")
    renderer = Renderer(World())
    for i in range(3):
        renderer.world.robot.z_m -= 0.05  # each pair its own
        pair = renderer.frame(with_robot=True)
        cv2.imwrite(str(folder / f"left_{i:03d}.png"), pair.left)
        cv2.imwrite(str(folder / f"right_{i:03d}.png"), pair.right)
    return folder


def _read(path: Path) -> dict[str, list]:
    out: dict[str, list] = {}
    with AnyReader([path]) as reader:
        for conn, _, raw in reader.messages():
            out.setdefault(conn.topic, []).append(reader.deserialize(raw, conn.msgtype))
    return out


def _host(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "host", *args], capture_output=True, text=True,
                          timeout=300)


def _image(msg) -> np.ndarray:
    data = np.frombuffer(bytes(msg.data), np.uint8).reshape(msg.height, msg.step)
    return data[:, :msg.width * (3 if msg.encoding == "bgr8" else 1)].reshape(
        msg.height, msg.width, -1).squeeze()


def test_capture_records_every_pair(src: Path, tmp_path: Path) -> None:
    rec = tmp_path / "capture.mcap"
    r = _host("capture", "--camera", f"replay:{src}", "--count", "3", "--interval", "0",
              "--out", str(tmp_path / "out"), "--record", str(rec))
    assert r.returncode == 0, r.stderr
    topics = _read(rec)
    assert len(topics["/stereo/left/image_raw"]) == len(topics["/stereo/right/camera_info"]) == 3
    for side in ("left", "right"):  # as the replay read them (BGR)
        for i, msg in enumerate(topics[f"/stereo/{side}/image_raw"]):
            assert np.array_equal(_image(msg), cv2.imread(str(src / f"{side}_{i:03d}.png")))
    assert "/stereo/disparity" not in topics  # capture computes none


def test_view_records_the_maps_it_showed(src: Path, tmp_path: Path) -> None:
    rec = tmp_path / "view.mcap"
    r = _host("view", "--camera", f"replay:{src}", "--border", "clip", "--num-disparities", "48",
              "--duration", "4", "--record", str(rec))
    assert r.returncode == 0, r.stderr
    topics = _read(rec)
    assert len(topics["/stereo/disparity"]) == len(topics["/stereo/left/image_raw"]) == 3
    msg = topics["/stereo/disparity"][0]
    assert (msg.min_disparity, msg.max_disparity) == (0, 48)
    assert msg.valid_window.height == msg.image.height  # the whole map
    phases = [s.message for d in topics["/diagnostics"] for s in d.status if s.name == "servo"]
    assert phases == ["view: no robot: looking only"] * 3


def test_an_existing_recording_is_never_overwritten(tmp_path: Path) -> None:
    rec = tmp_path / "old.mcap"
    rec.write_bytes(b"the user's")
    r = host("servo", "--sim", "--record", str(rec))
    assert r.returncode == 2 and "exists already" in r.stderr
    assert r.stderr.count("\n") == 1 and rec.read_bytes() == b"the user's"
    r = host("servo", "--sim", "--record", str(tmp_path / "run.bag"))
    assert r.returncode == 2 and "name it .mcap" in r.stderr


def test_options_that_cannot_go_together_are_one_line(tmp_path: Path) -> None:
    missing = tmp_path / "none.mcap"
    for args, words in (
            (["--sim", "--trials", "2", "--record", str(tmp_path / "t.mcap")],
             "not with --trials"),
            (["--sim", "--view-wait"], "give --view too"),
            (["--camera", f"replay:{missing}", "--port", "emulator"], "no such recording")):
        r = host("servo", *args)
        assert r.returncode == 2 and words in r.stderr, r.stderr
        assert r.stderr.count("\n") == 1
    assert not (tmp_path / "t.mcap").exists()
