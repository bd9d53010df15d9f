"""Shared fixtures: where the Middlebury reference scenes are (STEREO_SERVO_DATA)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest


def _middlebury() -> Path | None:
    root = os.environ.get("STEREO_SERVO_DATA")
    if not root:
        return None
    d = Path(root) / "middlebury"
    return d if (d / "cones").is_dir() else None


@pytest.fixture(scope="session")
def middlebury() -> Path:
    d = _middlebury()
    if d is None:
        pytest.skip("Middlebury scenes not found: set STEREO_SERVO_DATA to shared/data "
                    "(make test does when ../shared/data exists)")
    return d


ROOT = Path(__file__).resolve().parent.parent
PROTOCOL_C = ROOT / "protocol" / "c"
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all"]


@pytest.fixture(scope="session")
def native_build(tmp_path_factory):
    """Compile C sources natively with gcc (warnings are errors); returns the executable."""
    import shutil
    import subprocess

    if shutil.which("gcc") is None:
        pytest.skip("gcc not found")
    out_dir = tmp_path_factory.mktemp("native")

    def build(name: str, sources: list[Path], flags: list[str] = (), sanitize: bool = True,
              includes: list[Path] = ()) -> Path:
        exe = out_dir / name
        cmd = ["gcc", "-std=gnu11", "-O1", "-g", "-Wall", "-Wextra", "-Werror",
               f"-I{PROTOCOL_C}", *[f"-I{i}" for i in includes], *(SANITIZE if sanitize else []),
               *flags, *map(str, sources), "-o", str(exe)]
        subprocess.run(cmd, check=True)
        return exe

    return build


# The slow tiers: `pytest -m "not slow"` is the fast subset a change is first checked with;
# `make test` runs everything. A test file is in a tier for what it needs (why, beside it).
SLOW_FILES = {
    "tests/firmware/test_simavr.py": "the firmware's ELF in simavr",
    "tests/firmware/test_uno.py": "the simulated Uno through its bootloader",
    "tests/firmware/test_platformio.py": "PlatformIO builds and uploads",
    "tests/firmware/test_watchdog.py": "watchdog periods in simavr",
    "tests/firmware/test_budget.py": "floods in simavr",
    "tests/firmware/test_libfuzzer.py": "clang builds and fuzz runs",
    "tests/firmware/test_pins.py": "the firmware's pins in simavr",
    "tests/view/test_browser.py": "a browser",
    "tests/view/test_sim_watch.py": "real-time simulated runs",
    "tests/tuning/test_ray_backend.py": "Ray",
    "tests/sim/test_trials.py": "trial campaigns, Ray",
    "tests/sim/test_events.py": "closed-loop runs of every event",
    "tests/servo/test_closed_loop.py": "closed-loop runs",
    "tests/servo/test_heading.py": "closed-loop runs from every heading",
    "tests/servo/test_false_marker.py": "closed-loop runs among look-alikes",
    "tests/servo/test_lane.py": "closed-loop runs with a box put in the lane",
    "tests/servo/test_fixed_objects.py": "closed-loop runs past a box and at the view's edge",
    "tests/servo/test_cut_marker.py": "closed-loop runs with the card behind the object's edge",
    "tests/servo/test_acquire_freeze.py": "closed-loop runs with a sensor frozen in the probe",
    "tests/servo/test_range.py": "closed-loop runs from near and far",
    "tests/servo/test_timing_and_target.py": "closed-loop runs with a moved target",
    "tests/servo/test_servo_cli.py": "simulated host servo runs",
    "tests/sim/test_lens.py": "calibrations and closed-loop runs through distorting lenses",
    "tests/sim/test_render_speedup.py": "renders against the slow oracle renderer",
    "tests/test_cli_signals.py": "simulated runs ended by signals",
    "tests/tuning/test_self_supervised.py": "self-supervised tuning on rendered frames",
    "tests/stereo/test_middlebury_quality.py": "every matcher on the ten scenes",
    "tests/camera/test_calibrate_cli.py": "chessboard calibrations",
    "tests/camera/test_calibration.py": "chessboard calibrations",
    "tests/camera/test_calib_files.py": "a chessboard calibration (the fixture)",
    "tests/link/test_emulated_serial.py": "faulty emulated lines in real time",
    "tests/servo/test_loop_rate.py": "simulated servo runs",
    "tests/test_cli_link.py": "host servo runs on faulty lines",
    "tests/record": "recorded simulated runs",
    "tests/packaging": "builds and installs the package",
}


# Single tests in a slow tier while the rest of their file is fast: "file::name" (every
# parametrization of it), or "file::name[id]" for one. The race sweeps are not cut short for
# the fast tier: their first 300 trials missed two of the three mutants they kill
# (motor-output-outside-the-lock, torn-32-bit-clock-read), so only whole sweeps are a check.
SLOW_TESTS = {
    "tests/servo/test_progress.py::test_the_servo_names_a_hold_it_cannot_keep_instead_of_running_out_of_time":
        "a closed-loop run of 30 s",
    "tests/firmware/test_races.py::test_a_link_loss_cut_is_never_undone_or_lost_wherever_the_tick_lands":
        "an 1800-trial sweep in simavr",
    "tests/firmware/test_races.py::test_the_clock_read_at_a_carry_is_never_torn_wherever_the_tick_lands":
        "a 1500-trial sweep in simavr",
    "tests/firmware/test_races.py::test_a_drive_acknowledged_at_the_deadline_is_still_driven":
        "two 2500-trial sweeps in simavr",
    "tests/sim/test_recover_events.py::test_a_knocked_camera_is_re_referenced_and_the_robot_holds":
        "closed-loop runs",
    "tests/sim/test_recover_events.py::test_a_reset_whose_boot_frame_is_lost_is_waited_out_and_the_robot_re_acquired":
        "a closed-loop run",
    "tests/sim/test_recover_events.py::test_a_box_put_down_in_the_lane_is_waited_out_and_the_target_taken_up_again":
        "a closed-loop run",
    "tests/sim/test_recover_events.py::test_a_box_left_in_the_lane_ends_the_run_after_the_lane_bound":
        "a closed-loop run",
    "tests/sim/test_recover_events.py::test_a_camera_knocked_more_often_than_the_bound_ends_the_run_with_its_reason":
        "a closed-loop run",
    "tests/stereo/test_sgm.py::test_sgm_in_steady_state_takes_no_page_faults":
        "a fresh interpreter loading numba and matching 640x480 many times",
    "tests/tuning/test_tune_cli.py::test_parallel_workers_give_the_same_result_as_one_process":
        "worker processes that each load the matcher",
}


def _is_slow(rel: str, name: str) -> bool:
    if any(rel == p or rel.startswith(p + "/") for p in SLOW_FILES):
        return True
    node = f"{rel}::{name}"
    return node in SLOW_TESTS or node.split("[")[0] in SLOW_TESTS


def pytest_collection_modifyitems(config, items) -> None:
    for item in items:
        rel = Path(str(item.fspath)).resolve().relative_to(ROOT).as_posix()
        if _is_slow(rel, item.name):
            item.add_marker(pytest.mark.slow)
