"""The robot on a PC: the firmware's core with a simulated clock, a 115200-baud line, link
faults, and a pseudo-terminal that any serial program can open as if it were the robot (the
simulation talks to it in-process instead, host.emulator.lockstep)."""

from __future__ import annotations

import contextlib
import os
import select
import threading
import time
import tty
from collections import deque
from dataclasses import dataclass

import numpy as np

from host.emulator.core import FirmwareCore
from host.link import protocol_gen as gen

BYTES_PER_MS = gen.BAUD / 10 / 1000  # 8N1: ten bits a byte
TO_ROBOT, TO_HOST = 0, 1  # the line's two directions


@dataclass(frozen=True)
class Faults:
    """Link faults, applied to every byte in both directions. Rates are probabilities per byte;
    whether the n-th byte of a direction is hit is drawn from (seed, direction, n) alone, so a
    resend does not change which later bytes are hit. At reset_at_ms the board resets (its
    motors stop, it forgets its configuration and session) with reset_cause; boot_lost: the
    BOOT frame it sends then never reaches the host."""

    drop: float = 0.0
    corrupt: float = 0.0
    delay_ms: float = 0.0
    silent_after_ms: float | None = None  # then the line is cut both ways
    seed: int = 0
    reset_at_ms: float | None = None
    reset_cause: int = gen.ResetCause.WATCHDOG
    boot_lost: bool = False


