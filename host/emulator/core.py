"""The firmware's own register-free C core (firmware/atmega328/core) built natively as a shared
library and driven through ctypes: the emulator runs the same code as the robot, not a model."""

from __future__ import annotations

import ctypes
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

from host.emulator.build import (
    CACHE,
    FIRMWARE,
    PROTOCOL_C,
    BuildFailed,
    ToolMissing,
    digest,
    firmware_sources,
    need_sources,
)


def sources() -> list[Path]:
    """The firmware's register-free sources (its Makefile's SOURCES but the AVR layer's), with
    the emulated board (firmware/atmega328/emu: board.c and single_thread.c) in place of avr/."""
    avr = (FIRMWARE / "avr").resolve()
    portable = [p for p in firmware_sources() if avr not in p.parents]
    core = [p for p in portable if p.parent == (FIRMWARE / "core").resolve()]
    emu = [FIRMWARE / "emu" / "board.c", FIRMWARE / "emu" / "single_thread.c"]
    return [*core, *emu, *(p for p in portable if p not in core)]


def _headers() -> list[Path]:
    return [*sorted((FIRMWARE / "core").glob("*.h")), *sorted(PROTOCOL_C.glob("*.h")),
            FIRMWARE / "config.h"]


def build_library() -> Path:
    """Compile the core into a shared library in the user cache, keyed by a hash of its
    sources (the checkout's, or those the package ships)."""
    srcs = sources()
    need_sources(*srcs, FIRMWARE / "config.h")
    if shutil.which("gcc") is None:
        raise ToolMissing("gcc not found: the emulator compiles the firmware core natively "
                          "(install gcc)")
    lib = CACHE / f"firmware-core-{digest(srcs + _headers())}.so"
    if lib.exists():
        return lib
    CACHE.mkdir(parents=True, exist_ok=True)
    tmp = lib.with_suffix(f".{os.getpid()}.tmp")
    # --no-undefined: a board function no source defines is a build error, not a crash when the
    # core first calls it
    cmd = ["gcc", "-std=gnu11", "-O2", "-shared", "-fPIC", "-Wl,--no-undefined", "-Wall",
           "-Wextra", "-Werror", f"-I{PROTOCOL_C}", *map(str, srcs), "-o", str(tmp)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode:
        raise BuildFailed(f"building the firmware core failed: {r.stderr.strip()[:300]}")
    os.replace(tmp, lib)
    return lib


class FirmwareCore:
    """One robot: the core's state lives in the library's statics, so each instance loads its
    own copy of the library."""

    def __init__(self, reset_cause: int, now_ms: int = 0) -> None:
        self._dir = tempfile.TemporaryDirectory(prefix="stereo-servo-core-")
        path = Path(self._dir.name) / "core.so"
        shutil.copyfile(build_library(), path)
        self._lib = ctypes.CDLL(str(path))
        self._lib.robot_init.argtypes = [ctypes.c_uint8, ctypes.c_uint32]
        self._lib.robot_rx_byte.argtypes = [ctypes.c_uint8, ctypes.c_uint32]
        self._lib.robot_tick.argtypes = [ctypes.c_uint32]
        self._lib.robot_guard.argtypes = [ctypes.c_uint32]
        self._lib.emu_take_tx.argtypes = [ctypes.c_char_p, ctypes.c_uint16]
        self._lib.emu_take_tx.restype = ctypes.c_uint16
        self._lib.emu_motors.argtypes = [ctypes.POINTER(ctypes.c_int16)] * 2
        self._lib.emu_motors.restype = ctypes.c_uint32
        self._buf = ctypes.create_string_buffer(4096)
        self._left, self._right = ctypes.c_int16(), ctypes.c_int16()
        self._motor_refs = ctypes.byref(self._left), ctypes.byref(self._right)
        self._lib.robot_init(reset_cause, now_ms)

    def rx(self, data: bytes, now_ms: int) -> None:
        for b in data:
            self._lib.robot_rx_byte(b, now_ms & 0xFFFFFFFF)

    def tick(self, now_ms: int) -> None:
        """One millisecond tick: the link-loss guard (the AVR's timer interrupt), then the main
        loop's periodic work."""
        self._lib.robot_guard(now_ms & 0xFFFFFFFF)
        self._lib.robot_tick(now_ms & 0xFFFFFFFF)

    def take_tx(self) -> bytes:
        n = self._lib.emu_take_tx(self._buf, len(self._buf))
        return self._buf.raw[:n] if n else b""  # .raw copies the whole buffer: not for none

    def motors(self) -> tuple[int, int]:
        """Applied duty (permille) of the left and right motor."""
        self._lib.emu_motors(*self._motor_refs)
        return self._left.value, self._right.value
