"""The safety rules of the spec, the docs and the code, one or more tests a rule, on the real ELF
under simavr: judged at the motor pins (host/emulator/pins.py) or on the wire. Each test kills
a mutant of firmware/atmega328/mutants.toml (its name is in the test's docstring)."""

from __future__ import annotations

import struct
import subprocess

import pytest

from host.emulator.pins import timeline
from host.emulator.simavr import CYCLES_PER_BYTE, Script, run
from host.link import protocol_gen as gen
from host.link.frame import encode_frame
from host.link.messages import pack
from tests.firmware.common import MS, NO_RAMP, first


class Plan:
    """A harness script that remembers where each marked frame's last byte is."""

    def __init__(self) -> None:
        self.script = Script()
        self.sent = 0
        self.marks: dict[str, int] = {}

    def send(self, data: bytes, mark: str | None = None) -> Plan:
        self.script.send(data)
        self.sent += len(data)
        if mark:
            self.marks[mark] = self.sent - 1
        return self

    def msg(self, seq: int, msg, mark: str | None = None) -> Plan:
        return self.send(encode_frame(seq, *pack(msg)), mark)

    def run(self, ms: float) -> Plan:
        self.script.run_ms(ms)
        return self

    def line(self, text: str) -> Plan:
        self.script.lines.append(text)
        return self


def done(r, plan: Plan, mark: str) -> int:
    """Cycle at which the marked frame's stop bit ended."""
    return r.ins[plan.marks[mark]][0] + CYCLES_PER_BYTE


def stops_after(r, cycle: int, motor: str = "left") -> float:
    """ms from cycle to the first instant the motor's bridge is off, having been driven."""
    t = [d for d in timeline(r.io, motor) if d.cycle > cycle]
    on = first(i for i, d in enumerate(t) if d.driving)
    off = first(d for d in t[on:] if not d.driving)
    return (off.cycle - cycle) / MS


def acks(r, seq: int) -> list[int]:
    return [m.result for m in r.messages() if m.NAME == "ACK" and m.seq == seq]


# --- link loss ---


@pytest.mark.parametrize("phase", [0.0, 0.25, 0.5, 0.75, 0.9])
def test_the_link_loss_cut_is_never_early_whatever_the_phase_of_the_clock(
        harness, firmware_elf, phase) -> None:
    """link-loss-one-tick-early: at least link_timeout_ms pass between the SET_DRIVE's last
    byte and the cut, wherever within the 1 ms tick the frame arrives."""
    p = Plan().run(2).msg(0, NO_RAMP).run(2 + phase)
    p.msg(1, gen.SetDrive(left=500, right=500), "drive").run(270)
    r = run(harness, firmware_elf, p.script)
    stop_ms = stops_after(r, done(r, p, "drive"))
    assert gen.DEFAULT_LINK_TIMEOUT_MS <= stop_ms < gen.DEFAULT_LINK_TIMEOUT_MS + 2, stop_ms


def test_the_timer_interrupt_cuts_the_motors_while_the_main_loop_stalls(harness, hang_elf) -> None:
    """guard-only-flags-the-trip: the main loop stalls 40 ms across the deadline (test build:
    SET_DRIVE 997,-40); the cut still comes at the deadline, from the timer interrupt."""
    p = Plan().run(2).msg(0, gen.SetConfig(link_timeout_ms=50, accel_limit=0)).run(2)
    p.msg(1, gen.SetDrive(left=500, right=500), "drive").run(20)
    p.msg(2, gen.SetDrive(left=997, right=-40)).run(100)
    r = run(harness, hang_elf, p.script)
    stop_ms = stops_after(r, done(r, p, "drive"))
    assert 50 <= stop_ms < 52, stop_ms


