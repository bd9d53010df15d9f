"""Build the firmware (normal and hang test build) and the simavr harness once a session. Only a
missing toolchain skips; a compile error in code we own fails every test that needs it."""

from __future__ import annotations

from pathlib import Path

import pytest

from host.emulator import build


def _or_skip(fn, *args):
    try:
        return fn(*args)
    except build.ToolMissing as e:
        pytest.skip(str(e))


@pytest.fixture(scope="session")
def firmware_elf() -> Path:
    return _or_skip(build.firmware_elf)


@pytest.fixture(scope="session")
def hang_elf() -> Path:
    return _or_skip(build.firmware_elf, True)


@pytest.fixture(scope="session")
def harness(tmp_path_factory) -> Path:
    return _or_skip(build.simavr_harness, tmp_path_factory.mktemp("simavr"))
