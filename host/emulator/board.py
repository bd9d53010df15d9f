"""What every simulated board offers (native core, simavr ELF, simavr Uno), and the motor pins of
the two that run the real AVR binary, read from the simulator's event lines."""

from __future__ import annotations

import threading
import time
from functools import cache
from typing import Protocol

from host.emulator.build import config_define
from host.emulator.pins import Io


@cache
def pwm_top() -> int:
    """Timer1's TOP (ICR1), read from the firmware's config.h: OCR1x = duty * PWM_TOP / 1000."""
    return config_define("PWM_TOP")


class Board(Protocol):
    """A robot the simulated world can drive (native core, simavr ELF, simulated Uno, a test's
    fake): its motor outputs and its clock."""

    def motors(self) -> tuple[int, int]:
        """Duty (permille) applied to the left and right motor."""
        ...

    def advance(self, ms: float) -> None:
        """Let ms of the board's time pass."""
        ...


class PtyBoard(Board, Protocol):
    """A board running the AVR binary in real time, its UART on a pseudo-terminal."""

    path: str  # the pty the host opens


def duty(ocr: int, forward: bool, reverse: bool) -> int:
    """Duty in permille from a Timer1 compare value and the bridge's two direction inputs."""
    magnitude = ocr * 1000 // pwm_top()
    return magnitude if forward and not reverse else -magnitude if reverse and not forward else 0


class MotorPins:
    """OCR1A/OCR1B and PD4..PD7 as the simulators report them: "pwm CYCLE A B DIR" lines from
    the simulated Uno, "io CYCLE REGS..." lines from the bare-ELF harness."""

    def __init__(self) -> None:
        self.events: list[tuple[int, int, int, int]] = []  # (cycle, OCR1A, OCR1B, PD4..PD7)
        self._lock = threading.Lock()

    def feed(self, line: str) -> bool:
        """Take one event line; True if it was a pin event."""
        kind, *rest = line.split()
        if kind == "io":  # the bare-ELF harness: every watched register (hex) after the cycle
            io = Io(int(rest[0]), *(int(x, 16) for x in rest[1:]))
            event = (io.cycle, io.ocr1a, io.ocr1b, io.portd >> 4 & 0xF)
        elif kind == "pwm":  # the simulated Uno
            a, b, c, d = map(int, rest)
            event = (a, b, c, d)
        else:
            return False
        with self._lock:
            self.events.append(event)
        return True

    def motors(self) -> tuple[int, int]:
        with self._lock:
            _, a, b, d = self.events[-1] if self.events else (0, 0, 0, 0)
        return duty(a, bool(d & 1), bool(d & 2)), duty(b, bool(d & 4), bool(d & 8))


class WallClock:
    """advance() for a board that runs on the wall clock: waits until ms more have passed since
    the last call ended; a caller that fell behind (busy computing) is not made to wait."""

    def __init__(self) -> None:
        self._due = time.monotonic()

    def advance(self, ms: float) -> None:
        now = time.monotonic()
        self._due = max(self._due, now - 0.05) + ms / 1000  # at most 50 ms to catch up
        if self._due > now:
            time.sleep(self._due - now)
