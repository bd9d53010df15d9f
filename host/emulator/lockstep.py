"""The simulation's serial line, in-process and on the simulated clock: the host's bytes go into
the emulator (the real framing, CRC and the firmware core's parser, at line rate, with the link
faults), and every wait of the link lets simulated time pass for the whole world."""

from __future__ import annotations

import math
from collections.abc import Callable

from host.emulator.emulator import Emulator
from host.link.port import PortError


class LockstepLine:
    """A host.link.port.Port whose clock is the simulation's: now() reads it, read(wait_s)
    moves it on a millisecond at a time through advance_ms (which steps the world and the board
    together) until a byte arrives or wait_s has passed. Nothing here depends on the wall
    clock, so a run is the same on a loaded machine."""

    name = "the simulated robot's line"

    def __init__(self, emulator: Emulator, advance_ms: Callable[[int], None],
                 now_ms: Callable[[], int],
                 advance_until_tx: Callable[[int], None] | None = None) -> None:
        """advance_until_tx(n): advance_ms(1) up to n times, stopping after the millisecond by
        which the emulator has a byte for the host (in one call: host.sim.source)."""
        self.emulator = emulator
        self._advance = advance_ms
        self._advance_until_tx = advance_until_tx
        self._now_ms = now_ms
        self._open = True

    def now(self) -> float:
        return self._now_ms() / 1000

    def write(self, data: bytes) -> None:
        if not self._open:
            raise PortError("the line is closed")
        self.emulator.receive(data)

    def read(self, wait_s: float) -> bytes:
        emu = self.emulator
        out = emu.transmit()
        n = max(1, math.ceil(wait_s * 1000 - 1e-9))
        if self._advance_until_tx is not None:
            if not out:
                self._advance_until_tx(n)
                out = emu.transmit()
            return out
        for _ in range(n):
            if out:
                break
            self._advance(1)
            out = emu.transmit()
        return out

    def close(self) -> None:
        self._open = False
