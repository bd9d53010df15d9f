"""The robot behind a pseudo-terminal: the native emulator, the real ELF in simavr, or the
firmware flashed through optiboot into the simulated Uno."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

from host.emulator import build
from host.emulator.emulator import Emulator, PtyService


@pytest.fixture(scope="session")
def uno_flash(tmp_path_factory) -> Path:
    """The simulated Uno's flash after avrdude uploaded the firmware through optiboot."""
    from host.emulator.uno import SimulatedUno, avrdude

    try:
        hex_file = build.firmware_elf().with_suffix(".hex")
        flash = tmp_path_factory.mktemp("uno") / "flash.bin"
        with SimulatedUno(flash) as uno:
            r = avrdude(uno.path, hex_file)
            assert r.returncode == 0, r.stderr
            assert uno.wait(lambda u: u.saves, 5)
    except build.ToolMissing as e:
        pytest.skip(str(e))
    return flash


@pytest.fixture(params=["emulator", "simavr", "uno"])
def robot_port(request, tmp_path_factory) -> Iterator[str]:
    """A serial port with a freshly reset robot behind it, running in real time."""
    if request.param == "emulator":
        with PtyService(Emulator()) as service:
            yield service.path
        return
    if request.param == "uno":
        from host.emulator.uno import SimulatedUno

        # the flashed image on a board just powered up; its RESET-EN cut so that opening the
        # port does not reset it again (tests/firmware/test_uno.py covers the auto-reset)
        flash = tmp_path_factory.mktemp("uno") / "flash.bin"
        shutil.copy(request.getfixturevalue("uno_flash"), flash)
        with SimulatedUno(flash, autoreset=False) as uno:
            yield uno.path
        return
    from host.emulator.simavr import SimavrPty

    try:
        harness = build.simavr_harness(tmp_path_factory.mktemp("simavr"))
        elf = build.firmware_elf()
    except build.ToolMissing as e:  # a build error is a failure, not a skip
        pytest.skip(str(e))
    with SimavrPty(harness, elf) as sim:
        yield sim.path
