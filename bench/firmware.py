"""Firmware figures, all in simulated time under simavr and at the pins (host/emulator/pins.py
derives the enable waveform from Timer1's registers): flash and RAM (avr-size), PWM frequency and
duty, the link-loss stop time when quiet and under floods at line rate without flow control,
overruns and dropped replies, the dead interval on reversal, latency, and simavr's speed."""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from host.emulator import build
from host.emulator.pins import timeline
from host.emulator.simavr import CYCLES_PER_BYTE, F_CPU, FLOODS, Script, flood, run
from host.emulator.simavr import CYCLES_PER_MS as MS
from host.link import protocol_gen as gen
from host.link.frame import encode_frame
from host.link.messages import pack, unpack

NO_RAMP = gen.SetConfig(link_timeout_ms=gen.DEFAULT_LINK_TIMEOUT_MS, accel_limit=0)
FRAME = len(encode_frame(0, *pack(NO_RAMP)))  # bytes of a SET_CONFIG or SET_DRIVE frame


def driving(d) -> bool:
    return d.enable.driven and d.enable.duty > 0


def size(elf: Path) -> None:
    out = subprocess.run(["avr-size", "-A", str(elf)], capture_output=True, text=True).stdout
    sections = {p[0]: int(p[1]) for p in (line.split() for line in out.splitlines())
                if len(p) >= 2 and p[0].startswith(".") and p[1].isdigit()}
    flash = sections.get(".text", 0) + sections.get(".data", 0)
    ram = sections.get(".data", 0) + sections.get(".bss", 0) + sections.get(".noinit", 0)
    print(f"flash {flash} bytes (budget 4096), RAM data+bss+noinit {ram} bytes (budget 384)")


def stop_times(harness: Path, elf: Path) -> None:
    """The SET_DRIVE's stop bit to the enable pin off, 8 runs per kind at shifted phases."""
    for kind in ("quiet", *FLOODS):
        stops, overruns, dropped, nacks = [], [], [], []
        for i in range(8):
            s = Script().run_ms(2 + i * 0.137).message(0, NO_RAMP).run_ms(2)
            s.message(1, gen.SetDrive(left=500, right=500)).run_ms(3).quiet()
            if kind != "quiet":
                s.flow(False).send(flood(kind, 500 * MS // CYCLES_PER_BYTE, seed=i))
            s.run_ms(520).flow(True).quiet(False).message(2, gen.GetStatus()).run_ms(10)
            r = run(harness, elf, s)
            done = r.ins[2 * FRAME - 1][0] + CYCLES_PER_BYTE
            t = [d for d in timeline(r.io, "left") if d.cycle > done]
            on = next(k for k, d in enumerate(t) if driving(d))
            off = next(d for d in t[on:] if not driving(d))
            stops.append((off.cycle - done) / MS)
            msgs = [unpack(f.id, f.payload) for f in r.frames()]
            status = msgs[-1]
            overruns.append(status.rx_overruns)
            dropped.append(status.tx_dropped)
            nacks.append(sum(m.NAME == "NACK" for m in msgs))
            assert not r.resets
        print(f"link-loss stop, {kind:10s}: {min(stops):.3f}..{max(stops):.3f} ms after the last "
              f"accepted SET_DRIVE (timeout {gen.DEFAULT_LINK_TIMEOUT_MS} ms, 8 runs); "
              f"rx_overruns {min(overruns)}..{max(overruns)}, tx_dropped "
              f"{min(dropped)}..{max(dropped)}, NACKs sent {min(nacks)}..{max(nacks)}")


def pwm(harness: Path, elf: Path) -> None:
    r = run(harness, elf, Script().run_ms(2).message(0, NO_RAMP).run_ms(2)
            .message(1, gen.SetDrive(left=500, right=-250)).run_ms(5))
    for motor in ("left", "right"):
        d = timeline(r.io, motor)[-1]
        print(f"PWM at the {motor} enable pin for {500 if motor == 'left' else -250} permille: "
              f"{d.enable.freq_hz:.0f} Hz, duty {d.enable.duty * 100:.1f} %, "
              f"inputs {d.direction}")


def reversal(harness: Path, elf: Path) -> None:
    for accel in (0, gen.DEFAULT_ACCEL_LIMIT):
        dead = []
        for i in range(5):
            s = Script().run_ms(2 + i * 0.211)
            s.message(0, gen.SetConfig(link_timeout_ms=1000, accel_limit=accel)).run_ms(2)
            s.message(1, gen.SetDrive(left=600, right=600)).run_ms(200)
            s.message(2, gen.SetDrive(left=-600, right=-600)).run_ms(400)
            t = timeline(run(harness, elf, s).io, "left")
            fwd = max(k for k, d in enumerate(t) if driving(d) and d.direction == "forward")
            rev = min(k for k, d in enumerate(t) if driving(d) and d.direction == "reverse")
            dead.append((t[rev].cycle - t[fwd + 1].cycle) / MS)
        print(f"reversal +600 -> -600 permille, accel_limit {accel}: enable off for "
              f"{min(dead):.3f}..{max(dead):.3f} ms between the last forward and the first reverse"
              f" pulse (reverse_coast_ms {gen.DEFAULT_REVERSE_COAST_MS}, 5 runs)")


def latency_and_speed(harness: Path, elf: Path) -> None:
    lat = []
    for i in range(20):
        duty = 50 * (i + 1) * (-1) ** i
        r = run(harness, elf, Script().run_ms(3 + i * 0.37).message(0, NO_RAMP).run_ms(2)
                .message(1, gen.SetDrive(left=duty, right=-duty)).run_ms(5))
        first = next(p for p in r.pwm if p.cycle > r.last_in_done())
        lat.append(first.cycle - r.last_in_done())
    print(f"SET_DRIVE last byte (stop bit) -> first motor register write: median "
          f"{statistics.median(lat):.0f} cycles ({statistics.median(lat) / 16:.0f} us), "
          f"max {max(lat)} cycles, over {len(lat)} frames")
    n = 5400
    data = b"".join(encode_frame(i & 0xFF, *pack(gen.SetDrive(left=100, right=100)))
                    for i in range(n))
    r = run(harness, elf, Script().quiet().send(data).run_ms(5100))
    sim_s = r.end_cycle / F_CPU
    print(f"simavr speed with line-rate traffic: {sim_s:.2f} s simulated in {r.seconds:.2f} s"
          f" wall = {sim_s / r.seconds:.1f}x real time; resets {len(r.resets)}")
    r = run(harness, elf, Script().run_ms(5000))
    print(f"simavr speed idle (the firmware sleeps between 1 ms ticks): "
          f"{r.end_cycle / F_CPU / r.seconds:.1f}x real time")


def main() -> int:
    elf = build.firmware_elf()
    print(f"# conditions: {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.2f}; simulated time")
    size(elf)
    with tempfile.TemporaryDirectory() as d:
        harness = build.simavr_harness(Path(d))
        pwm(harness, elf)
        reversal(harness, elf)
        stop_times(harness, elf)
        latency_and_speed(harness, elf)
    return 0


if __name__ == "__main__":
    sys.exit(main())
