"""Run the real firmware ELF under simavr (firmware/atmega328/simavr/harness.c) from a script,
and read back what its registers, pins (host/emulator/pins.py) and UART did, in simulated CPU
cycles."""

from __future__ import annotations

import random
import subprocess
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from host.emulator.board import MotorPins, WallClock
from host.emulator.pins import F_CPU, Io
from host.emulator.process import stop
from host.link import protocol_gen as gen
from host.link.frame import Frame, FrameDecoder, encode_frame
from host.link.messages import pack, unpack

CYCLES_PER_MS = F_CPU // 1000  # simulated time: CPU cycles in a millisecond
CYCLES_PER_BYTE = 10 * F_CPU // gen.BAUD  # the harness feeds bytes at the host's line rate


@dataclass
class Pwm:
    """The motor registers after a change: compare values and PD4..PD7 (IN1 IN2 IN3 IN4 as
    bits 0..3)."""

    cycle: int
    ocr1a: int
    ocr1b: int
    dir: int


@dataclass
class SimRun:
    ins: list[tuple[int, int]] = field(default_factory=list)   # (cycle, byte) into the UART
    tx: list[tuple[int, int]] = field(default_factory=list)    # (cycle, byte) out of the UART
    io: list[Io] = field(default_factory=list)                 # register states, by change
    pwm: list[Pwm] = field(default_factory=list)               # motor registers, by change
    resets: list[int] = field(default_factory=list)
    end_cycle: int = 0
    seconds: float = 0.0
    n_in: int = 0
    n_tx: int = 0

    def frames(self) -> list[Frame]:
        return FrameDecoder().feed(bytes(b for _, b in self.tx))

    def messages(self) -> list[Any]:
        """The firmware's frames as message objects (host.link.messages.unpack)."""
        return [unpack(f.id, f.payload) for f in self.frames()]

    def settled(self) -> list[Pwm]:
        """Output changes with the transients dropped: the firmware writes OCR1A, then OCR1B a
        few cycles later; a state that lasted under 100 cycles is not a state."""
        out = []
        for p, nxt in zip(self.pwm, self.pwm[1:] + [None]):
            if nxt is None or nxt.cycle - p.cycle >= 100:
                out.append(p)
        return out

    def last_in_done(self) -> int:
        """Cycle at which the last byte sent had fully arrived (its stop bit)."""
        return self.ins[-1][0] + CYCLES_PER_BYTE


FLOODS = ("bad-crc", "get-status", "refused", "garbage")


def flood(kind: str, n_bytes: int, seed: int = 11) -> bytes:
    """At least n_bytes of hostile traffic: SET_DRIVE frames with a bad CRC, valid GET_STATUS
    polls, refused frames (good CRC, duty out of range) or random garbage."""
    if kind == "garbage":
        rng = random.Random(seed)
        return bytes(rng.randrange(256) for _ in range(n_bytes))
    frames: list[bytes] = []
    size = 0
    while size < n_bytes:
        i = len(frames) & 0xFF
        if kind == "bad-crc":
            f = bytearray(encode_frame(i, *pack(gen.SetDrive(left=700, right=700))))
            f[-1] ^= 0x5A
        elif kind == "get-status":
            f = bytearray(encode_frame(i, *pack(gen.GetStatus())))
        elif kind == "refused":
            f = bytearray(encode_frame(i, gen.SetDrive.ID,
                                       (1500).to_bytes(2, "little", signed=True) + bytes(2)))
        else:
            raise ValueError(f"unknown flood {kind!r}")
        frames.append(bytes(f))
        size += len(f)
    return b"".join(frames)


class Script:
    """Commands for the harness: send bytes, let simulated time pass."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def send(self, data: bytes) -> Script:
        self.lines.append(f"send {data.hex()}")
        return self

    def message(self, seq: int, msg: object) -> Script:
        return self.send(encode_frame(seq, *pack(msg)))

    def run_ms(self, ms: float) -> Script:
        self.lines.append(f"run {ms}")
        return self

    def flow(self, on: bool) -> Script:
        """on: bytes go in only while simavr's UART can take them; off: at line rate regardless,
        so that the receiver overruns when the firmware falls behind."""
        self.lines.append(f"flow {int(on)}")
        return self

    def quiet(self, on: bool = True) -> Script:
        self.lines.append(f"quiet {int(on)}")
        return self

    def text(self) -> str:
        return "\n".join(self.lines) + "\n"


def run(harness: Path, elf: Path, script: Script, timeout: float = 120) -> SimRun:
    out = subprocess.run([str(harness), str(elf)], input=script.text(), capture_output=True,
                         text=True, timeout=timeout)
    if out.returncode:
        raise RuntimeError(f"harness failed ({out.returncode}): {out.stderr}{out.stdout[-500:]}")
    return parse(out.stdout.splitlines())


def parse(lines: list[str]) -> SimRun:
    """The harness's event lines (see harness.c) as a SimRun."""
    r = SimRun()
    for line in lines:
        kind, *rest = line.split()
        if kind == "in":
            r.ins.append((int(rest[0]), int(rest[1], 16)))
        elif kind == "tx":
            r.tx.append((int(rest[0]), int(rest[1], 16)))
        elif kind == "io":
            io = Io(int(rest[0]), *(int(x, 16) for x in rest[1:]))
            r.io.append(io)
            p = Pwm(io.cycle, io.ocr1a, io.ocr1b, io.portd >> 4 & 0xF)
            if not r.pwm or (r.pwm[-1].ocr1a, r.pwm[-1].ocr1b, r.pwm[-1].dir) != (
                    p.ocr1a, p.ocr1b, p.dir):
                r.pwm.append(p)
        elif kind == "reset":
            r.resets.append(int(rest[0]))
        elif kind == "end":
            r.end_cycle, r.n_in, r.n_tx = int(rest[0]), int(rest[2]), int(rest[3])
            r.seconds = float(rest[5])
        elif kind == "crashed":
            raise RuntimeError(f"firmware crashed: {line}")
    return r


class SimavrPty:
    """The real ELF in simavr, in real time, its UART0 on a pseudo-terminal; its motor pins are
    read from the harness's events (a Board, like the native emulator and the simulated Uno)."""

    def __init__(self, harness: Path, elf: Path) -> None:
        self.pins = MotorPins()
        self._clock = WallClock()
        self._proc = subprocess.Popen([str(harness), str(elf), "--pty"], stdout=subprocess.PIPE,
                                      stderr=subprocess.PIPE, text=True)
        assert self._proc.stdout is not None
        for line in self._proc.stdout:  # simavr's own "Loaded ..." lines come first
            if line.startswith("pty "):
                self.path = line.split()[1]
                break
        else:
            self.close()
            raise RuntimeError("the simavr harness did not start")
        self._reader = threading.Thread(target=self._read_events, daemon=True)
        self._reader.start()

    def _read_events(self) -> None:
        assert self._proc.stderr is not None
        for line in self._proc.stderr:  # pwm and reset events
            if line.strip():
                self.pins.feed(line)

    def motors(self) -> tuple[int, int]:
        """Duty (permille) the firmware applies, from OCR1A/OCR1B and PD4..PD7."""
        return self.pins.motors()

    def advance(self, ms: float) -> None:
        """Let ms of the board's time pass (it runs on the wall clock, so this waits)."""
        self._clock.advance(ms)

    def close(self) -> None:
        """Stop the simulator (killed if it does not exit within 5 s)."""
        stop(self._proc)
        if hasattr(self, "_reader"):
            self._reader.join(timeout=2)

    def __enter__(self) -> SimavrPty:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