class ByteDraws:
    """Counter-based draws for the line's faults: (drop, corrupt, xor) of byte n of a direction
    depend on (seed, direction, n) only, computed a block of positions at a time."""

    BLOCK = 4096

    def __init__(self, seed: int) -> None:
        self.seed = seed
        self._blocks: dict[tuple[int, int], np.ndarray] = {}

    def at(self, direction: int, n: int) -> tuple[float, float, int]:
        key = (direction, n // self.BLOCK)
        block = self._blocks.get(key)
        if block is None:
            block = np.random.default_rng([self.seed, *key]).random((self.BLOCK, 3))
            self._blocks = {key: block, **{k: v for k, v in self._blocks.items()
                                           if k[0] != direction}}
        drop, corrupt, xor = block[n % self.BLOCK]
        return float(drop), float(corrupt), 1 + int(xor * 255)

    def rows(self, direction: int, n0: int, count: int) -> list[list[float]]:
        """The draws (drop, corrupt, xor as drawn) of bytes n0 .. n0+count-1 of a direction:
        at()'s, taken a block's run at a time (a frame's bytes in one slice, not one numpy
        index and three conversions a byte)."""
        out: list[list[float]] = []
        n, end = n0, n0 + count
        while n < end:
            self.at(direction, n)  # its block, made or kept as at() keeps it
            block = self._blocks[(direction, n // self.BLOCK)]
            stop = min(end, (n // self.BLOCK + 1) * self.BLOCK)
            out += block[n % self.BLOCK:n % self.BLOCK + stop - n].tolist()
            n = stop
        return out


class Emulator:
    """The firmware core, a clock in ms, and the serial line to the host.

    Time moves only through advance(); bytes from the host are queued by receive() and reach
    the core when their due time comes (line rate in line_rate mode, else at once); the core's
    bytes come back through transmit().
    """

    def __init__(self, faults: Faults = Faults(), line_rate: bool = True,
                 reset_cause: int = gen.ResetCause.POWER_ON) -> None:
        self.faults = faults
        self.line_rate = line_rate
        self.now_ms = 0.0
        self._draws = ByteDraws(faults.seed)
        self._sent = [0, 0]  # bytes that entered the line, per direction
        self.resets = 0  # resets of the fault model (Faults.reset_at_ms) so far
        self._core = FirmwareCore(reset_cause, 0)
        self._inbound: deque[tuple[float, int]] = deque()
        self._outbound: deque[tuple[float, int]] = deque()
        self._line_free_ms = 0.0  # when the line to the robot is free again
        self._tx_free_ms = 0.0    # when the line to the host is free again
        self._ticked_ms = 0
        self.lock = threading.RLock()
        record = os.environ.get("HOST_EMULATOR_RECORD")  # test hook: keep what the host sent
        self._record = open(record, "ab", buffering=0) if record else None  # noqa: SIM115
        self._collect()

    @property
    def silent(self) -> bool:
        after = self.faults.silent_after_ms
        return after is not None and self.now_ms >= after

    def _faulty(self, data: bytes, direction: int) -> list[int]:
        f = self.faults
        n0 = self._sent[direction]
        self._sent[direction] += len(data)
        if not (f.drop or f.corrupt):
            return list(data)
        out = []
        p_drop, p_corrupt = f.drop, f.corrupt
        for b, (drop, corrupt, xor) in zip(data, self._draws.rows(direction, n0, len(data)),
                                           strict=True):
            if drop < p_drop:
                continue
            if corrupt < p_corrupt:
                b ^= 1 + int(xor * 255)
            out.append(b)
        return out

    def _reset_due(self) -> None:
        """The fault model's reset: the core starts again at this time, the bytes on their way
        to it and in its transmit buffer lost; its BOOT frame lost too when boot_lost."""
        f = self.faults
        if f.reset_at_ms is None or self.resets or self.now_ms < f.reset_at_ms:
            return
        self.resets += 1
        self._inbound.clear()
        self._core = FirmwareCore(f.reset_cause, int(self.now_ms))  # a board just started
        if f.boot_lost:
            self._core.take_tx()

    def receive(self, data: bytes) -> None:
        """Bytes the host wrote, starting on the line now."""
        with self.lock:
            if self._record:
                self._record.write(data)
            if self.silent:
                return
            for b in self._faulty(data, TO_ROBOT):
                start = max(self.now_ms, self._line_free_ms) if self.line_rate else self.now_ms
                self._line_free_ms = start + (1 / BYTES_PER_MS if self.line_rate else 0.0)
                self._inbound.append((self._line_free_ms + self.faults.delay_ms, b))

    def transmit(self) -> bytes:
        """Bytes from the robot that have reached the host by now."""
        with self.lock:
            out = bytearray()
            while self._outbound and self._outbound[0][0] <= self.now_ms:
                out.append(self._outbound.popleft()[1])
            return bytes(out)

    def _deliver(self) -> None:
        while self._inbound and self._inbound[0][0] <= self.now_ms:
            self._core.rx(bytes([self._inbound.popleft()[1]]), int(self.now_ms))

    def _collect(self) -> None:
        self._queue_tx(self._core.take_tx())

    def _queue_tx(self, data: bytes) -> None:
        """The core's bytes (just taken from it) onto the line to the host."""
        if not data or self.silent:
            return
        for b in self._faulty(data, TO_HOST):
            if self.line_rate:
                self._tx_free_ms = max(self.now_ms, self._tx_free_ms) + 1 / BYTES_PER_MS
                due = self._tx_free_ms
            else:
                due = self.now_ms
            self._outbound.append((due + self.faults.delay_ms, b))

    def process(self) -> None:
        """Hand the core every byte due by now, without moving the clock."""
        with self.lock:
            self._deliver()
            self._collect()

    def advance(self, ms: float) -> None:
        """Move the clock on by ms, ticking the core every millisecond. (The simulation calls
        this every simulated millisecond: the reset and the delivery are looked at only when
        one is set or due, the same steps as calling them every millisecond.)"""
        with self.lock:
            end = self.now_ms + ms
            inbound = self._inbound
            while self.now_ms < end:
                self.now_ms = now = min(end, float(int(self.now_ms) + 1))
                if self.faults.reset_at_ms is not None:
                    self._reset_due()
                if inbound and inbound[0][0] <= now:
                    self._deliver()
                if int(now) != self._ticked_ms:
                    self._ticked_ms = int(now)
                    self._core.tick(self._ticked_ms)
                self._collect()

    def motors(self) -> tuple[int, int]:
        """Applied duty (permille) of the left and right motor."""
        with self.lock:
            return self._core.motors()

    def has_tx(self) -> bool:
        """Whether transmit() would return bytes now."""
        with self.lock:
            return bool(self._outbound) and self._outbound[0][0] <= self.now_ms

    def lockstep(self) -> Lockstep | None:
        """The pieces of one millisecond of advance(1), for a caller stepping the world in the
        same loop (host.sim.source): None when a step needs more than they do (a reset to
        come, a clock between milliseconds)."""
        if self.faults.reset_at_ms is not None or self.now_ms != int(self.now_ms):
            return None
        return Lockstep(self)


class Lockstep:
    """advance(1) and motors() of an Emulator without a reset to come and on a whole
    millisecond, taken apart for a loop that calls them every millisecond: the same calls into
    the core in the same order (the caller holds the emulator's lock)."""

    def __init__(self, emu: Emulator) -> None:
        core = emu._core
        lib = core._lib
        self.guard, self.tick, self.take = lib.robot_guard, lib.robot_tick, lib.emu_take_tx
        self.read_motors, self.motor_refs = lib.emu_motors, core._motor_refs
        self.left, self.right, self.buf = core._left, core._right, core._buf
        self.emu, self.core = emu, core

    def current(self) -> bool:
        """Whether these are still the emulator's pieces (its core the same, no reset to come,
        its clock on a whole millisecond)."""
        emu = self.emu
        return (emu._core is self.core and emu.faults.reset_at_ms is None
                and emu.now_ms == int(emu.now_ms))

    def motors(self) -> tuple[int, int]:
        self.read_motors(*self.motor_refs)
        return self.left.value, self.right.value

    def advance_1(self) -> None:
        """advance(1): the clock on a millisecond, the due bytes delivered, the core ticked,
        its bytes collected."""
        emu = self.emu
        emu.now_ms = now = emu.now_ms + 1.0
        inbound = emu._inbound
        if inbound and inbound[0][0] <= now:
            emu._deliver()
        n = int(now)
        if n != emu._ticked_ms:
            emu._ticked_ms = n
            self.guard(n & 0xFFFFFFFF)
            self.tick(n & 0xFFFFFFFF)
        k = self.take(self.buf, len(self.buf))
        if k:
            emu._queue_tx(self.buf.raw[:k])


class PtyService:
    """Serves an emulator on a pseudo-terminal from a background thread.

    realtime: the clock follows the wall clock. Otherwise the caller moves it (advance) and
    bytes are handled at once at the current time, which keeps a simulation deterministic.
    """

    def __init__(self, emulator: Emulator, realtime: bool = True) -> None:
        self.emulator = emulator
        self.realtime = realtime
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)  # raw mode; the slave stays open so clients may come and go
        os.set_blocking(self._master, False)
        self.path = os.ttyname(self._slave)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="pty-emulator", daemon=True)

    def start(self) -> PtyService:
        self._thread.start()
        return self

    def _run(self) -> None:
        t0 = time.monotonic()
        emu = self.emulator
        while not self._stop.is_set():
            ready, _, _ = select.select([self._master], [], [], 0.001)
            if ready:
                with contextlib.suppress(OSError):  # no client has the port open
                    emu.receive(os.read(self._master, 4096))
            if self.realtime:
                now = (time.monotonic() - t0) * 1000
                if now > emu.now_ms:
                    emu.advance(now - emu.now_ms)
            else:
                emu.process()
            out = emu.transmit()
            if out:
                with contextlib.suppress(OSError):
                    os.write(self._master, out)

    def close(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=2)
        for fd in (self._master, self._slave):
            with contextlib.suppress(OSError):
                os.close(fd)

    def __enter__(self) -> PtyService:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()
