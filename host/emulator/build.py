"""Build the firmware ELF and the simavr harness from the source tree (developer tools)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from host.errors import HostError


class ToolMissing(HostError):
    """A compiler or library the build needs is not installed (tests skip on this only)."""


class BuildFailed(HostError):
    """Code we own did not compile: always a failure, never a skip."""

ROOT = Path(__file__).resolve().parents[2]
FIRMWARE = ROOT / "firmware" / "atmega328"
SIMAVR_INCLUDE = Path("/usr/include/simavr")


def _need(tool: str, package: str) -> None:
    if shutil.which(tool) is None:
        raise ToolMissing(f"{tool} not found: install {package} (make system-deps, as root)")


def firmware_elf(test_hang: bool = False, firmware: Path = FIRMWARE) -> Path:
    """Build (make) and return the firmware ELF under firmware/build (ignored by git);
    test_hang: the build that hangs on demand, in build/hang."""
    _need("avr-gcc", "gcc-avr, avr-libc and binutils-avr")
    args = ["make", "-s", "-C", str(firmware)] + (["TEST_HANG=1"] if test_hang else [])
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode:
        raise BuildFailed(f"firmware build failed: {r.stderr.strip()[-1500:]}")
    return firmware / "build" / ("hang" if test_hang else "") / "firmware.elf"


def simavr_harness(out_dir: Path) -> Path:
    """Compile firmware/atmega328/simavr/harness.c against libsimavr into out_dir."""
    _need("gcc", "gcc")
    if not (SIMAVR_INCLUDE / "sim_avr.h").exists():
        raise ToolMissing("simavr headers not found: install simavr and libsimavr-dev")
    exe = out_dir / "simavr-harness"
    r = subprocess.run(["gcc", "-std=gnu11", "-O2", "-Wall", "-Wextra", "-Werror",
                        f"-I{SIMAVR_INCLUDE}", f"-I{ROOT / 'protocol' / 'c'}",
                        str(FIRMWARE / "simavr" / "harness.c"), "-lsimavr",
                        "-o", str(exe)], capture_output=True, text=True)
    if r.returncode:
        raise BuildFailed(f"simavr harness build failed: {r.stderr.strip()[-1500:]}")
    return exe
