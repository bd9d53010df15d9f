"""Shared fixtures (where the Middlebury reference scenes are: STEREO_SERVO_DATA), the slow
tiers, and what makes two pytest-xdist workers safe side by side (make test runs -n 2)."""

from __future__ import annotations

import contextlib
import os
import signal
import time
from pathlib import Path

import pytest
from numba.core import event

# A suite started in the background of a script (bash's `cmd &` without job control) has SIGINT
# ignored, and every program the tests start inherits that: the tests that end one with Ctrl-C
# (test_cli_signals, test_sim_watch, the resumed campaign in test_trials) then wait in vain (a
# fresh-clone run under `nohup bash -c '... &'` failed those four). The default handler here
# becomes the default action in each program started (exec resets a handler, not an ignore).
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


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
    "tests/sim/test_knock_acquire.py": "a closed-loop run knocked during the probe",
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
    "tests/sim/test_recover_events.py::test_at_the_defaults_a_knocked_camera_is_re_referenced_and_the_robot_holds":
        "a closed-loop run",
    "tests/sim/test_recover_events.py::test_a_look_alike_that_replaced_the_target_during_a_knock_is_no_re_reference":
        "a closed-loop run",
    "tests/sim/test_recover_events.py::test_a_knock_with_the_marker_hidden_ends_the_run_at_the_moved_bound":
        "a closed-loop run",
    "tests/stereo/test_sgm.py::test_sgm_in_steady_state_takes_no_page_faults":
        "a fresh interpreter loading numba and matching 640x480 many times",
    "tests/tuning/test_tune_cli.py::test_parallel_workers_give_the_same_result_as_one_process":
        "worker processes that each load the matcher",
    "tests/sim/test_recover_events.py::test_a_knock_after_a_nearer_object_became_the_target_is_re_referenced":
        "a closed-loop run",
    "tests/test_cli_view_sim.py::test_view_shows_the_simulated_world":
        "host view serving the simulated world",
    "tests/view/test_view_command.py::test_view_shows_a_recording_without_stop":
        "host view serving a replay",
    "tests/tuning/test_progress.py::test_the_bar_shows_on_a_terminal":
        "host tune on a terminal",
}


def _is_slow(rel: str, name: str) -> bool:
    if any(rel == p or rel.startswith(p + "/") for p in SLOW_FILES):
        return True
    node = f"{rel}::{name}"
    return node in SLOW_TESTS or node.split("[")[0] in SLOW_TESTS


def pytest_ignore_collect(collection_path: Path, config) -> bool | None:
    """The fast tier (-m "not slow", exactly) does not even import the SLOW_FILES: their
    imports (scipy.stats, Ray, rosbags, playwright) cost each worker ~3 s of CPU, for tests
    it then deselects. Any other -m collects them and marks their tests slow as before."""
    if " ".join(config.getoption("markexpr").split()) != "not slow":
        return None
    rel = collection_path.resolve().relative_to(ROOT).as_posix()
    return True if rel in SLOW_FILES else None


def pytest_collection_modifyitems(config, items) -> None:
    slow_files = set()
    for item in items:
        rel = Path(str(item.fspath)).resolve().relative_to(ROOT).as_posix()
        if _is_slow(rel, item.name):
            item.add_marker(pytest.mark.slow)
            slow_files.add(rel)
    if WORKER:  # pytest-xdist hands out whole files in this order (make test: no reordering)
        items.sort(key=lambda item: _schedule_key(item, slow_files))


def _schedule_key(item, slow_files: set[str]) -> int:
    """Files holding a slow-tier test first (the closed-loop, simavr and Ray files take minutes
    with a few tests each), so that the two workers do not end with one of them running a long
    file alone while the other idles; a stable sort keeps each file's tests together and in
    their order."""
    rel = Path(str(item.fspath)).resolve().relative_to(ROOT).as_posix()
    return 0 if rel in slow_files else 1


# ---- two workers side by side (pytest-xdist; make test runs -n 2 --dist loadfile) ----------
# Each file runs whole on one worker (its module fixtures, ports and files stay its own). What
# files share is made safe here: the firmware ELFs are built once before the workers start
# (every later make finds them up to date) and each worker's Ray keeps its session files apart;
# numba's cache is read and written under a lock wherever host.stereo is imported
# (host.stereo.numba_cache).
WORKER = os.environ.get("PYTEST_XDIST_WORKER")
if WORKER:
    os.environ.setdefault("RAY_TMPDIR", f"/tmp/ray-{WORKER}")  # short: Ray's socket paths


def pytest_sessionstart(session) -> None:
    if session.config.pluginmanager.hasplugin("dsession"):  # the controller, before workers
        from host.emulator import build
        from host.errors import HostError
        for test_hang in (False, True):
            # on an error the fixtures build again and skip (tool missing) or fail with it
            with contextlib.suppress(HostError):
                build.firmware_elf(test_hang)


class _NumbaCompiles(event.Listener):
    """Records the numba kernels compiled (not loaded from the cache) during each test: the
    warm step (python -m host.warm) should have compiled them, and compiling costs a
    test tens of seconds."""

    def __init__(self) -> None:
        self.depth, self.t0, self.seconds, self.names = 0, 0.0, 0.0, []

    def on_start(self, ev) -> None:
        if self.depth == 0:
            self.t0 = time.perf_counter()
        self.depth += 1
        func = ev.data["dispatcher"].py_func
        if not func.__module__.startswith("numba"):  # ours, not numba's own overloads
            self.names.append(f"{func.__module__}.{func.__qualname__}")

    def on_end(self, ev) -> None:
        self.depth -= 1
        if self.depth == 0:
            self.seconds += time.perf_counter() - self.t0

    def take(self) -> tuple[float, list[str]]:
        got = (self.seconds, sorted(set(self.names)))
        self.seconds, self.names = 0.0, []
        return got


_COMPILES = _NumbaCompiles()
event.register("numba:compile", _COMPILES)
_COMPILED: dict[tuple[str, str], tuple[float, list[str]]] = {}  # (nodeid, phase)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    seconds, names = _COMPILES.take()
    if names:  # carried to the controller in the report (pytest-xdist)
        item.user_properties.append(("numba compiled", (call.when, round(seconds, 1), names)))
    yield


def pytest_runtest_logreport(report) -> None:
    for key, value in report.user_properties:  # a phase's entry comes again in later reports
        if key == "numba compiled":
            when, seconds, names = value
            _COMPILED[(report.nodeid, when)] = (seconds, names)


def pytest_terminal_summary(terminalreporter) -> None:
    if not _COMPILED:
        return
    terminalreporter.section("numba compiled during tests (not in the warm step's cache)")
    for (nodeid, when), (seconds, names) in sorted(_COMPILED.items(), key=lambda kv: -kv[1][0]):
        terminalreporter.write_line(f"{seconds:7.1f} s {when:8} {nodeid}: {', '.join(names)}")