def test_set_config_does_not_restart_the_deadline(harness, firmware_elf) -> None:
    """set-config-refreshes-link."""
    p = Plan().run(2).msg(0, NO_RAMP).run(2)
    p.msg(1, gen.SetDrive(left=500, right=500), "drive").run(150)
    p.msg(2, NO_RAMP).run(300)
    r = run(harness, firmware_elf, p.script)
    assert acks(r, 2) == [gen.AckResult.APPLIED]
    stop_ms = stops_after(r, done(r, p, "drive"))
    assert gen.DEFAULT_LINK_TIMEOUT_MS <= stop_ms < gen.DEFAULT_LINK_TIMEOUT_MS + 2, stop_ms


def test_a_resend_of_the_drive_in_force_restarts_the_deadline(harness, firmware_elf) -> None:
    """duplicate-does-not-refresh-link: ACK DUPLICATE of the SET_DRIVE in force is an accepted
    SET_DRIVE (spec, Link loss)."""
    p = Plan().run(2).msg(0, NO_RAMP).run(2)
    p.msg(7, gen.SetDrive(left=500, right=500)).run(150)
    p.msg(7, gen.SetDrive(left=500, right=500), "resend").run(300)
    r = run(harness, firmware_elf, p.script)
    assert acks(r, 7) == [gen.AckResult.APPLIED, gen.AckResult.DUPLICATE]
    stop_ms = stops_after(r, done(r, p, "resend") - 150 * MS)
    assert 150 + gen.DEFAULT_LINK_TIMEOUT_MS <= stop_ms < 150 + gen.DEFAULT_LINK_TIMEOUT_MS + 2


def test_after_a_link_loss_stop_the_same_drive_is_applied_again(harness, firmware_elf) -> None:
    """last-command-kept-after-link-loss: the host's resend after the stop is applied, not
    acknowledged as a duplicate while the motors stay off."""
    p = Plan().run(2).msg(0, NO_RAMP).run(2)
    p.msg(7, gen.SetDrive(left=500, right=500)).run(300)
    p.msg(7, gen.SetDrive(left=500, right=500), "again").run(20)
    r = run(harness, firmware_elf, p.script)
    assert acks(r, 7) == [gen.AckResult.APPLIED, gen.AckResult.APPLIED]
    last = timeline(r.io, "left")[-1]
    assert last.driving and last.enable.duty == 0.5


def test_after_a_link_loss_stop_a_resent_set_config_is_applied(harness, firmware_elf) -> None:
    """last-command-kept-after-link-loss: the last command before the stop was a SET_CONFIG;
    sent again after the stop it is applied (ACK APPLIED), not a duplicate."""
    p = Plan().run(2).msg(0, NO_RAMP).run(2)
    p.msg(1, gen.SetDrive(left=500, right=500)).run(5).msg(7, NO_RAMP).run(300)
    p.msg(7, NO_RAMP).run(10)
    r = run(harness, firmware_elf, p.script)
    assert acks(r, 7) == [gen.AckResult.APPLIED, gen.AckResult.APPLIED]

# --- reversal ---


def test_stop_then_reverse_coasts_before_the_bridge_is_driven_again(harness, firmware_elf) -> None:
    """stop-starts-no-coast: STOP cuts at once, and the coast interval still holds."""
    p = Plan().run(2).msg(0, NO_RAMP).run(2)
    p.msg(1, gen.SetDrive(left=600, right=600)).run(20)
    p.msg(2, gen.Stop(), "stop").msg(3, gen.SetDrive(left=-600, right=-600)).run(30)
    r = run(harness, firmware_elf, p.script)
    for motor in ("left", "right"):
        t = timeline(r.io, motor)
        off = first(d for d in t if d.cycle > done(r, p, "stop") - 100 and not d.driving)
        back = first(d for d in t if d.cycle > off.cycle and d.driving)
        assert back.direction == "reverse"
        assert (back.cycle - off.cycle) / MS >= gen.DEFAULT_REVERSE_COAST_MS, motor


# --- ranges ---


def _set_config(seq: int, timeout: int, accel: int) -> bytes:
    """A SET_CONFIG frame built byte by byte: the host's pack() would refuse a bad value."""
    return encode_frame(seq, gen.SetConfig.ID, struct.pack("<HH", timeout, accel))


