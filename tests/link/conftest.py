"""The robot behind a pseudo-terminal: the native emulator or the real ELF in simavr."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from host.emulator import build
from host.emulator.emulator import Emulator, PtyService


@pytest.fixture(params=["emulator", "simavr"])
def robot_port(request, tmp_path_factory) -> Iterator[str]:
    """A serial port with a freshly reset robot behind it, running in real time."""
    if request.param == "emulator":
        with PtyService(Emulator()) as service:
            yield service.path
        return
    from host.emulator.simavr import SimavrPty

    try:
        harness = build.simavr_harness(tmp_path_factory.mktemp("simavr"))
        elf = build.firmware_elf()
    except build.ToolMissing as e:  # a build error is a failure, not a skip
        pytest.skip(str(e))
    with SimavrPty(harness, elf) as sim:
        yield sim.path
