"""Firmware figures, all in simulated time under simavr: flash and RAM (avr-size), cycles from
a SET_DRIVE's last byte to the PWM update, the link-loss stop time, and simavr's speed."""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from host.emulator import build
from host.emulator.simavr import F_CPU, Script, run
from host.link import protocol_gen as gen
from host.link.frame import encode_frame
from host.link.messages import pack


def main() -> int:
    elf = build.firmware_elf()
    size = subprocess.run(["avr-size", "-A", str(elf)], capture_output=True, text=True).stdout
    sections = {p[0]: int(p[1]) for p in (line.split() for line in size.splitlines())
                if len(p) >= 2 and p[0].startswith(".") and p[1].isdigit()}
    flash = sections.get(".text", 0) + sections.get(".data", 0)
    ram = sections.get(".data", 0) + sections.get(".bss", 0) + sections.get(".noinit", 0)
    print(f"flash {flash} bytes (budget 4096), RAM data+bss+noinit {ram} bytes (budget 384)")
    with tempfile.TemporaryDirectory() as d:
        harness = build.simavr_harness(Path(d))
        lat = []
        for i in range(20):
            duty = 50 * (i + 1) * (-1) ** i
            r = run(harness, elf, Script().run_ms(3 + i * 0.37)
                    .message(1, gen.SetDrive(left=duty, right=-duty)).run_ms(5))
            first = next(p for p in r.pwm if p.cycle > r.last_in_done())
            lat.append(first.cycle - r.last_in_done())
        print(f"SET_DRIVE last byte (stop bit) -> first PWM register write: median "
              f"{statistics.median(lat):.0f} cycles ({statistics.median(lat) / 16:.0f} us), "
              f"max {max(lat)} cycles, over {len(lat)} frames")
        stops = []
        for i in range(10):
            r = run(harness, elf, Script().run_ms(2 + i * 0.29)
                    .message(1, gen.SetDrive(left=500, right=500)).run_ms(300))
            off = r.settled()[-1]
            stops.append((off.cycle - r.last_in_done()) / (F_CPU / 1000))
        print(f"link-loss stop after the last frame: {min(stops):.2f}..{max(stops):.2f} ms "
              f"(timeout {gen.DEFAULT_LINK_TIMEOUT_MS} ms)")
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
