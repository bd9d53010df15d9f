"""host servo as a user runs it: the simulated run writes its log and plot; bad input is one
line and exit status 2."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import cv2


def run(*argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "host", "servo", *argv], capture_output=True,
                          text=True, timeout=300)


def test_sim_run_writes_log_and_plot(tmp_path: Path) -> None:
    log, fig = tmp_path / "run.csv", tmp_path / "run.png"
    r = run("--sim", "--start-depth", "0.9", "--border", "clip", "--num-disparities", "48",
            "--log", str(log), "--plot", str(fig))
    assert r.returncode == 0, r.stderr
    assert "target: nearest object at disparity" in r.stderr and "held at " in r.stderr
    rows = list(csv.DictReader(log.open()))
    assert {"t", "phase", "reason", "target_m", "depth_m", "error_m", "robot_px", "left",
            "right"} <= set(rows[0])
    assert rows[-1]["phase"] == "hold" and (rows[-1]["left"], rows[-1]["right"]) == ("0", "0")
    assert abs(float(rows[-1]["truth_depth_m"]) - 1.2) < 0.03
    assert cv2.imread(str(fig)) is not None


def test_missing_port_and_bad_camera_are_one_line_errors(tmp_path: Path) -> None:
    r = run("--camera", f"replay:{tmp_path}")
    assert r.returncode == 2 and "--port is needed" in r.stderr and r.stderr.count("\n") == 1
    r = run("--camera", f"replay:{tmp_path / 'none'}", "--port", "emulator")
    assert r.returncode == 2 and "no such folder" in r.stderr and r.stderr.count("\n") == 1
    r = run("--camera", "sim", "--port", "/dev/ttyNOPE0")
    assert r.returncode == 2 and "needs --port emulator" in r.stderr
    r = run("--sim", "--drop", "1.5")
    assert r.returncode == 2 and "argument --drop: must be >= 0 and <= 1" in r.stderr


def test_link_fault_options_reach_the_simulated_robot() -> None:
    """host servo --sim takes the emulator's link faults: a robot that goes silent ends the run
    with the link's error, not a hold."""
    r = run("--sim", "--start-depth", "0.9", "--border", "clip", "--num-disparities", "48",
            "--drop", "0.001", "--corrupt", "0.001", "--delay-ms", "5", "--silent-after", "1500")
    assert r.returncode != 0 and "did not answer" in r.stderr and "held at" not in r.stderr
