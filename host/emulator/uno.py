"""A simulated Arduino Uno (firmware/atmega328/simavr/uno.c): the Uno's own bootloader, an
application flash kept in a file, UART0 on a pty that avrdude programs and the host talks to."""

from __future__ import annotations

import subprocess
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from host.emulator import build
from host.emulator.board import MotorPins, WallClock
from host.emulator.process import stop
from host.errors import HostError

# Debian's arduino-core-avr: optiboot 4.4, the version Unos carry (Debian's build overruns the
# 512-byte boot section; uno.c says how the simulated flash makes room)
OPTIBOOT = Path("/usr/share/arduino/hardware/arduino/avr/bootloaders/optiboot/"
                "optiboot_atmega328.hex")
SOURCE = build.FIRMWARE / "simavr" / "uno.c"
MCUSR_BITS = {0x01: "PORF", 0x02: "EXTRF", 0x04: "BORF", 0x08: "WDRF"}


def program(out_dir: Path | None = None) -> Path:
    """Compile uno.c against libsimavr into out_dir (default: the cache), again when it
    changes."""
    return build.simavr_program(SOURCE, "simavr-uno", out_dir)


@dataclass(frozen=True)
class Reset:
    cycle: int  # CPU cycles since power-on
    mcusr: int  # as the bootloader finds it

    @property
    def flags(self) -> str:
        return "+".join(n for bit, n in MCUSR_BITS.items() if self.mcusr & bit) or "none"


class SimulatedUno:
    """The simulated board as a process; path is its serial port.

    Opening the port resets the chip through its bootloader (the Uno's DTR auto-reset); the
    application section lives in flash (a file; absent = an erased chip) and is saved when the
    bootloader has written it. bootloader=None: a chip flashed over ISP, which starts the
    application directly. autoreset=False: the board's RESET-EN trace cut, opening the port
    leaves the chip running. Events (resets, motor outputs, saves) are read as they come.
    """

    def __init__(self, flash: Path, out_dir: Path | None = None,
                 bootloader: Path | None = OPTIBOOT, autoreset: bool = True) -> None:
        if bootloader is not None and not bootloader.exists():
            raise build.ToolMissing(f"the Uno's bootloader {bootloader} is missing: install "
                            "arduino-core-avr (make system-deps, as root)")
        exe = program(out_dir)
        self.flash = flash
        self.resets: list[Reset] = []
        self.saves: list[int] = []  # bytes programmed, at each save of the flash file
        self.crashes: list[int] = []  # cycles at which simavr stopped the CPU (until a reset)
        self.pins = MotorPins()
        self._clock = WallClock()
        self._cond = threading.Condition()
        args = [str(exe), str(bootloader or "-"), str(flash)]
        self._proc = subprocess.Popen(args + ([] if autoreset else ["--no-autoreset"]),
                                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        assert self._proc.stdout is not None
        first = self._proc.stdout.readline().split()
        if first[:1] != ["pty"]:
            err = self._proc.communicate(timeout=5)[1].strip()
            raise HostError(f"the simulated Uno did not start: {err or 'no port'}")
        self.path: str = first[1]
        self._reader = threading.Thread(target=self._read, name="uno-events", daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self._proc.stdout is not None
        for line in self._proc.stdout:
            kind, *rest = line.split()
            with self._cond:
                if kind == "reset":
                    self.resets.append(Reset(int(rest[0]), int(rest[1], 16)))
                elif kind == "pwm":
                    self.pins.feed(line)
                elif kind == "saved":
                    self.saves.append(int(rest[0]))
                elif kind == "crashed":
                    self.crashes.append(int(rest[0]))
                self._cond.notify_all()

    def wait(self, condition: Callable[[SimulatedUno], bool], timeout_s: float) -> bool:
        """Wait until condition(self) holds (checked at each event) or timeout_s passes."""
        with self._cond:
            return self._cond.wait_for(lambda: condition(self), timeout_s)

    def motors(self) -> tuple[int, int]:
        """Duty (permille) the flashed firmware applies to the left and right motor, read from
        OCR1A/OCR1B and the direction pins PD4..PD7."""
        return self.pins.motors()

    def advance(self, ms: float) -> None:
        """Let ms of the board's time pass. The board runs on the wall clock, so this waits."""
        self._clock.advance(ms)

    def stderr(self) -> str:
        """What the simulator said on stderr (after close)."""
        return self._proc.stderr.read() if self._proc.stderr and self._proc.poll() is not None \
            else ""

    def close(self) -> None:
        """Stop the board; it saves the flash file first if the bootloader changed it."""
        stop(self._proc)
        self._reader.join(timeout=2)

    def __enter__(self) -> SimulatedUno:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def avrdude(port: str, hex_file: Path, timeout_s: float = 90,
            extra: tuple[str, ...] = ()) -> subprocess.CompletedProcess[str]:
    """Upload hex_file through an Uno's bootloader, as `make flash` does; output in .stderr."""
    build._need("avrdude", "avrdude")
    return subprocess.run(["avrdude", "-p", "atmega328p", "-c", "arduino", "-P", port,
                           "-b", "115200", *extra, "-U", f"flash:w:{hex_file}:i"],
                          capture_output=True, text=True, timeout=timeout_s)


def hex_image(hex_file: Path) -> dict[int, int]:
    """Address -> byte of the data records of an Intel HEX file (to compare with the flash)."""
    image: dict[int, int] = {}
    for line in hex_file.read_text().split():
        raw = bytes.fromhex(line[1:])
        if raw[3] == 0:
            base = int.from_bytes(raw[1:3], "big")
            image.update((base + i, b) for i, b in enumerate(raw[4:4 + raw[0]]))
    return image
