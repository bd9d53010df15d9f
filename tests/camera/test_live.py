"""Live cameras on fake captures: controls locked alike, grants read back, timestamps and skew,
side-by-side frames split, and a swapped pair caught at start."""

from __future__ import annotations

import argparse
from pathlib import Path

import cv2
import numpy as np
import pytest

from host.camera import discovery
from host.camera.calib_files import Calibration, from_camera_info
from host.camera.controls import EXPOSURE_MANUAL
from host.camera.geometry import Geometry
from host.camera.minoru import MinoruSource
from host.camera.open import check_left_right, open_source
from host.camera.sbs import SideBySideSource
from host.camera.source import CameraError
from host.stereo.synthetic import synthetic_scene

from .fake_capture import FakeCapture, sensor_controls
from .fake_sysfs import SBS, add_camera, add_minoru

SCENE = synthetic_scene(3)  # 320x240, disparities 4..40 px
LEFT, RIGHT = SCENE.left, SCENE.right


def _minoru(caps: dict[str, FakeCapture], **kw) -> MinoruSource:
    return MinoruSource(devices=("L", "R"), open_capture=caps.__getitem__, **kw)


def test_exposure_gain_and_white_balance_locked_to_the_left_sensors_values(capsys) -> None:
    caps = {"L": FakeCapture([LEFT] * 20, sensor_controls(156, 40, 4600)),
            "R": FakeCapture([RIGHT] * 20, sensor_controls(312, 64, 5200))}
    src = _minoru(caps, settle_frames=3)
    assert src.locked == {"exposure": 156, "gain": 40, "white balance": 4600}
    for cap in caps.values():
        assert cap.get(cv2.CAP_PROP_AUTO_EXPOSURE) == EXPOSURE_MANUAL
        assert cap.get(cv2.CAP_PROP_AUTO_WB) == 0
        assert (cap.get(cv2.CAP_PROP_EXPOSURE), cap.get(cv2.CAP_PROP_GAIN),
                cap.get(cv2.CAP_PROP_WB_TEMPERATURE)) == (156, 40, 4600)
        assert cap.i == 2  # three frames on auto to settle first
    assert capsys.readouterr().err == ""


def test_missing_or_refused_controls_are_warned_about_not_hidden(capsys) -> None:
    no_wb = sensor_controls(156, 40, 4600)
    del no_wb[cv2.CAP_PROP_WB_TEMPERATURE]
    caps = {"L": FakeCapture([LEFT] * 20, sensor_controls(156, 40, 4600)),
            "R": FakeCapture([RIGHT] * 20, no_wb, fixed={cv2.CAP_PROP_GAIN: 64})}
    src = _minoru(caps, settle_frames=0)
    assert src.locked == {"exposure": 156}
    err = capsys.readouterr().err
    assert "R offers no white balance control" in err
    assert "could not lock gain at 40: R kept 64" in err


def test_the_granted_format_is_read_back_and_differences_warned(capsys) -> None:
    caps = {"L": FakeCapture([LEFT] * 5, fixed={cv2.CAP_PROP_BUFFERSIZE: 4.0,
                                               cv2.CAP_PROP_FPS: 15.0}),
            "R": FakeCapture([RIGHT] * 5)}
    src = _minoru(caps, lock=False)
    assert str(src.granted[0]) == "YUYV 320x240 at 15 fps, 4 buffers"
    assert str(src.granted[1]) == "YUYV 320x240 at 30 fps, 1 buffer"
    assert "L: the driver granted 15 fps instead of 30; 4 buffers instead of 1" in \
        capsys.readouterr().err
    assert src.describe()["granted"] == [str(g) for g in src.granted]


