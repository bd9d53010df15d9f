"""platformio.ini and firmware/atmega328/Makefile build the same thing (PlatformIO cannot fetch
its platform here, so the agreement is checked on the two files), and the simulators run it at
the Makefile's clock (host/emulator/pins.py's F_CPU, simavr/common.h's)."""

from __future__ import annotations

import configparser
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from host.emulator import pins

ROOT = Path(__file__).resolve().parents[2]
FW = ROOT / "firmware" / "atmega328"


@pytest.fixture(scope="module")
def make_config() -> dict[str, str]:
    if shutil.which("make") is None:
        pytest.skip("make not found")
    out = subprocess.run(["make", "-s", "-C", str(FW), "print-config"], capture_output=True,
                         text=True, check=True).stdout
    return dict(line.split("=", 1) for line in out.splitlines())


@pytest.fixture(scope="module")
def pio() -> configparser.ConfigParser:
    cfg = configparser.ConfigParser()
    cfg.read(ROOT / "platformio.ini")
    return cfg


def _number(text: str) -> int:
    return int(re.sub(r"[UL]+$", "", text))


def test_same_mcu_and_clock(make_config, pio) -> None:
    assert pio["env"]["board_build.mcu"] == make_config["MCU"]
    assert _number(pio["env"]["board_build.f_cpu"]) == _number(make_config["F_CPU"])
    assert _number(make_config["F_CPU"]) == pins.F_CPU  # the simulated pins' and runs' clock
    common = (FW / "simavr" / "common.h").read_text()  # the clock simavr runs the ELF at
    assert re.findall(r"^#define F_CPU (\w+)$", common, re.MULTILINE) == [make_config["F_CPU"]]


def test_same_sources(make_config, pio) -> None:
    make_sources = {str((FW / s).resolve().relative_to(ROOT))
                    for s in make_config["SOURCES"].split()}
    pio_sources = set(re.findall(r"\+<([^>]+)>", pio["env"]["build_src_filter"]))
    assert pio_sources == make_sources


def test_same_includes_defines_and_warnings(make_config, pio) -> None:
    flags = pio["env"]["build_flags"].split()
    pio_includes = {str((ROOT / flags[i + 1]).resolve()) for i, f in enumerate(flags) if f == "-I"}
    make_includes = {str((FW / i).resolve()) for i in make_config["INCLUDES"].split()}
    assert pio_includes == make_includes
    make_defines = {d for d in make_config["DEFINES"].split() if not d.startswith("F_CPU=")}
    pio_defines = {f[2:] for f in flags if f.startswith("-D")}
    assert pio_defines == make_defines
    make_flags = set(make_config["CFLAGS"].split())
    for flag in ("-std=gnu11", "-Os", "-flto", "-mrelax", "-Wall", "-Wextra", "-Werror"):
        assert flag in flags and flag in make_flags


def test_every_environment_uploads_to_an_atmega328p(pio) -> None:
    envs = [s for s in pio.sections() if s.startswith("env:")]
    assert {"env:uno", "env:nano"} <= set(envs)
    for env in envs:
        assert pio[env]["board"] in ("uno", "nanoatmega328", "nanoatmega328new")
        assert pio[env]["upload_protocol"] in ("arduino", "usbasp")