def test_set_config_limits_are_enforced_on_the_wire(harness, firmware_elf) -> None:
    """link-timeout-min-1, link-timeout-max-65534: the spec's bounds, at the robot."""
    cases = [(49, 0, False), (50, 0, True), (5000, 0, True), (5001, 0, False),
             (1, 0, False), (65534, 0, False), (250, 10000, True), (250, 10001, False)]
    p = Plan().run(2)
    for seq, (timeout, accel, _) in enumerate(cases):
        p.send(_set_config(seq, timeout, accel)).run(3)
    r = run(harness, firmware_elf, p.script)
    replies = {m.seq: m for m in r.messages() if m.NAME in ("ACK", "NACK")}
    for seq, (timeout, accel, ok) in enumerate(cases):
        want = (gen.Ack(seq=seq, result=gen.AckResult.APPLIED) if ok
                else gen.Nack(seq=seq, error=gen.Error.OUT_OF_RANGE))
        assert replies[seq] == want, (timeout, accel)


# --- duplicates ---


def _same_payload() -> tuple[gen.SetConfig, gen.SetDrive]:
    """A SET_CONFIG (250 ms / 0) and a SET_DRIVE (250 / 0) whose payload bytes are the same."""
    config = gen.SetConfig(link_timeout_ms=250, accel_limit=0)
    drive = gen.SetDrive(left=250, right=0)
    assert pack(config)[1] == pack(drive)[1]
    return config, drive


def test_a_command_differing_only_in_its_id_is_applied(harness, firmware_elf) -> None:
    """duplicate-ignores-id: SET_CONFIG 250 ms / 0 and SET_DRIVE 250 / 0 have the same payload
    bytes; with the same SEQ the second is still a new command."""
    config, drive = _same_payload()
    p = Plan().run(2).msg(5, config).run(3).msg(5, drive).run(10)
    r = run(harness, firmware_elf, p.script)
    assert acks(r, 5) == [gen.AckResult.APPLIED, gen.AckResult.APPLIED]
    assert timeline(r.io, "left")[-1].enable.duty == 0.25


def test_a_command_differing_only_in_its_id_from_the_drive_in_force_is_applied(
        harness, firmware_elf) -> None:
    """duplicate-ignores-id, with the drive armed: a SET_CONFIG with the SEQ and payload bytes
    of the SET_DRIVE in force is a new command (ACK APPLIED), not a resend of the drive. (The
    other order no longer tells: a SET_DRIVE after a SET_CONFIG finds no drive armed, and a
    drive not armed is applied again whatever it matched.)"""
    config, drive = _same_payload()
    p = Plan().run(2).msg(5, drive).run(3).msg(5, config).run(10)
    r = run(harness, firmware_elf, p.script)
    assert acks(r, 5) == [gen.AckResult.APPLIED, gen.AckResult.APPLIED]


def test_a_command_differing_only_in_its_last_byte_is_applied(harness, firmware_elf) -> None:
    """duplicate-compares-first-byte."""
    p = Plan().run(2).msg(0, NO_RAMP).run(2)
    p.msg(5, gen.SetDrive(left=300, right=300)).run(5)
    p.msg(5, gen.SetDrive(left=300, right=-300)).run(40)
    r = run(harness, firmware_elf, p.script)
    assert acks(r, 5) == [gen.AckResult.APPLIED, gen.AckResult.APPLIED]
    assert timeline(r.io, "right")[-1].direction == "reverse"


def test_after_hello_the_first_command_is_applied_whatever_its_seq(harness, firmware_elf) -> None:
    """hello-keeps-last-command: a new session numbers its commands afresh."""
    p = Plan().run(2).msg(0, gen.SetDrive(left=300, right=300)).run(5)
    p.msg(0, gen.Hello(nonce=7)).run(5).msg(0, gen.SetDrive(left=300, right=300)).run(5)
    r = run(harness, firmware_elf, p.script)
    assert acks(r, 0) == [gen.AckResult.APPLIED, gen.AckResult.APPLIED]


# --- reset record ---