def test_driver_timestamps_on_the_monotonic_clock_are_used_and_skew_reported() -> None:
    import time

    t0 = time.monotonic() * 1000
    caps = {"L": FakeCapture([LEFT] * 10, stamp=lambda i: t0 + 33.3 * i),
            "R": FakeCapture([RIGHT] * 10, stamp=lambda i: t0 + 33.3 * i + 4.0)}
    src = _minoru(caps, lock=False)
    frames = [src.read() for _ in range(5)]
    assert src.stamps == ["driver", "driver"]
    assert frames[2].t_left == pytest.approx((t0 + 66.6) / 1000)
    assert all(f.skew_ms == pytest.approx(4.0) for f in frames)
    assert "median 4.0 ms, max 4.0 ms" in src.skew_summary()


def test_without_driver_stamps_the_grab_time_stands_in() -> None:
    import time

    caps = {"L": FakeCapture([LEFT] * 3), "R": FakeCapture([RIGHT] * 3)}  # POS_MSEC stays 0
    src = _minoru(caps, lock=False)
    before = time.monotonic()
    f = src.read()
    assert src.stamps == ["grab", "grab"]
    assert before <= f.t_left <= f.t_right <= time.monotonic()


def _sbs_tree(tmp_path: Path, monkeypatch) -> None:
    add_camera(tmp_path, "3-2", ("32e4", "9750"), "3D USB Camera", [3, 4], SBS)
    monkeypatch.setattr(discovery, "SYSFS", tmp_path)


def test_side_by_side_frames_are_split_into_the_two_views(tmp_path: Path, monkeypatch) -> None:
    _sbs_tree(tmp_path, monkeypatch)
    # a real video through cv2.VideoCapture: an image sequence of side-by-side frames
    for i in range(3):
        cv2.imwrite(str(tmp_path / f"sbs_{i:03d}.png"), np.hstack([LEFT, RIGHT]))
    opened = []

    def open_capture(device: str):
        opened.append(device)
        return cv2.VideoCapture(str(tmp_path / "sbs_%03d.png"), cv2.CAP_IMAGES)

    src = SideBySideSource((320, 240), "sbs", open_capture=open_capture, lock=False)
    assert opened == ["/dev/video3"] and str(src.asked) == "MJPG 640x240 at 60 fps, 1 buffer"
    f = src.read()
    grey = [cv2.cvtColor(v, cv2.COLOR_BGR2GRAY) if v.ndim == 3 else v for v in (f.left, f.right)]
    np.testing.assert_array_equal(grey[0], LEFT)
    np.testing.assert_array_equal(grey[1], RIGHT)
    assert f.t_left == f.t_right
    assert "left/right check passed" in check_left_right(src, "refuse")
    with pytest.raises(CameraError, match=r"offers views of 1280x720, 320x240, 640x480, not "
                                          r"800x600 \(--size is the size of one view\)"):
        SideBySideSource((800, 600), "sbs", open_capture=open_capture)


def test_a_swapped_side_by_side_camera_is_refused_naming_swap(tmp_path, monkeypatch) -> None:
    _sbs_tree(tmp_path, monkeypatch)
    frames = [np.hstack([RIGHT, LEFT])] * 20  # this camera puts the right view first

    src = SideBySideSource(open_capture=lambda d: FakeCapture(frames), lock=False)
    with pytest.raises(CameraError, match=r"left and right look swapped \(median disparity "
                                          r"-\d+\.\d px over \d+ textured pixels\): pass --swap"):
        check_left_right(src, "refuse")
    src = SideBySideSource(open_capture=lambda d: FakeCapture(frames), lock=False)
    assert "swapped them back" in check_left_right(src, "auto")
    f = src.read()
    np.testing.assert_array_equal(f.left, LEFT)
    src = SideBySideSource(swap=True, open_capture=lambda d: FakeCapture(frames), lock=False)
    assert "passed" in check_left_right(src, "refuse")


