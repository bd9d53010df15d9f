"""--camera replay:FILE.mcap: a recorded simulated run replays into the servo with the same
targets and marker disparities, its calibration from the bag's CameraInfo; a replay that runs
out ends with its own outcome and exit status; a killed recording replays to its last chunk;
host tune --objective self gets the same pairs from a bag as from the folder of its pairs."""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

pytest.importorskip("rosbags")

from host.camera.bag import BagSource  # noqa: E402
from host.camera.calib_files import is_ideal  # noqa: E402
from host.camera.source import CameraError  # noqa: E402
from host.emulator.emulator import Emulator, PtyService  # noqa: E402
from host.errors import RecordingEnded  # noqa: E402
from host.link.client import RobotLink  # noqa: E402
from host.servo.loop import Servo  # noqa: E402
from host.sim.run import Setup  # noqa: E402
from tests.record.conftest import STEPS  # noqa: E402


def test_a_replay_sees_what_the_run_saw(run):
    path, _, seen, recorded = run
    snaps = [snap for _, snap in seen]
    with BagSource(path, speed=0) as source, PtyService(Emulator()) as service, \
            RobotLink(service.path) as link:
        calib = source.calibration
        assert calib is not None and is_ideal(calib)  # the sim's pairs need no rectifying
        assert calib.geometry == recorded.geometry
        servo = Servo(source, link, Setup().params, calib.geometry, recorded.control,
                      clock=source.clock)
        replayed = []
        servo.observers.append(replayed.append)
        servo.reference()
        for _ in range(STEPS):
            servo.step()
        with pytest.raises(CameraError, match="the camera ended"):
            servo.step()
    assert [s.target for s in replayed] == [s.target for s in snaps]  # reference, re-measures
    assert [s.phase for s in replayed] == [s.phase for s in snaps]
    robot = [r.robot_px for r in servo.rows]
    want = [r.robot_px for r in recorded.rows]
    assert all(a == b or math.isnan(a) and math.isnan(b) for a, b in zip(robot, want))
    assert len(robot) == len(want) == STEPS


def test_a_replay_that_runs_out_says_so(run):
    path = run[0]
    r = subprocess.run([sys.executable, "-m", "host", "servo", "--camera", f"replay:{path}",
                        "--port", "emulator", "--speed", "0", "--settle", "0"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == RecordingEnded.status, r.stderr
    last = r.stderr.strip().splitlines()[-1]
    assert f"the recording ended after {STEPS + 5} pairs in phase" in last
    assert "before the robot held at the target" in last
    target = run[3].target.disparity
    assert f"target: nearest object at disparity {target:.2f} px" in r.stderr
    assert "no --calib" not in r.stderr  # the geometry came from the bag


def test_tune_gets_the_same_pairs_from_a_bag_as_from_their_folder(run, tmp_path):
    from host.commands.tune import camera_scenes

    path, _, seen, recorded = run
    for i, (frame, _) in enumerate(seen):
        cv2.imwrite(str(tmp_path / f"left_{i:03d}.png"), frame.left)
        cv2.imwrite(str(tmp_path / f"right_{i:03d}.png"), frame.right)

    def scenes(camera: str):
        args = argparse.Namespace(camera=camera, calib=None, frames=4, size="320x240",
                                  speed=None, swap_check="off")
        return camera_scenes(args)

    from_bag, focal_baseline = scenes(f"replay:{path}")
    from_folder, _ = scenes(f"replay:{tmp_path}")
    g = recorded.geometry
    assert focal_baseline == pytest.approx(g.focal_px * g.baseline_m)
    assert len(from_bag) == len(from_folder) == 4
    for a, b in zip(from_bag, from_folder):  # the folder's PNGs read as BGR, the bag's mono8
        assert a.left.ndim == 2 and np.array_equal(a.left, b.left[..., 0])


def test_a_killed_recording_replays_to_its_last_chunk(run, tmp_path: Path):
    cut = tmp_path / "cut.mcap"
    data = run[0].read_bytes()
    cut.write_bytes(data[:len(data) // 2])  # as a killed run leaves it: no summary, a chunk cut
    with BagSource(cut, speed=0) as source:
        frames = list(source)
        assert source.truncated and 0 < len(frames) < STEPS + 5
        assert "the file is cut off" in source.ended()
    with BagSource(run[0], speed=0) as source:
        assert len(list(source)) == STEPS + 5 and not source.truncated


def test_a_file_that_is_not_a_recording_is_one_line(tmp_path: Path):
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(b"not an mcap file at all")
    r = subprocess.run([sys.executable, "-m", "host", "view", "--camera", f"replay:{bad}"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "not an MCAP file" in r.stderr, r.stderr
    assert r.stderr.count("\n") == 1


def test_a_calibrated_camera_replays_rectified_as_the_run_saw_it(tmp_path: Path):
    """Raw pairs of a distorting lens with the CameraInfo of its calibration: the same K, D,
    R, P as the --ros files, and a replay rectified with it sees what the run saw, bit for
    bit."""
    import yaml

    from host.camera.calib_files import save_ros
    from host.camera.calibration import Rectifier
    from host.record import record_servo
    from host.record.messages import info_fields
    from host.sim.faults import CameraFaults, WorldFaults
    from host.sim.run import simulation

    path = tmp_path / "lens.mcap"
    args = argparse.Namespace(record=path, record_compression="zstd", record_queue=10_000)
    seen = []
    faults = WorldFaults(camera=CameraFaults(distortion=(-0.15, -0.1)))
    with simulation(Setup((320, 240), 1.9, faults=faults), reference=False) as sim:
        with record_servo(args, sim.servo, sim.source.clock):
            sim.servo.observers.append(lambda snap: seen.append(snap.left))
            sim.servo.reference()
            for _ in range(3):
                sim.step()
        calib = sim.servo.source.calibration
    save_ros(calib, tmp_path)
    with BagSource(path, speed=0) as source:
        for side in ("left", "right"):
            ros = yaml.safe_load((tmp_path / f"{side}.yaml").read_text())
            got = info_fields(source._infos[side])
            for key, name in (("K", "camera_matrix"), ("D", "distortion_coefficients"),
                              ("R", "rectification_matrix"), ("P", "projection_matrix")):
                assert np.allclose(got[key].ravel(), ros[name]["data"], rtol=1e-12), key
        assert not is_ideal(source.calibration)
        rectify = Rectifier(source.calibration)
        frames = [rectify(f) for f in source]
    assert len(frames) == len(seen) == 8
    assert all(np.array_equal(f.left, s) for f, s in zip(frames, seen))