def _record_address(elf) -> int:
    """Data-space address of the .noinit reset record (avr-nm)."""
    out = subprocess.run(["avr-nm", str(elf)], capture_output=True, text=True, check=True).stdout
    return next(int(line.split()[0], 16) & 0xFFFF for line in out.splitlines()
                if line.endswith(" record"))


def _boot_causes(harness, elf, *before: str, after: tuple[str, ...] = ()) -> list[int]:
    p = Plan()
    for line in before:
        p.line(line)
    p.run(5)
    for line in after:
        p.line(line)
    p.run(5)
    r = run(harness, elf, p.script)
    return [m.reset_cause for m in r.messages() if m.NAME == "BOOT"]


MCUSR_CLEARED = "poke 54 00"  # what the application sees behind optiboot 4.4


def _record(magic: int, mark: int, complement: int) -> str:
    return struct.pack("<HBB", magic, mark, complement).hex()


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_ram_at_power_on_behind_optiboot_is_power_on(harness, firmware_elf, seed) -> None:
    """record-never-checked: simavr zeroes RAM, a real chip does not; the harness fills it."""
    causes = _boot_causes(harness, firmware_elf, f"fill {seed}", MCUSR_CLEARED)
    assert causes == [gen.ResetCause.POWER_ON]


@pytest.mark.parametrize(("record", "cause"), [
    (_record(0x5EA7, 0x57, 0xA8), gen.ResetCause.WATCHDOG),
    (_record(0x5EA7, 0x52, 0xAD), gen.ResetCause.UNKNOWN),
    (_record(0x5EA6, 0x57, 0xA8), gen.ResetCause.POWER_ON),   # magic off by one bit
    (_record(0x5EA7, 0x57, 0xA9), gen.ResetCause.POWER_ON),   # complement off by one bit
    (_record(0x5EA7, 0x57, 0x57), gen.ResetCause.POWER_ON),   # no complement
], ids=["watchdog", "running", "bad-magic", "bad-complement", "no-complement"])
def test_the_reset_record_is_believed_only_when_whole(harness, firmware_elf, record, cause) -> None:
    """record-magic-unchecked, record-complement-unchecked."""
    addr = _record_address(firmware_elf)
    causes = _boot_causes(harness, firmware_elf, "fill 9", f"poke {addr:x} {record}",
                          MCUSR_CLEARED)
    assert causes == [cause]


def test_a_reset_after_a_watchdog_reset_is_not_reported_as_watchdog(harness, firmware_elf) -> None:
    """stale-watchdog-mark-kept: the WATCHDOG mark is read once, then the record says RUNNING."""
    addr = _record_address(firmware_elf)
    causes = _boot_causes(harness, firmware_elf, "fill 9",
                          f"poke {addr:x} {_record(0x5EA7, 0x57, 0xA8)}", MCUSR_CLEARED,
                          after=("reset 0",))
    assert causes == [gen.ResetCause.WATCHDOG, gen.ResetCause.UNKNOWN]


# --- UART ---


