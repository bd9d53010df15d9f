"""host calibrate: rejected views named, coverage shown, OpenCV and ROS files and the check
picture written; nothing written when the calibration fails."""

from __future__ import annotations

from pathlib import Path

import cv2

from host.camera.calib_files import Calibration
from host.cli import main

from .boards import BASELINE_MM, BOARD, SQUARE_MM, bent_view, views


def test_calibrate_reports_rejects_and_writes_every_file(tmp_path: Path, capsys) -> None:
    shots = tmp_path / "shots"
    shots.mkdir()
    pairs = views(10)
    pairs.insert(4, bent_view(102))
    for i, f in enumerate(pairs):
        cv2.imwrite(str(shots / f"left_{i:03d}.png"), f.left)
        cv2.imwrite(str(shots / f"right_{i:03d}.png"), f.right)
    calib, ros, pic = tmp_path / "calib.yml", tmp_path / "ros", tmp_path / "check.png"
    ros.mkdir()
    args = ["calibrate", str(shots), "--board", f"{BOARD[0]}x{BOARD[1]}", "--square",
            str(SQUARE_MM), "--min-views", "8"]
    assert main(args + ["--out", str(calib), "--ros", str(ros), "--picture", str(pic)]) == 0
    out = capsys.readouterr().out
    assert "10 of 11 pairs used" in out
    assert "  004.png: rejected, reprojection error " in out
    assert "reprojection RMS" in out and "left: corners in " in out and "right: " in out
    back = Calibration.load(calib)
    assert abs(back.baseline_mm / BASELINE_MM - 1) < 0.01
    assert Calibration.load(f"{ros / 'left.yaml'},{ros / 'right.yaml'}").size == (640, 480)
    assert cv2.imread(str(pic)).shape == (480, 1280, 3)
    # a failed calibration writes nothing
    for p in (calib, pic):
        p.unlink()
    assert main(args[:-1] + ["20", "--out", str(calib), "--picture", str(pic)]) == 2
    err = capsys.readouterr().err
    assert "only 11 of 11 pairs; need 20" in err and err.count("\n") == 1
    assert not calib.exists() and not pic.exists()
