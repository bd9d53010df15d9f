"""The real ELF under simavr, judged at the motor pins: the enable waveform (frequency, duty) is
derived from Timer1's registers and DDRB by host/emulator/pins.py, because simavr 1.6 does not
report PWM toggles on PB1/PB2; the direction inputs are PORTD where DDRD makes them outputs.
Covers reset and init, PWM, reversal through a coast interval, the ramp, the link-loss stop
under floods at line rate without flow control, overruns, and the duplicate counterexample."""

from __future__ import annotations

import pytest

from host.emulator.pins import Pin, enable_pin, timeline
from host.emulator.simavr import CYCLES_PER_BYTE, FLOODS, Script, flood, run
from host.link import protocol_gen as gen
from tests.firmware.common import FRAME, MS, NO_RAMP, first


def test_pwm_at_the_enable_pins_is_20_khz_with_the_commanded_duty(harness, firmware_elf):
    r = run(harness, firmware_elf, Script().run_ms(2).message(0, NO_RAMP).run_ms(2)
            .message(1, gen.SetDrive(left=500, right=-250)).run_ms(5))
    left, right = timeline(r.io, "left")[-1], timeline(r.io, "right")[-1]
    assert left.enable == Pin(True, 0.5, 20_000.0), left
    assert right.enable == Pin(True, 0.25, 20_000.0), right
    assert (left.direction, right.direction) == ("forward", "reverse")


def test_pins_from_reset_through_init_never_drive_the_bridge(harness, firmware_elf):
    r = run(harness, firmware_elf, Script().run_ms(5))
    for motor in ("left", "right"):
        for d in timeline(r.io, motor):
            assert not d.driving and d.direction in ("floating", "off"), (motor, d)
    last = r.io[-1]
    # after init: enables are outputs wired to Timer1 (mode 10, no prescaler, TOP 400) at 0 %
    assert last.wgm == 10 and last.prescaler == 1 and last.icr1 == 400
    assert last.tccr1a >> 4 == 0b1010  # COM1A1 and COM1B1: non-inverting on OC1A and OC1B
    for motor in ("left", "right"):
        assert enable_pin(last, motor) == Pin(True, 0.0, 0.0)
    # the motors are set up first: the bridge inputs are low outputs within 0.2 ms of reset
    set_up = first(io for io in r.io if io.ddrd & 0xF0 == 0xF0)
    assert set_up.cycle < 0.2 * MS and set_up.portd & 0xF0 == 0
    assert r.messages()[0].NAME == "BOOT"


def test_a_watchdog_reset_disables_the_watchdog_before_the_c_runtime_runs(harness, hang_elf):
    """After a watchdog reset WDRF forces the watchdog on at its shortest timeout; .init3 must
    clear MCUSR and WDE at once, then main arms it again."""
    s = (Script().run_ms(2).message(1, gen.SetDrive(left=999, right=-999)).run_ms(200))
    r = run(harness, hang_elf, s)
    assert len(r.resets) == 1
    after = [io for io in r.io if io.cycle >= r.resets[0]]
    cleared = first(io for io in after if not io.mcusr & 0x08 and not io.wdtcsr & 0x08)
    assert cleared.cycle - r.resets[0] < 100, "WDRF and WDE still set past .init3"
    armed = first(io for io in after if io.cycle > cleared.cycle and io.wdtcsr & 0x08)
    motors_set_up = first(io for io in after if io.ddrd & 0xF0 == 0xF0)
    assert armed.cycle > motors_set_up.cycle  # main arms it after the motors are off
    assert all(not d.driving for d in timeline(after, "left"))


def reversal(r, motor: str, was: str, becomes: str) -> tuple[float, list, list]:
    """Dead interval in ms between the last driven instant in direction was and the first
    driven instant in direction becomes, the states in between, and those after."""
    t = timeline(r.io, motor)
    was_on = [i for i, d in enumerate(t) if d.driving and d.direction == was]
    becomes_on = [i for i, d in enumerate(t) if d.driving and d.direction == becomes]
    assert was_on and becomes_on, f"{motor} never driven {was} and then {becomes}"
    end, start = max(was_on), min(becomes_on)
    assert end < start
    return (t[start].cycle - t[end + 1].cycle) / MS, t[end + 1:start], t[start:]


@pytest.mark.parametrize("ramp", [False, True], ids=["no-ramp", "default-ramp"])
@pytest.mark.parametrize("sign", [1, -1], ids=["forward-to-reverse", "reverse-to-forward"])
def test_reversal_goes_through_zero_and_coasts_before_the_bridge_is_driven_again(
        harness, firmware_elf, ramp, sign):
    accel = gen.DEFAULT_ACCEL_LIMIT if ramp else 0
    s = Script().run_ms(2).message(0, gen.SetConfig(link_timeout_ms=1000, accel_limit=accel))
    s.run_ms(2).message(1, gen.SetDrive(left=600 * sign, right=600 * sign)).run_ms(200)
    s.message(2, gen.SetDrive(left=-600 * sign, right=-600 * sign)).run_ms(400)
    r = run(harness, firmware_elf, s)
    was, becomes = ("forward", "reverse") if sign > 0 else ("reverse", "forward")
    for motor in ("left", "right"):
        dead_ms, between, after = reversal(r, motor, was, becomes)
        # the direction inputs change only while the enable is off (duty 0 in force at the pin)
        assert between and all(not d.driving for d in between), motor
        assert gen.DEFAULT_REVERSE_COAST_MS <= dead_ms < gen.DEFAULT_REVERSE_COAST_MS + 2, motor
        assert timeline(r.io, motor)[-1].enable == Pin(True, 0.6, 20_000.0)
        if ramp:  # the new direction is ramped too, from zero at the acceleration limit
            steps = [b.enable.duty - a.enable.duty for a, b in zip(after, after[1:])]
            assert after[0].enable.duty <= 2 * accel / 100 / 1000 + 1e-9, motor
            assert max(steps) <= 2 * accel / 100 / 1000 + 1e-9, motor
            full = first(d for d in after if d.enable.duty == 0.6)
            assert (full.cycle - after[0].cycle) / MS >= 600 / (accel / 100) - 2, motor


