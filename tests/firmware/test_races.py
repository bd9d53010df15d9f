"""Interrupt races a few cycles wide, on the real ELF under simavr: the harness's sweep runs the
same exchange once for every instruction boundary of it, with one extra Timer0 tick landing at
that boundary (harness.c, sweep), so a window of one instruction between the main loop's steps
is hit for sure, not once in thousands of runs. Judged at the motor pins and on the wire; each
test kills mutants of firmware/atmega328/mutants.toml (named in its docstring)."""

from __future__ import annotations

import subprocess

import pytest

from host.emulator.pins import timeline
from host.emulator.simavr import CYCLES_PER_BYTE, F_CPU, SimRun, parse
from host.link import protocol_gen as gen
from host.link.frame import encode_frame
from host.link.messages import pack

DRIVE = gen.SetDrive(left=500, right=500)
PWM_PERIOD = F_CPU // 20_000  # cycles: a new OCR1x takes effect at the PWM's next TOP


def frame(seq: int, msg) -> str:
    return f"send {encode_frame(seq, *pack(msg)).hex()}"


def _trial_lines(harness, elf, before: list[str], n: int, after: list[str]) -> list[list[str]]:
    """The harness's output for each of the n trials of a sweep (harness.c), each with the
    lines before the first trial (the events before the sweep)."""
    text = "\n".join([*before, f"sweep {n}", *after]) + "\n"
    out = subprocess.run([str(harness), str(elf)], input=text, capture_output=True, text=True,
                         timeout=600)
    assert out.returncode == 0, out.stderr[-500:]
    lines = out.stdout.splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith("trial ")]
    assert len(starts) == n, f"{len(starts)} trials of {n}"
    prefix = lines[:starts[0]]
    return [prefix + lines[a:b] for a, b in zip(starts, [*starts[1:], len(lines)])]


def sweep(harness, elf, before: list[str], n: int, after: list[str]) -> list[SimRun]:
    """One SimRun per trial: the events before the sweep, then the trial's own. Trial k has an
    extra tick after k instructions of `after` (harness.c)."""
    return [parse(t) for t in _trial_lines(harness, elf, before, n, after)]


def forced_cycles(harness, elf, before: list[str], n: int, after: list[str]) -> list[tuple[int,
                                                                                        SimRun]]:
    """As sweep, each trial with the cycle at which its extra tick was raised (harness.c:
    "force CYCLE"; the CPU takes it as soon as interrupts are on)."""
    trials = []
    for t in _trial_lines(harness, elf, before, n, after):
        trial = t[next(i for i, x in enumerate(t) if x.startswith("trial ")):]
        force = next(int(x.split()[1]) for x in trial if x.startswith("force "))
        trials.append((force, parse(t)))
    return trials


def frame_cycles(r: SimRun) -> list[int]:
    """The cycle at which each frame the firmware sent began (its START byte on the line)."""
    out, i = [], 0
    for f in r.frames():
        n = len(encode_frame(f.seq, f.id, f.payload))
        while r.tx[i][1] != gen.START:
            i += 1
        out.append(r.tx[i][0])
        i += n
    return out


def status_of(r: SimRun):
    """The STATUS the trial's GET_STATUS was answered with (None: no answer, a failure)."""
    return next((m for m in r.messages() if m.NAME == "STATUS"), None)


def driven_spans(r: SimRun, motor: str, after: int) -> list[tuple[int, int]]:
    """(from, to) cycles in which the motor's bridge was driven, from cycle `after` on."""
    spans, start = [], None
    for d in timeline(r.io, motor):
        on = d.enable.driven and d.enable.duty > 0
        if on and start is None:
            start = d.cycle
        elif not on and start is not None:
            spans.append((start, d.cycle))
            start = None
    if start is not None:
        spans.append((start, r.end_cycle))
    return [(a, b) for a, b in spans if b > after]


def test_a_link_loss_cut_is_never_undone_or_lost_wherever_the_tick_lands(
        harness, firmware_elf) -> None:
    """board-lock-without-cli, motor-output-outside-the-lock: while the ramp writes the motors
    every ms, the deadline's tick lands at each instruction of the passes around it. The cut
    must hold (the bridge never driven again before a new SET_DRIVE, nor OCR1x written non-zero)
    and be reported (STATUS:
    LINK_LOST, one link loss, duty 0): a trip that falls between the main loop's read and its
    write would be undone, or cleared unseen."""
    before = ["run 2", frame(0, gen.SetConfig(link_timeout_ms=50, accel_limit=100)), "run 2",
              frame(1, DRIVE), "run 51"]
    after = ["run 8", frame(2, gen.GetStatus()), "run 6"]
    trials = sweep(harness, firmware_elf, before, 1800, after)
    bad = []
    for k, r in enumerate(trials):
        status = status_of(r)
        ok = (status is not None and status.flags & gen.StatusFlag.LINK_LOST and
              status.link_losses == 1 and not status.flags & gen.StatusFlag.DRIVING and
              (status.left, status.right) == (0, 0))
        for motor in ("left", "right"):
            ok = ok and len(driven_spans(r, motor, 0)) == 1
        # and at the registers behind the pins: once both compare values were written 0 (the
        # cut), neither is written non-zero again; an undo within one PWM period would not show
        # at the pin, yet the new value would take effect at TOP and drive on until the next pass
        duty = [(p.ocr1a, p.ocr1b) for p in r.pwm]
        on = next(i for i, d in enumerate(duty) if d != (0, 0))
        cut = next((i for i in range(on, len(duty)) if duty[i] == (0, 0)), len(duty))
        ok = ok and cut < len(duty) and all(d == (0, 0) for d in duty[cut:])
        if not ok:
            bad.append((k, status))
    assert not bad, f"{len(bad)} of {len(trials)} trials: first {bad[0]}"


