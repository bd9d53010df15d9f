"""host emulate: the robot on a pseudo-terminal, for `host servo --port PATH` or any serial tool."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

from host.commands.options import NON_NEGATIVE, POSITIVE, SEED, float_range
from host.emulator.emulator import Emulator, Faults, PtyService
from host.errors import HostError
from host.files import check_folder

if TYPE_CHECKING:
    from host.emulator.uno import Reset

FLASH_DEFAULT = Path("uno-flash.bin")
RESET_LINES_PER_S = 3  # an erased chip resets ~60 times a second: say so once, not 60 times


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--simavr", action="store_true",
                   help="run the real AVR binary in simavr instead of the natively built core")
    p.add_argument("--uno", action="store_true",
                   help="a simulated Arduino Uno with its bootloader: program it with avrdude "
                        "or platformio, then talk to the firmware it runs")
    p.add_argument("--flash", type=Path, default=FLASH_DEFAULT, metavar="FILE",
                   help="--uno: the board's application flash, kept between runs "
                        "(absent = an erased chip; default %(default)s)")
    p.add_argument("--drop", type=RATE, default=0.0, metavar="RATE",
                   help="drop this share of the bytes, both ways")
    p.add_argument("--corrupt", type=RATE, default=0.0, metavar="RATE",
                   help="corrupt this share of the bytes, both ways")
    p.add_argument("--delay-ms", type=NON_NEGATIVE, default=0.0, help="delay every byte (ms)")
    p.add_argument("--silent-after", type=NON_NEGATIVE, metavar="MS",
                   help="stop answering (cut the line) after MS ms (as host servo's)")
    p.add_argument("--seed", type=SEED, default=0, help="seed of the fault injection")
    p.add_argument("--duration", type=POSITIVE, metavar="S", help="stop after S seconds")
    p.set_defaults(run=run)


RATE = float_range(0, 1, hi_open=True)


def run(args: argparse.Namespace) -> int:
    """Until --duration (exit 0) or a signal: Ctrl-C, SIGTERM and SIGHUP end it with 128+n
    (host.cli), the board closed on the way out."""
    if args.simavr and args.uno:
        raise HostError("--simavr and --uno are two different boards: choose one")
    if args.flash != FLASH_DEFAULT and not args.uno:
        raise HostError("--flash is the simulated Uno's flash: it goes with --uno")
    if args.simavr or args.uno:
        _no_faults(args)
    if args.simavr:
        return _run_simavr(args)
    if args.uno:
        return _run_uno(args)
    faults = Faults(args.drop, args.corrupt, args.delay_ms,
                    args.silent_after, args.seed)
    emu = Emulator(faults)
    with PtyService(emu) as service:
        print(service.path, flush=True)
        print(f"emulating the robot on {service.path} (Ctrl-C to stop)", file=sys.stderr)
        last = None
        t_end = None if args.duration is None else time.monotonic() + args.duration
        while t_end is None or time.monotonic() < t_end:
            motors = emu.motors()
            if motors != last:
                print(f"t={emu.now_ms / 1000:8.3f} s  motors left {motors[0]:5d} "
                      f"right {motors[1]:5d} permille", file=sys.stderr, flush=True)
                last = motors
            time.sleep(0.01)
    return 0


def _no_faults(args: argparse.Namespace) -> None:
    if args.drop or args.corrupt or args.delay_ms or args.silent_after is not None:
        raise HostError("fault injection works on the native emulator only "
                        "(drop --simavr/--uno)")


def _run_simavr(args: argparse.Namespace) -> int:
    from host.emulator import build
    from host.emulator.simavr import SimavrPty

    with SimavrPty(build.simavr_harness(), build.firmware_elf()) as sim:
        print(sim.path, flush=True)
        print(f"the firmware ELF runs in simavr on {sim.path} (Ctrl-C to stop)",
              file=sys.stderr)
        time.sleep(args.duration if args.duration is not None else 1e9)
    return 0


def _run_uno(args: argparse.Namespace) -> int:
    from host.emulator.uno import SimulatedUno

    if args.flash.is_dir():
        raise HostError(f"--flash {args.flash} is a folder; name a file")
    check_folder(args.flash.parent, "--flash", target=args.flash)  # where a program is saved
    with SimulatedUno(args.flash) as uno:
        print(uno.path, flush=True)
        print(f"a simulated Arduino Uno (optiboot) on {uno.path}, flash in {args.flash}; "
              f"opening the port resets it (Ctrl-C to stop)", file=sys.stderr, flush=True)
        t_end = None if args.duration is None else time.monotonic() + args.duration
        seen_resets, seen_saves, seen_crashes, last = 0, 0, 0, None
        resets = _ResetLines()
        while t_end is None or time.monotonic() < t_end:
            for r in uno.resets[seen_resets:]:
                resets.add(r, time.monotonic())
            for c in uno.crashes[seen_crashes:]:
                print(f"the program stopped the simulated CPU at {c / 16e6:8.3f} s; it "
                      f"restarts at the next reset (open the port)", file=sys.stderr)
            for n in uno.saves[seen_saves:]:
                print(f"programmed: {n} bytes saved to {args.flash}", file=sys.stderr)
            seen_resets, seen_saves = len(uno.resets), len(uno.saves)
            seen_crashes = len(uno.crashes)
            if uno.motors() != last:
                last = uno.motors()
                print(f"motors left {last[0]:5d} right {last[1]:5d} permille",
                      file=sys.stderr, flush=True)
            time.sleep(0.01)
    return 0


class _ResetLines:
    """Reset lines, at most RESET_LINES_PER_S a second; beyond that one line that says the
    chip keeps resetting (an erased flash: the bootloader starts over and over)."""

    def __init__(self) -> None:
        self.window, self.shown, self.said = 0.0, 0, False

    def add(self, r: Reset, now: float) -> None:
        if now - self.window >= 1.0:
            self.window, self.shown = now, 0
        self.shown += 1
        if self.shown <= RESET_LINES_PER_S:
            print(f"reset at {r.cycle / 16e6:8.3f} s ({r.flags})", file=sys.stderr)
        elif not self.said:
            self.said = True
            print("the chip keeps resetting (an erased flash restarts the bootloader over and "
                  "over): further resets are not shown; upload a program (make flash PORT=...)",
                  file=sys.stderr, flush=True)