def test_the_default_ramp_takes_duty_up_at_the_acceleration_limit(harness, firmware_elf):
    r = run(harness, firmware_elf, Script().run_ms(2)
            .message(1, gen.SetDrive(left=600, right=0)).run_ms(200))
    t = [d for d in timeline(r.io, "left") if d.cycle > r.last_in_done()]
    start = first(d for d in t if d.driving)
    full = first(d for d in t if d.enable.duty == 0.6)
    ramp_ms = (full.cycle - start.cycle) / MS
    expected = 600 / (gen.DEFAULT_ACCEL_LIMIT / 100)  # permille / (permille per ms)
    assert expected - 2 <= ramp_ms <= expected + 1, ramp_ms
    steps = [b.enable.duty - a.enable.duty for a, b in zip(t, t[1:])]
    assert max(steps) <= 2 * gen.DEFAULT_ACCEL_LIMIT / 100 / 1000 + 1e-9


@pytest.mark.parametrize("kind", ["quiet", *FLOODS])
def test_the_motors_stop_250_ms_after_the_last_accepted_drive_whatever_follows(
        harness, firmware_elf, kind):
    s = Script().run_ms(2).message(0, NO_RAMP).run_ms(2)
    s.message(1, gen.SetDrive(left=500, right=500)).run_ms(3).quiet()
    if kind != "quiet":
        s.flow(False).send(flood(kind, 500 * MS // CYCLES_PER_BYTE))  # 500 ms at line rate
    s.run_ms(520).flow(True).quiet(False).message(2, gen.GetStatus()).run_ms(10)
    r = run(harness, firmware_elf, s)
    drive_done = r.ins[2 * FRAME - 1][0] + CYCLES_PER_BYTE  # the SET_DRIVE's stop bit
    t = [d for d in timeline(r.io, "left") if d.cycle > drive_done]
    on = first(i for i, d in enumerate(t) if d.driving)
    off = first(d for d in t[on:] if not d.driving)
    stop_ms = (off.cycle - drive_done) / MS
    assert gen.DEFAULT_LINK_TIMEOUT_MS <= stop_ms < gen.DEFAULT_LINK_TIMEOUT_MS + 2, stop_ms
    assert all(not d.driving for d in t if d.cycle > off.cycle)
    assert r.resets == []
    status = r.messages()[-1]
    assert status.NAME == "STATUS" and status.flags & gen.StatusFlag.LINK_LOST
    assert not status.flags & gen.StatusFlag.DRIVING and (status.left, status.right) == (0, 0)
    if kind != "quiet":  # faster than simavr's UART takes bytes: it overran, and it was counted
        assert status.rx_overruns > 0
    if kind == "get-status":  # 30-byte answers to 6-byte polls: dropped, never waited for
        assert status.tx_dropped > 0
    nacks = sum(m.NAME == "NACK" for m in r.messages())
    flood_ms = 520  # NACKs are rate-limited: a burst, then one per interval
    assert nacks <= 4 + flood_ms / gen.DEFAULT_NACK_INTERVAL_MS + 1, nacks
    if kind in ("bad-crc", "refused"):  # but they still come, one per interval
        assert nacks >= 4 + flood_ms / gen.DEFAULT_NACK_INTERVAL_MS * 0.8, nacks


def test_bytes_that_pile_up_while_the_main_loop_stalls_are_counted_as_overruns(
        harness, hang_elf):
    # the test build's 25 ms stall (SET_DRIVE 997,-25), within one watchdog period
    s = Script().run_ms(2).message(1, gen.SetDrive(left=997, right=-25)).run_ms(1)
    s.send(flood("get-status", 300)).run_ms(40).message(2, gen.GetStatus()).run_ms(10)
    r = run(harness, hang_elf, s)
    status = r.messages()[-1]
    assert status.NAME == "STATUS" and r.resets == []
    assert status.rx_overruns > 0  # the receive ring filled up during the stall


def test_a_new_command_with_the_seq_of_an_old_one_is_applied_not_taken_for_a_resend(
        harness, firmware_elf):
    """The issue's counterexample on the real firmware: SET_DRIVE seq 10 at +300, then 255
    GET_STATUS, then SET_DRIVE seq 10 at -300."""
    s = Script().run_ms(2).message(0, gen.SetConfig(link_timeout_ms=5000, accel_limit=0))
    s.run_ms(2).message(10, gen.SetDrive(left=300, right=300)).run_ms(5)
    for seq in range(11, 11 + 255):
        s.message(seq & 0xFF, gen.GetStatus())
    s.message(10, gen.SetDrive(left=-300, right=-300)).run_ms(300)
    r = run(harness, firmware_elf, s)
    acks = [m for m in r.messages() if m.NAME == "ACK" and m.seq == 10]
    assert [a.result for a in acks] == [gen.AckResult.APPLIED, gen.AckResult.APPLIED]
    last = timeline(r.io, "left")[-1]
    assert last.direction == "reverse" and last.enable.duty == 0.3