def test_a_swapped_minoru_is_caught_at_start_through_the_command_line_path(
        tmp_path: Path, monkeypatch) -> None:
    add_minoru(tmp_path, "1-1", first_node=0)
    monkeypatch.setattr(discovery, "SYSFS", tmp_path)
    # the sensor on hub port 1 (video2) is wired as the right eye in this unit
    views = {"/dev/video2": RIGHT, "/dev/video0": LEFT}
    caps: list[FakeCapture] = []

    def open_capture(device: str) -> FakeCapture:
        caps.append(FakeCapture([views[device]] * 40, sensor_controls(100, 10, 4000)))
        return caps[-1]

    monkeypatch.setattr("host.camera.live.open_v4l2", open_capture)
    args = argparse.Namespace(camera="minoru", size="320x240", devices=None, swap=False,
                              swap_check="refuse", timestamps="auto", lock=True, calib=None)
    with pytest.raises(CameraError, match="left and right look swapped .*: pass --swap"):
        open_source(args)
    assert all(c.released for c in caps)  # nothing left open
    with pytest.raises(CameraError, match="left and right look swapped .*: drop --swap"):
        open_source(argparse.Namespace(**{**vars(args), "swap": True, "devices":
                                          "/dev/video0,/dev/video2"}))
    with open_source(argparse.Namespace(**{**vars(args), "swap": True})) as src:
        assert src.devices == ("/dev/video0", "/dev/video2")
    with open_source(argparse.Namespace(**{**vars(args), "swap_check": "auto"})) as src:
        np.testing.assert_array_equal(src.read().left, LEFT)


def test_a_plain_scene_is_not_judged() -> None:
    flat = np.full((240, 320), 120, np.uint8)
    caps = {"L": FakeCapture([flat] * 5), "R": FakeCapture([flat] * 5)}
    assert "left/right not checked" in check_left_right(_minoru(caps, lock=False), "refuse")


def test_when_the_second_sensor_does_not_open_the_first_is_released() -> None:
    first = FakeCapture([LEFT])

    def open_capture(device: str) -> FakeCapture:
        if device == "R":
            raise CameraError("cannot open R")
        return first

    with pytest.raises(CameraError, match="cannot open R"):
        MinoruSource(devices=("L", "R"), open_capture=open_capture)
    assert first.released


def _a_calibration(size: tuple[int, int]) -> Calibration:
    """A calibration whose rectification moves every pixel (distortion and a small rotation on
    each side), without a chessboard fit (the session's fixture costs ~20 s)."""
    g = Geometry.minoru_default(*size)
    k = np.array([[g.focal_px, 0, g.cx], [0, g.focal_px, g.cy], [0, 0, 1]])
    p1 = np.hstack([k, np.zeros((3, 1))])
    p2 = p1.copy()
    p2[0, 3] = -g.focal_px * g.baseline_m
    rot = cv2.Rodrigues(np.array([0.01, -0.02, 0.005]))[0]
    return from_camera_info(size, {"K": k, "D": np.array([[-0.12, 0.03, 0.001, -0.002, 0]]),
                                   "R": rot, "P": p1},
                            {"K": k, "D": np.array([[-0.1, 0.02, 0, 0.001, 0]]), "R": rot.T,
                             "P": p2})


def test_a_side_by_side_camera_is_rectified_with_a_calibration_like_any_other(
        tmp_path: Path, monkeypatch) -> None:
    from host.camera.calibration import Rectifier

    from .boards import views

    _sbs_tree(tmp_path, monkeypatch)
    calib = tmp_path / "calib.yml"
    calibration = _a_calibration((640, 480))
    calibration.save(calib)
    pair = views(1, seed=7)[0]  # 640x480 views: the camera's 1280x480 mode
    monkeypatch.setattr("host.camera.live.open_v4l2",
                        lambda d: FakeCapture([np.hstack([pair.left, pair.right])] * 30))
    args = argparse.Namespace(camera="sbs:/dev/video3", size="640x480", devices=None,
                              swap=False, swap_check="refuse", timestamps="auto", lock=False,
                              calib=str(calib))
    with open_source(args) as src:
        assert str(src.asked) == "MJPG 1280x480 at 60 fps, 1 buffer"
        got = src.read()
    want = Rectifier(calibration)(pair)
    assert not np.array_equal(want.left, pair.left) and not np.array_equal(want.right, pair.right)
    np.testing.assert_array_equal(got.left, want.left)
    np.testing.assert_array_equal(got.right, want.right)