def test_the_clock_read_at_a_carry_is_never_torn_wherever_the_tick_lands(
        harness, firmware_elf) -> None:
    """torn-32-bit-clock-read: a SET_DRIVE handled while the firmware's ms count is 255, and the
    tick that carries it to 256 landing at each of the handling's instructions. A read of the
    count torn between its bytes is 256 ms ahead, the deadline then already behind the guard,
    and the motors cut at once: each trial must keep them driven after ACK APPLIED (and count
    no link loss)."""
    # ticks come at about 1537 + 16000 k cycles (clock_init): the count is 255 from 255.1 ms; the
    # sweep starts at 255.45 ms, as the frame's last byte comes in (its handling: trials 0-1500)
    before = ["run 2", frame(0, gen.SetConfig(link_timeout_ms=250, accel_limit=0)),
              "run 252.5", frame(1, DRIVE), "run 0.95"]
    after = ["run 10", frame(2, gen.GetStatus()), "run 6"]
    trials = sweep(harness, firmware_elf, before, 1500, after)
    bad = []
    for k, r in enumerate(trials):
        ms = r.messages()
        status = status_of(r)
        acked = [m.result for m in ms if m.NAME == "ACK" and m.seq == 1]
        spans = [driven_spans(r, motor, 0) for motor in ("left", "right")]
        ok = (acked == [gen.AckResult.APPLIED] and status is not None and
              status.link_losses == 0 and status.flags & gen.StatusFlag.DRIVING and
              all(len(s) == 1 and s[0][1] == r.end_cycle for s in spans))
        if not ok:
            bad.append((k, acked, status))
    assert not bad, f"{len(bad)} of {len(trials)} trials: first {bad[0]}"


@pytest.mark.parametrize("seq", [2, 1], ids=["new-seq", "resend"])
def test_a_drive_acknowledged_at_the_deadline_is_still_driven(harness, firmware_elf, seq) -> None:
    """A keepalive SET_DRIVE handled just as the deadline of the one before passes, the tick that
    trips the guard landing at each of its instructions: whatever the ACK says it was (APPLIED,
    or DUPLICATE for a resend of the drive in force), the drive must be in force after it, not
    cut by a trip that fell between the catch-up and the refresh of the deadline."""
    before = ["run 2", frame(0, gen.SetConfig(link_timeout_ms=50, accel_limit=0)), "run 2",
              frame(1, DRIVE), "run 50.45", frame(seq, DRIVE), "run 0.95"]
    after = ["run 25", frame(3, gen.GetStatus()), "run 6"]
    trials = sweep(harness, firmware_elf, before, 2500, after)
    bad = []
    for k, r in enumerate(trials):
        acks = [(c, m) for c, m in zip(frame_cycles(r), r.messages())
                if m.NAME == "ACK" and m.seq == seq]
        ack_at, ack = acks[-1]
        status = status_of(r)
        # driven from the ACK on (or from the end of a coast that a link-loss stop caught up
        # before the drive began), and never cut again
        spans = [driven_spans(r, motor, ack_at + PWM_PERIOD) for motor in ("left", "right")]
        ok = (status is not None and status.flags & gen.StatusFlag.DRIVING and
              all(len(s) == 1 and s[0][1] == r.end_cycle for s in spans))
        if not ok:
            bad.append((k, ack.result, status))
    assert not bad, f"{len(bad)} of {len(trials)} trials: first {bad[0]}"


def test_a_trip_as_a_status_request_comes_in_is_in_its_answer(harness, firmware_elf) -> None:
    """no-catch-up-before-a-frame: the main loop hands the core the received bytes before its
    tick, so a trip taken as a frame's last byte comes in is handled by the core before the
    tick's catch-up. The last byte of a GET_STATUS arrives 1 ms before the deadline of the drive
    in force, the extra tick (which trips the guard) landing at each instruction from there
    on. Every trial whose trip came within 200 cycles of that byte's stop bit, before the
    firmware can have parsed and checked the frame (the CRC-32C of its last byte alone takes
    longer; the catch-up came some 900 cycles after it, measured), must be answered with the
    stop: LINK_LOST, one link loss, duty 0. Without the catch-up before the frame, STATUS said
    "not driving, no link loss, duty 500" while the motors were cut."""
    status = encode_frame(3, *pack(gen.GetStatus()))
    # the drive is heard in ms h; the status's last byte arrives in ms h + 50, where the extra
    # tick makes the count h + 51: the guard trips at the tick
    before = ["run 2", frame(0, gen.SetConfig(link_timeout_ms=50, accel_limit=0)), "run 2",
              frame(1, DRIVE), "run 51", f"send {status[:-1].hex()}", "run 0.7"]
    after = [f"send {status[-1:].hex()}", "run 8"]
    trials = forced_cycles(harness, firmware_elf, before, 800, after)
    early, bad, driving = 0, [], 0
    for k, (force, r) in enumerate(trials):
        s = status_of(r)
        assert s is not None, f"trial {k}: no STATUS"
        driving += bool(s.flags & gen.StatusFlag.DRIVING)
        if force <= r.ins[-1][0] + CYCLES_PER_BYTE + 200:
            early += 1
            if not (s.flags & gen.StatusFlag.LINK_LOST and s.link_losses == 1 and
                    (s.left, s.right) == (0, 0)):
                bad.append((k, force - r.ins[-1][0] - CYCLES_PER_BYTE, s))
    assert early > 20, f"only {early} trials tripped as the byte came in"
    assert driving, "the deadline was not at the sweep: no trial tripped after the answer"
    assert not bad, f"{len(bad)} of {early} trials: first {bad[0]}"
