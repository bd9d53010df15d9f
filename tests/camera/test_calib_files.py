"""Calibration files: the OpenCV file and ROS camera_info round-trip, older key names still
load, and every kind of bad file is one line and exit status 2 from the command line."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml

from host.camera.calib_files import MATRICES, Calibration, load_calibration, ros_text, save_ros
from host.camera.calibration import Rectifier
from host.camera.source import CameraError
from host.cli import main

from .boards import views


def test_opencv_file_round_trip_with_the_stereo_sample_names(spoiled_run, tmp_path) -> None:
    calib = spoiled_run.calibration
    path = tmp_path / "calib.yml"
    calib.save(path)
    back = Calibration.load(path)
    assert back.size == calib.size and back.rms == pytest.approx(calib.rms)
    for k in MATRICES:
        np.testing.assert_allclose(back.mats[k], calib.mats[k], rtol=1e-9, atol=1e-12)
    text = path.read_text()
    assert text.startswith("%YAML") and "baseline_mm" in text and "\nM1: " in text
    # a file from before the rename (K1/K2) still loads
    (tmp_path / "old.yml").write_text(text.replace("\nM1: ", "\nK1: ").replace("\nM2: ", "\nK2: "))
    np.testing.assert_array_equal(Calibration.load(tmp_path / "old.yml").mats["M1"],
                                  back.mats["M1"])


def test_ros_camera_info_round_trip(spoiled_run, tmp_path: Path) -> None:
    calib = spoiled_run.calibration
    left, right = save_ros(calib, tmp_path)
    info = yaml.safe_load(right.read_text())
    assert info["distortion_model"] == "plumb_bob" and info["image_width"] == 640
    assert info["camera_name"] == "right"
    p = np.array(info["projection_matrix"]["data"]).reshape(3, 4)
    # ROS keeps Tx = -fx' * baseline in metres
    assert p[0, 3] == pytest.approx(-p[0, 0] * calib.baseline_mm / 1000, rel=1e-6)
    back = load_calibration(f"{left},{right}")
    assert back.size == calib.size
    for k in ("M1", "D1", "M2", "D2", "R1", "R2", "P1", "P2"):
        np.testing.assert_array_equal(back.mats[k], calib.mats[k].reshape(back.mats[k].shape))
    for k in ("R", "T", "Q"):
        np.testing.assert_allclose(back.mats[k], calib.mats[k], rtol=1e-6, atol=1e-9)
    f0 = calib.mats["F"] / calib.mats["F"][2, 2]
    np.testing.assert_allclose(back.mats["F"], f0, rtol=1e-5, atol=1e-9)
    e0 = calib.mats["E"]
    np.testing.assert_allclose(back.mats["E"], e0, rtol=1e-5, atol=1e-6 * np.abs(e0).max())
    assert back.geometry == pytest.approx(calib.geometry)
    # the same rectification, pixel for pixel
    frame = views(1, seed=3)[0]
    a, b = Rectifier(calib)(frame), Rectifier(back)(frame)
    np.testing.assert_array_equal(a.left, b.left)
    np.testing.assert_array_equal(a.right, b.right)
    # and the text is what camera_calibration writes: these keys, in this order
    keys = [line.split(":")[0] for line in ros_text(calib, "left").splitlines()
            if not line.startswith(" ")]
    assert keys == ["image_width", "image_height", "camera_name", "camera_matrix",
                    "distortion_model", "distortion_coefficients", "rectification_matrix",
                    "projection_matrix"]


def _bad_files(folder: Path, good: str, ros_left: str) -> dict[str, tuple[str, str]]:
    """name -> (--calib value, expected message part); files are written into folder."""
    files = {
        "syntax.yml": ("%YAML:1.0\n---\nimage_size: [640, 480\nM1: {{\n",
                       "not readable as OpenCV YAML (a syntax error"),
        "binary.yml": (bytes(range(256)) * 4, "not a text file"),
        "only_size.yml": (good.split("\nM1:")[0] + "\n", "missing M1, D1, M2, D2, R, T, E, F, "
                                                         "R1, R2, P1, P2, Q"),
        "list_size.yml": ("%YAML:1.0\n---\nimage_size: [640, 480]\n", "missing M1"),
        "bad_size.yml": (good.replace("   data: [ 640, 480 ]", "   data: [ 640, -4 ]"),
                         "image_size must be two positive whole numbers"),
        "empty.yml": ("", "the file is empty"),
        "not_calib.yml": ("just: text\n", "no image_size (not a host calibrate file?)"),
        "wrong_shape.yml": (good.replace("R1: !!opencv-matrix\n   rows: 3\n   cols: 3",
                                         "R1: !!opencv-matrix\n   rows: 1\n   cols: 9"),
                            "R1 is not a finite 3x3 matrix"),
        "one_ros.yaml": (ros_left, "is one camera's ROS camera_info: pass both"),
        "ros_syntax.yaml": (ros_left.replace("rows: 3", "rows: [3", 1),
                            "not readable as YAML (a syntax error at line"),
        "ros_short.yaml": (ros_left.replace("camera_matrix:\n  rows: 3", "camera_matrix:\n  "
                                            "rows: 2"), "camera_matrix must have rows, cols"),
    }
    cases = {}
    for name, (content, message) in files.items():
        path = folder / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
        value = f"{path},{folder / 'right.yaml'}" if name.startswith("ros_") else str(path)
        cases[name] = (value, message)
    cases["missing.yml"] = (str(folder / "missing.yml"), "no such calibration file")
    return cases


def test_the_list_style_image_size_of_a_whole_file_is_read(spoiled_run, tmp_path) -> None:
    calib = spoiled_run.calibration
    calib.save(tmp_path / "c.yml")
    text = (tmp_path / "c.yml").read_text()
    start = text.index("image_size:")
    end = text.index("\nM1:")
    (tmp_path / "c.yml").write_text(text[:start] + "image_size: [640, 480]" + text[end:])
    assert Calibration.load(tmp_path / "c.yml").size == (640, 480)


def test_each_bad_calibration_file_is_one_line_and_exit_2(spoiled_run, tmp_path: Path,
                                                           capsys) -> None:
    calib = spoiled_run.calibration
    calib.save(tmp_path / "good.yml")
    save_ros(calib, tmp_path)
    shots = tmp_path / "shots"
    shots.mkdir()
    cv2.imwrite(str(shots / "left_000.png"), views(1)[0].left)
    cv2.imwrite(str(shots / "right_000.png"), views(1)[0].right)
    cases = _bad_files(tmp_path, (tmp_path / "good.yml").read_text(),
                       (tmp_path / "left.yaml").read_text())
    assert len(cases) == 12
    for name, (value, message) in cases.items():
        with pytest.raises(CameraError, match="^" + value.split(",")[0].replace(".", r"\.")):
            load_calibration(value)
        out = tmp_path / f"out_{name}"
        code = main(["capture", "--camera", f"replay:{shots}", "--calib", value, "--count", "1",
                     "--interval", "0", "--out", str(out)])
        err = capsys.readouterr().err
        assert code == 2, name
        assert err.count("\n") == 1 and message in err, (name, err)
        assert err.startswith("host capture: error: "), err
        assert not out.exists(), name  # nothing made for a run that could not start