def nested_false_frames(n_bytes: int) -> bytes:
    """The costliest input for the parser: START and the largest LEN over and over, so every
    rejected frame's bytes hold the next false frame."""
    unit = bytes([gen.START, gen.MAX_PAYLOAD])
    return unit * (n_bytes // len(unit))


def test_a_flood_of_nested_false_frames_causes_no_watchdog_reset(harness, firmware_elf) -> None:
    """rx-bytes-per-pass-unbounded: at line rate without flow control the parser falls behind;
    a bounded pass drops bytes (counted) instead of starving the watchdog."""
    p = Plan().run(2).msg(0, NO_RAMP).run(2).msg(1, gen.SetDrive(left=500, right=500)).run(3)
    p.line("quiet 1").line("flow 0").send(nested_false_frames(300 * MS // CYCLES_PER_BYTE))
    p.run(320).line("flow 1").line("quiet 0").send(bytes(2 * gen.MAX_PAYLOAD))  # ends a false frame
    p.msg(2, gen.GetStatus()).run(10)
    r = run(harness, firmware_elf, p.script)
    assert r.resets == []
    status = r.messages()[-1]
    assert status.NAME == "STATUS" and status.rx_overruns > 0
    assert status.flags & gen.StatusFlag.LINK_LOST


def test_a_burst_during_a_short_stall_is_held_by_the_receive_ring(harness, hang_elf) -> None:
    """rx-ring-16: four SET_DRIVE frames (48 bytes) arrive at line rate while the main loop
    stalls 15 ms (test build: SET_DRIVE 997,-15); none is lost."""
    p = Plan().run(2).msg(0, NO_RAMP).run(2).msg(1, gen.SetDrive(left=997, right=-15)).run(0.5)
    p.line("flow 0")
    for seq in range(2, 6):
        p.msg(seq, gen.SetDrive(left=100 * seq, right=100 * seq))
    p.run(25).line("flow 1").msg(6, gen.GetStatus()).run(10)
    r = run(harness, hang_elf, p.script)
    got = r.messages()
    assert [m.seq for m in got if m.NAME == "ACK"] == [0, 1, 2, 3, 4, 5]
    assert got[-1].NAME == "STATUS" and got[-1].rx_overruns == 0


# --- frame gap and link-loss count (issue 29, defect 2) ---


def test_a_false_start_on_the_line_does_not_swallow_the_keepalives(harness, firmware_elf) -> None:
    """Noise that reads as START and the largest LEN used to swallow the next 31 bytes: the
    next keepalives, so the motors were cut by link loss. Now the partial frame is dropped at
    the gap before the next keepalive."""
    drive = gen.SetDrive(left=500, right=500)
    p = Plan().run(2).msg(0, NO_RAMP).run(2).msg(1, drive, "drive").run(40)
    p.send(bytes([gen.START, gen.MAX_PAYLOAD])).run(40)
    for _ in range(10):  # the same SET_DRIVE every 80 ms: ACK DUPLICATE, deadline restarted
        p.msg(1, drive).run(80)
    p.msg(2, gen.GetStatus()).run(5)
    r = run(harness, firmware_elf, p.script)
    t = [d for d in timeline(r.io, "left") if d.cycle > done(r, p, "drive")]
    on = first(i for i, d in enumerate(t) if d.driving)
    assert all(d.driving for d in t[on:]), "the motors were cut"
    status = r.messages()[-1]
    assert status.NAME == "STATUS" and status.link_losses == 0
    assert not status.flags & gen.StatusFlag.LINK_LOST and status.framing_errors == 1


def test_a_frame_with_gaps_between_its_bytes_is_dropped(harness, firmware_elf) -> None:
    frame = encode_frame(3, *pack(gen.SetDrive(left=400, right=400)))
    p = Plan().run(2).msg(0, NO_RAMP).run(2)
    for b in frame:
        p.send(bytes([b])).run(gen.DEFAULT_FRAME_GAP_MS + 2)
    p.msg(4, gen.GetStatus()).run(5).msg(5, gen.SetDrive(left=300, right=300)).run(5)
    r = run(harness, firmware_elf, p.script)
    got = r.messages()
    assert [m.seq for m in got if m.NAME == "ACK"] == [0, 5]  # the gapped frame never counted
    status = first(m for m in got if m.NAME == "STATUS")
    assert status.framing_errors >= 1 and status.left == 0
    assert timeline(r.io, "left")[-1].enable.duty == 0.3


def test_status_counts_every_link_loss_stop(harness, firmware_elf) -> None:
    p = Plan().run(2).msg(0, NO_RAMP).run(2)
    for seq in (1, 2):
        p.msg(seq, gen.SetDrive(left=300, right=300)).run(gen.DEFAULT_LINK_TIMEOUT_MS + 20)
    p.msg(3, gen.SetDrive(left=300, right=300)).run(5).msg(4, gen.GetStatus()).run(5)
    r = run(harness, firmware_elf, p.script)
    status = r.messages()[-1]
    assert status.NAME == "STATUS" and status.link_losses == 2
    assert not status.flags & gen.StatusFlag.LINK_LOST  # cleared by the last SET_DRIVE
