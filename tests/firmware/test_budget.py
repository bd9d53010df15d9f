"""The firmware's budget (issue 29): 4 KB of flash and 384 B of RAM, the RAM counted as the static
data plus the deepest the stack reaches under the costliest traffic, measured in simavr with RAM
filled with a pattern at power-on (harness: fill, stack)."""

from __future__ import annotations

import subprocess

from host.emulator.simavr import CYCLES_PER_BYTE, Script, flood
from host.link import protocol_gen as gen
from tests.firmware.common import MS

FLASH_BUDGET = 4096
RAM_BUDGET = 384


def _size(elf) -> tuple[int, int]:
    """(flash, static RAM): text + data, data + bss + noinit (avr-size's sysv sections)."""
    out = subprocess.run(["avr-size", "-A", str(elf)], capture_output=True, text=True,
                         check=True).stdout
    sec = {line.split()[0]: int(line.split()[1]) for line in out.splitlines()
           if line.startswith(".")}
    return sec.get(".text", 0) + sec.get(".data", 0), sum(
        sec.get(s, 0) for s in (".data", ".bss", ".noinit"))


def _symbol(elf, name: str) -> int:
    out = subprocess.run(["avr-nm", str(elf)], capture_output=True, text=True, check=True).stdout
    return next(int(line.split()[0], 16) & 0xFFFF for line in out.splitlines()
                if line.split()[-1] == name)


def test_the_firmware_fits_its_flash_budget(firmware_elf) -> None:
    flash, _ = _size(firmware_elf)
    assert flash <= FLASH_BUDGET, f"{flash} B of flash, budget {FLASH_BUDGET}"


def test_static_ram_and_the_deepest_stack_under_floods_fit_the_ram_budget(
        harness, firmware_elf) -> None:
    _, static = _size(firmware_elf)
    end = _symbol(firmware_elf, "_end")  # the first byte after .data, .bss and .noinit
    s = Script()
    s.lines.append("fill 7")
    s.run_ms(2).message(0, gen.SetConfig(link_timeout_ms=5000, accel_limit=400)).run_ms(2)
    s.message(1, gen.SetDrive(left=600, right=-600)).run_ms(2).quiet().flow(False)
    unit = bytes([gen.START, gen.MAX_PAYLOAD])  # nested false frames: the parser's worst
    s.send(unit * (100 * MS // CYCLES_PER_BYTE // 2)).run_ms(110)
    for kind in ("bad-crc", "get-status", "refused", "garbage"):
        s.send(flood(kind, 100 * MS // CYCLES_PER_BYTE)).run_ms(110)
    s.flow(True).send(bytes(2 * gen.MAX_PAYLOAD)).message(2, gen.Hello(nonce=1)).run_ms(5)
    s.message(3, gen.GetStatus()).run_ms(5)
    s.lines.append(f"stack 7 {end:x}")
    out = subprocess.run([str(harness), str(firmware_elf)], input=s.text(), capture_output=True,
                         text=True, timeout=120, check=True).stdout
    lowest = int(next(line for line in out.splitlines() if line.startswith("stack ")).split()[1],
                 16)
    stack = 0x900 - lowest  # RAMEND is 0x8FF
    assert 40 < stack < 0x900 - end, stack  # the pattern was there, and the stack did run
    assert static + stack <= RAM_BUDGET, f"{static} B static + {stack} B of stack"
    print(f"flash {_size(firmware_elf)[0]} B, RAM {static} B static + {stack} B stack")
