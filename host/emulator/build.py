"""Build the firmware ELF, the native core's sources and the simavr programs from the firmware
sources: those of the source checkout, or the copy an installed package ships (host/emulator/
_sources), built into a user cache."""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
from pathlib import Path

from host.errors import HostError


class ToolMissing(HostError):
    """A compiler or library the build needs is not installed (tests skip on this only)."""


class BuildFailed(HostError):
    """Code we own did not compile: always a failure, never a skip."""


CHECKOUT = Path(__file__).resolve().parents[2]
PACKAGED = Path(__file__).resolve().parent / "_sources"  # the wheel's copy (setup.py puts it)
IN_CHECKOUT = (CHECKOUT / "firmware" / "atmega328").is_dir() and (CHECKOUT / "protocol").is_dir()
SOURCE_ROOT = CHECKOUT if IN_CHECKOUT else PACKAGED  # holds firmware/atmega328 and protocol/c
FIRMWARE = SOURCE_ROOT / "firmware" / "atmega328"
PROTOCOL_C = SOURCE_ROOT / "protocol" / "c"
CACHE = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "stereo-servo"
ROOT = CHECKOUT if IN_CHECKOUT else CACHE  # where builds are written (build/, in ignored folders)
SIMAVR_INCLUDE = Path("/usr/include/simavr")


def _need(tool: str, package: str) -> None:
    if shutil.which(tool) is None:
        raise ToolMissing(f"{tool} not found: install {package} (make system-deps, as root)")


def need_sources(*paths: Path) -> None:
    """A clear error when the firmware sources are absent (a package built without them)."""
    missing = [p for p in paths if not p.exists()]
    if missing:
        raise HostError(f"the firmware sources are missing ({missing[0]}): reinstall "
                        "stereo-servo from its wheel or sdist, or run from a source checkout")


def firmware_sources() -> list[Path]:
    """The C files the firmware Makefile's SOURCES names (the one list of them), as paths."""
    makefile = FIRMWARE / "Makefile"
    need_sources(makefile)
    text = makefile.read_text().replace("\\\n", " ")
    variables = dict(re.findall(r"^(\w+)\s*:=\s*(.*)$", text, re.MULTILINE))
    words = re.sub(r"\$\((\w+)\)", lambda m: variables[m.group(1)], variables["SOURCES"])
    return [(FIRMWARE / w).resolve() for w in words.split()]


def config_define(name: str) -> int:
    """A whole-number #define of firmware/atmega328/config.h (e.g. PWM_TOP)."""
    config = FIRMWARE / "config.h"
    need_sources(config)
    m = re.search(rf"^#define {name} (\d+)\b", config.read_text(), re.MULTILINE)
    if m is None:
        raise BuildFailed(f"{config}: no #define {name} NUMBER")
    return int(m.group(1))


def need_simavr() -> None:
    _need("gcc", "gcc")
    if not (SIMAVR_INCLUDE / "sim_avr.h").exists():
        raise ToolMissing("simavr headers not found (/usr/include/simavr): install simavr and "
                          "libsimavr-dev (make system-deps, as root)")


def digest(paths: list[Path]) -> str:
    """A short hash of the files' names and contents: a cache key that changes with the code."""
    h = hashlib.sha256()
    for p in paths:
        h.update(p.name.encode() + b"\0" + p.read_bytes())
    return h.hexdigest()[:16]


def _tree_files(root: Path) -> list[Path]:
    return sorted(p for p in root.rglob("*") if p.is_file() and "build" not in p.parts[
        len(root.parts):])


def _writable_firmware() -> Path:
    """The firmware folder make builds in: the checkout's own, or a copy of the shipped sources
    in the cache (a package's folder is not ours to write in), one per version of them."""
    if IN_CHECKOUT:
        return FIRMWARE
    need_sources(FIRMWARE / "Makefile", PROTOCOL_C / "frame.c")
    files = _tree_files(FIRMWARE) + _tree_files(PROTOCOL_C)
    tree = CACHE / f"firmware-src-{digest(files)}"
    if not tree.exists():
        tmp = tree.with_name(f"{tree.name}.{os.getpid()}.tmp")
        shutil.rmtree(tmp, ignore_errors=True)
        shutil.copytree(FIRMWARE, tmp / "firmware" / "atmega328")
        shutil.copytree(PROTOCOL_C, tmp / "protocol" / "c")
        try:
            os.replace(tmp, tree)
        except OSError:  # another process made it first
            shutil.rmtree(tmp, ignore_errors=True)
    return tree / "firmware" / "atmega328"


def firmware_elf(test_hang: bool = False, firmware: Path | None = None) -> Path:
    """Build (make) and return the firmware ELF under firmware/build (ignored by git; in the
    cache for an installed package); test_hang: the build that hangs on demand, in build/hang."""
    _need("avr-gcc", "gcc-avr, avr-libc and binutils-avr")
    _need("make", "make")
    firmware = firmware or _writable_firmware()
    args = ["make", "-s", "-C", str(firmware)] + (["TEST_HANG=1"] if test_hang else [])
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode:
        raise BuildFailed(f"firmware build failed: {r.stderr.strip()[-1500:]}")
    return firmware / "build" / ("hang" if test_hang else "") / "firmware.elf"


def simavr_program(source: Path, name: str, out_dir: Path | None = None,
                   includes: tuple[Path, ...] = ()) -> Path:
    """Compile one simavr program (harness.c, uno.c) against libsimavr into out_dir (default:
    the cache), keyed by a hash of what it is built from (the headers beside it too: the two
    programs' common.h); renamed into place, so a running program keeps its file."""
    need_sources(source)
    need_simavr()
    headers = [h for d in (source.parent, *includes) for h in sorted(d.glob("*.h"))]
    out_dir = out_dir or CACHE / "simavr"
    exe = out_dir / f"{name}-{digest([source, *headers])}"
    if exe.exists():
        return exe
    out_dir.mkdir(parents=True, exist_ok=True)
    tmp = out_dir / f"{exe.name}.{os.getpid()}.tmp"
    r = subprocess.run(["gcc", "-std=gnu11", "-O2", "-Wall", "-Wextra", "-Werror",
                        f"-I{SIMAVR_INCLUDE}", *(f"-I{d}" for d in includes), str(source),
                        "-lsimavr", "-o", str(tmp)], capture_output=True, text=True)
    if r.returncode:
        raise BuildFailed(f"building {source.name} against simavr failed: "
                          f"{r.stderr.strip()[-1500:]}")
    os.replace(tmp, exe)
    return exe


def simavr_harness(out_dir: Path | None = None) -> Path:
    """Compile firmware/atmega328/simavr/harness.c against libsimavr (into out_dir, default the
    cache)."""
    return simavr_program(FIRMWARE / "simavr" / "harness.c", "simavr-harness", out_dir,
                          (PROTOCOL_C,))
