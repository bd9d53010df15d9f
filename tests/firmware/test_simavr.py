"""The real firmware binary under simavr, in simulated time: handshake, PWM, link-loss stop,
bad input, watchdog, sustained traffic, and the protocol's golden vectors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from host.emulator.simavr import CYCLES_PER_BYTE, F_CPU, Script, run
from host.link import protocol_gen as gen
from host.link.frame import encode_frame
from host.link.messages import describe, pack, unpack
from tests.firmware.common import MS, NO_RAMP, first

ROOT = Path(__file__).resolve().parents[2]


def test_boot_and_hello_report_schema_hash_and_power_on(harness, firmware_elf) -> None:
    r = run(harness, firmware_elf, Script().run_ms(5).message(1, gen.Hello(nonce=0xC0FFEE))
            .run_ms(10))
    boot, reply = r.messages()
    assert boot == gen.Boot(reset_cause=gen.ResetCause.POWER_ON, fw_version=0x0100,
                            schema_hash=gen.SCHEMA_HASH)
    assert reply.nonce == 0xC0FFEE and reply.schema_hash == gen.SCHEMA_HASH
    assert reply.reset_cause == gen.ResetCause.POWER_ON
    assert reply.link_timeout_ms == gen.DEFAULT_LINK_TIMEOUT_MS
    assert r.pwm[-1].ocr1a == 0 and r.pwm[-1].ocr1b == 0 and r.pwm[-1].dir == 0


def test_set_drive_sets_compare_registers_and_direction_pins(harness, firmware_elf) -> None:
    r = run(harness, firmware_elf, Script().run_ms(5).message(0, NO_RAMP).run_ms(2)
            .message(1, gen.SetDrive(left=500, right=-250)).run_ms(10))
    change = r.settled()[-1]
    # duty permille * ICR1 (400) / 1000; IN1 (bit 0) = left forward, IN4 (bit 3) = right reverse
    assert (change.ocr1a, change.ocr1b, change.dir) == (200, 100, 0b1001)
    applied = first(p for p in r.pwm if p.cycle > r.last_in_done())
    latency = applied.cycle - r.last_in_done()
    assert 0 < latency < 4000, f"{latency} cycles from the last byte's stop bit to the PWM"
    assert r.messages()[-1] == gen.Ack(seq=1, result=gen.AckResult.APPLIED)


def test_set_config_changes_the_link_timeout(harness, firmware_elf) -> None:
    r = run(harness, firmware_elf, Script().run_ms(2)
            .message(1, gen.SetConfig(link_timeout_ms=100, accel_limit=0)).run_ms(5)
            .message(2, gen.SetDrive(left=100, right=100)).run_ms(200))
    off = r.settled()[-1]
    assert off.ocr1a == 0
    last = r.ins[-1][0] + CYCLES_PER_BYTE
    assert 100 <= (off.cycle - last) / MS < 102


def test_garbage_and_corrupted_frames_are_refused_and_the_next_frame_works(
        harness, firmware_elf) -> None:
    bad = bytearray(encode_frame(3, *pack(gen.SetDrive(left=900, right=900))))
    bad[5] ^= 0x40
    script = (Script().run_ms(2).message(0, NO_RAMP).run_ms(2)
              .send(bytes([0x00, 0xA5, 0xFF, 0x13, 0x37, 0xA5, 0x02])).run_ms(2)
              .send(bytes(bad)).run_ms(5)
              .send(encode_frame(4, 0x7E, b"\x01")).run_ms(5)
              .message(5, gen.SetDrive(left=250, right=250)).run_ms(10))
    r = run(harness, firmware_elf, script)
    replies = r.messages()[2:]
    assert gen.Nack(seq=3, error=gen.Error.BAD_CRC) in replies
    assert gen.Nack(seq=4, error=gen.Error.UNKNOWN_ID) in replies
    assert replies[-1] == gen.Ack(seq=5, result=gen.AckResult.APPLIED)
    assert all(p.ocr1a in (0, 100) for p in r.pwm) and r.pwm[-1].ocr1a == 100


def test_a_resent_command_is_acknowledged_but_not_applied_twice(harness, firmware_elf) -> None:
    s = Script().run_ms(2).message(7, gen.SetDrive(left=300, right=300)).run_ms(5)
    s.message(7, gen.SetDrive(left=300, right=300)).run_ms(5)
    r = run(harness, firmware_elf, s)
    assert r.messages()[1:] == [gen.Ack(seq=7, result=gen.AckResult.APPLIED),
                               gen.Ack(seq=7, result=gen.AckResult.DUPLICATE)]


def test_watchdog_resets_a_hung_firmware_with_the_motors_off(harness, hang_elf) -> None:
    s = (Script().run_ms(2).message(0, NO_RAMP).run_ms(2)
         .message(1, gen.SetDrive(left=500, right=500)).run_ms(5)
         .message(2, gen.SetDrive(left=999, right=-999)).run_ms(300)
         .message(3, gen.Hello(nonce=1)).run_ms(5).message(4, gen.GetStatus()).run_ms(5))
    r = run(harness, hang_elf, s)
    assert len(r.resets) == 1
    hang_start = r.ins[3 * len(encode_frame(0, *pack(NO_RAMP))) - 1][0] + CYCLES_PER_BYTE
    # two WDTO_30MS periods (interrupt, then reset); simavr times one at 32 ms
    assert 60 <= (r.resets[0] - hang_start) / MS <= 68
    driving = [p for p in r.settled() if p.cycle < hang_start][-1]
    stopped = first(p for p in r.settled() if p.cycle > hang_start)
    # the watchdog interrupt stops the motors one period into the hang, before the reset
    # (both enables low: the bridge is off; the direction inputs keep their levels at duty 0)
    assert driving.ocr1a == 200 and (stopped.ocr1a, stopped.ocr1b) == (0, 0)
    assert 28 <= (stopped.cycle - hang_start) / MS <= 36
    after = [p for p in r.pwm if p.cycle >= stopped.cycle]
    assert all(p.ocr1a == p.ocr1b == 0 for p in after)
    msgs = r.messages()
    boots = [m for m in msgs if isinstance(m, gen.Boot)]
    assert [b.reset_cause for b in boots] == [gen.ResetCause.POWER_ON, gen.ResetCause.WATCHDOG]
    hello = first(m for m in msgs if isinstance(m, gen.HelloReply))
    status = first(m for m in msgs if isinstance(m, gen.Status))
    assert hello.reset_cause == gen.ResetCause.WATCHDOG
    assert status.flags & gen.StatusFlag.WATCHDOG_RESET


def test_ten_seconds_of_line_rate_traffic_cause_no_watchdog_reset(harness, firmware_elf) -> None:
    # simavr's UART takes a byte per 1496 cycles (10.7 kB/s): 12-byte frames for over 10 s
    n = 9000
    data = b"".join(encode_frame(i & 0xFF, *pack(gen.SetDrive(left=i % 1000, right=-(i % 1000))))
                    for i in range(n))
    r = run(harness, firmware_elf, Script().quiet().run_ms(1).send(data).run_ms(10_200))
    assert r.resets == []
    assert r.n_in == len(data) and r.end_cycle / F_CPU > 10
    acks = [m for m in r.messages() if isinstance(m, gen.Ack)]
    assert len(acks) == n and all(a.result == gen.AckResult.APPLIED for a in acks)


VECTORS = json.loads((ROOT / "protocol" / "vectors.json").read_text())["vectors"]


def expected_reply(frame: dict) -> str:
    """What the robot must answer to a frame the host's decoder accepted (vectors.json)."""
    text = frame["text"]
    if text.startswith("error"):
        return "NACK " + text.split()[1]
    name = text.split()[0]
    cls = next(c for c in gen.MESSAGES.values() if name == c.NAME)
    if cls.DIRECTION == "robot_to_host":
        return "NACK WRONG_DIRECTION"
    return {"HELLO": "HELLO_REPLY", "GET_STATUS": "STATUS"}.get(name, "ACK")


def reply_name(frame) -> str:
    msg = unpack(frame.id, frame.payload)
    return f"NACK {gen.Error(msg.error).name}" if isinstance(msg, gen.Nack) else msg.NAME


@pytest.mark.parametrize("vector", VECTORS, ids=[v["name"] for v in VECTORS])
def test_golden_vectors_get_the_answers_the_host_expects(harness, firmware_elf, vector) -> None:
    r = run(harness, firmware_elf,
            Script().run_ms(2).send(bytes.fromhex(vector["input"])).run_ms(20))
    replies = [reply_name(f) for f in r.frames()[1:]]  # after BOOT
    crc_nacks = replies.count("NACK BAD_CRC")
    assert crc_nacks <= vector["crc_errors"]
    assert [x for x in replies if x != "NACK BAD_CRC"] == [expected_reply(f)
                                                          for f in vector["frames"]]
    assert describe  # the host's text form is what vectors.json records
