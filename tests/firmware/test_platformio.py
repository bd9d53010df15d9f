"""PlatformIO, as users run it: `platformio run` builds every environment of platformio.ini, the
same image as the Makefile, and `platformio run -t upload` programs the simulated Uno."""

from __future__ import annotations

import configparser
import os
import subprocess
from pathlib import Path

import pytest

from host.emulator import build
from host.emulator.uno import SimulatedUno, hex_image
from host.link import protocol_gen as gen
from host.link.client import RobotLink

ROOT = build.ROOT
SETUP = ROOT / "tools" / "platformio-offline.sh"
PIO = ROOT / ".venv" / "bin" / "pio"


@pytest.fixture(scope="module")
def pio_env(tmp_path_factory) -> dict[str, str]:
    """Environment for `pio`: the offline core (tools/platformio-offline.sh), a fresh build dir."""
    r = subprocess.run(["bash", str(SETUP)], capture_output=True, text=True, timeout=600)
    if r.returncode == 3:
        pytest.skip(f"PlatformIO cannot be set up here: {r.stderr.strip()}")
    assert r.returncode == 0, r.stderr
    return {**os.environ, "PLATFORMIO_CORE_DIR": str(ROOT / "build" / "platformio"),
            "PLATFORMIO_BUILD_DIR": str(tmp_path_factory.mktemp("pio-build"))}


def _pio(env: dict[str, str], *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(PIO), *args], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=300)


def _environments() -> list[str]:
    cfg = configparser.ConfigParser()
    cfg.read(ROOT / "platformio.ini")
    return [s.removeprefix("env:") for s in cfg.sections() if s.startswith("env:")]


def _sizes(elf: Path) -> tuple[int, int]:
    """(flash, RAM) in bytes as avr-size counts them: text + data, data + bss."""
    out = subprocess.run(["avr-size", str(elf)], capture_output=True, text=True,
                         check=True).stdout
    text, data, bss = map(int, out.splitlines()[1].split()[:3])
    return text + data, data + bss


@pytest.fixture(scope="module")
def built(pio_env) -> Path:
    """`platformio run` for every environment; returns the build folder."""
    envs = _environments()
    r = _pio(pio_env, "run", *[a for e in envs for a in ("-e", e)])
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr
    return Path(pio_env["PLATFORMIO_BUILD_DIR"])


def test_platformio_run_builds_every_environment(built) -> None:
    for env in _environments():
        assert (built / env / "firmware.hex").stat().st_size > 0, env


def test_the_uno_image_is_the_makefiles(built) -> None:
    try:
        make_elf = build.firmware_elf()
    except build.ToolMissing as e:
        pytest.skip(str(e))
    # the same functions and sizes; link-time optimisation may lay them out in another order
    assert _sizes(built / "uno" / "firmware.elf") == _sizes(make_elf)


def test_platformio_upload_programs_the_simulated_uno_and_the_firmware_says_hello(
        pio_env, built, tmp_path) -> None:
    image = hex_image(built / "uno" / "firmware.hex")
    try:
        uno = SimulatedUno(tmp_path / "flash.bin")
    except build.ToolMissing as e:
        pytest.skip(str(e))
    with uno:
        r = _pio(pio_env, "run", "-e", "uno", "-t", "upload", "--upload-port", uno.path)
        out = r.stdout + r.stderr
        assert r.returncode == 0, out[-3000:]
        assert f"{len(image)} bytes of flash verified" in out
        assert uno.wait(lambda u: u.saves, 5)
        flash = (tmp_path / "flash.bin").read_bytes()
        assert all(flash[a] == b for a, b in image.items())
        with RobotLink(uno.path) as robot:
            assert robot.hello.schema_hash == gen.SCHEMA_HASH
