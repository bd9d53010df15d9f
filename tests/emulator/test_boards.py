"""The simulated boards take their facts from the firmware's own files (its Makefile's source
list, config.h's PWM_TOP), and every board's simulator is stopped the same way."""

import subprocess
import sys

import pytest

from host.emulator import board, build, core
from host.emulator.process import stop

MAKEFILE = build.FIRMWARE / "Makefile"


@pytest.fixture
def firmware(tmp_path, monkeypatch):
    """A copy of the firmware's Makefile and config.h that a test may change."""
    (tmp_path / "Makefile").write_text(MAKEFILE.read_text())
    (tmp_path / "config.h").write_text((build.FIRMWARE / "config.h").read_text())
    for module in (build, core):
        monkeypatch.setattr(module, "FIRMWARE", tmp_path)
    board.pwm_top.cache_clear()
    yield tmp_path
    board.pwm_top.cache_clear()


def test_the_native_core_builds_the_makefiles_portable_sources(firmware):
    text = (firmware / "Makefile").read_text()
    (firmware / "Makefile").write_text(text.replace("core/drive.c", "core/drive.c core/extra.c"))
    sources = [p.resolve() for p in core.sources()]
    root = firmware.resolve()
    assert root / "core" / "extra.c" in sources
    assert root / "emu" / "board.c" in sources
    assert root / "emu" / "single_thread.c" in sources
    assert not any(root / "avr" in p.parents for p in sources)  # no registers natively


def test_the_checkouts_core_sources_are_its_makefiles_less_the_avr_layer():
    names = {p.name for p in core.sources()}
    assert {"robot.c", "drive.c", "link_loss.c", "board.c", "single_thread.c", "frame.c"} <= names
    assert not names & {"main.c", "uart.c", "clock.c", "motors.c", "reset.c"}


def test_duty_follows_the_firmwares_pwm_top(firmware):
    config = firmware / "config.h"
    config.write_text(config.read_text().replace("#define PWM_TOP 400", "#define PWM_TOP 800"))
    assert board.duty(400, True, False) == 500
    assert board.duty(400, False, True) == -500


def test_a_simulator_that_ignores_terminate_is_killed():
    code = ("import signal, sys, time; signal.signal(signal.SIGTERM, signal.SIG_IGN); "
            "print('ready', flush=True); time.sleep(60)")
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline() == "ready\n"
    stop(proc, timeout_s=0.5)
    assert proc.returncode == -9
    proc.stdout.close()
