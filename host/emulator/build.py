"""Build the firmware ELF and the simavr harness from the source tree (developer tools)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from host.errors import HostError

ROOT = Path(__file__).resolve().parents[2]
FIRMWARE = ROOT / "firmware" / "atmega328"
SIMAVR_INCLUDE = Path("/usr/include/simavr")


def _need(tool: str, package: str) -> None:
    if shutil.which(tool) is None:
        raise HostError(f"{tool} not found: install {package} (make system-deps, as root)")


def firmware_elf(test_hang: bool = False) -> Path:
    """Build (make) and return the firmware ELF; test_hang: the build that hangs on demand."""
    _need("avr-gcc", "gcc-avr, avr-libc and binutils-avr")
    args = ["make", "-s", "-C", str(FIRMWARE)] + (["TEST_HANG=1"] if test_hang else [])
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode:
        raise HostError(f"firmware build failed: {r.stderr.strip().splitlines()[-1:]}")
    return FIRMWARE / ("build-hang" if test_hang else "build") / "firmware.elf"


def simavr_harness(out_dir: Path) -> Path:
    """Compile firmware/atmega328/simavr/harness.c against libsimavr into out_dir."""
    _need("gcc", "gcc")
    if not (SIMAVR_INCLUDE / "sim_avr.h").exists():
        raise HostError("simavr headers not found: install simavr and libsimavr-dev")
    exe = out_dir / "simavr-harness"
    subprocess.run(["gcc", "-std=gnu11", "-O2", "-Wall", "-Wextra", "-Werror",
                    f"-I{SIMAVR_INCLUDE}", f"-I{ROOT / 'protocol' / 'c'}",
                    str(FIRMWARE / "simavr" / "harness.c"), "-lsimavr",
                    "-o", str(exe)], check=True)
    return exe
