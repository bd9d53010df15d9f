"""Build the firmware (normal and hang test build) and the simavr harness once a session."""

from __future__ import annotations

from pathlib import Path

import pytest

from host.emulator import build
from host.errors import HostError


def _or_skip(fn, *args):
    try:
        return fn(*args)
    except HostError as e:
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
