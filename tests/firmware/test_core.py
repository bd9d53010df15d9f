"""The firmware's register-free core (host/emulator/core.py: the same C, built natively), driven
call by call where the order of the timer interrupt and the main loop matters, or where a
tick's length is beyond what simavr's 1 ms clock produces."""

from __future__ import annotations

import pytest

from host.emulator.build import ToolMissing
from host.link import protocol_gen as gen
from host.link.frame import FrameDecoder, encode_frame
from host.link.messages import pack, unpack


@pytest.fixture
def core():
    from host.emulator.core import FirmwareCore

    try:
        c = FirmwareCore(gen.ResetCause.POWER_ON)
    except ToolMissing as e:
        pytest.skip(str(e))
    yield c


def send(core, seq: int, msg, now: int) -> list:
    core.rx(encode_frame(seq, *pack(msg)), now)
    return [unpack(f.id, f.payload) for f in FrameDecoder().feed(core.take_tx())]


def test_a_resend_handled_right_after_a_trip_is_applied_not_a_duplicate(core) -> None:
    """no-catch-up-before-a-frame: the timer interrupt trips, and before the main loop's next
    tick a resend of the last SET_DRIVE is handled: the stop is caught up first, so the resend
    is applied (ACK APPLIED, motors driven) instead of acknowledged while the motors stay off."""
    send(core, 0, gen.SetConfig(link_timeout_ms=250, accel_limit=0), 1)
    assert send(core, 7, gen.SetDrive(left=400, right=400), 2)[-1].result == gen.AckResult.APPLIED
    core.tick(3)
    assert core.motors() == (400, 400)
    core._lib.robot_guard(2 + 251)  # the interrupt alone: the main loop has not ticked yet
    assert core.motors() == (0, 0)
    reply = send(core, 7, gen.SetDrive(left=400, right=400), 2 + 251)
    assert reply[-1] == gen.Ack(seq=7, result=gen.AckResult.APPLIED)
    for t in range(254, 300):  # the coast after the stop, then driven again
        core.tick(t)
    assert core.motors() == (400, 400)


def test_the_ramp_budget_never_moves_a_motor_faster_than_the_limit_after_a_long_tick(core) -> None:
    """Defect 3 of issue 29 (the budget wrapped at 16 bits): at the largest acceleration limit
    a 30 ms tick spent coasting, then a 1 ms tick, moved the duty 0 -> 444 (limit 100 a ms)."""
    limit = 10000  # the spec's largest accel_limit
    send(core, 0, gen.SetConfig(link_timeout_ms=5000, accel_limit=limit), 0)
    send(core, 1, gen.SetDrive(left=500, right=500), 0)
    t = 0
    while core.motors() != (500, 500):
        t += 1
        core.tick(t)
    send(core, 2, gen.SetDrive(left=-1000, right=-1000), t)
    while core.motors() != (0, 0):  # ramps down to zero, then coasts
        t += 1
        core.tick(t)
    before = core.motors()[0]
    for step in (30, 1, 1, 1):  # a long tick (a slow main-loop pass), then ordinary ones
        t += step
        core.tick(t)
        now = core.motors()[0]
        assert abs(now - before) <= limit // 100 * step, (step, before, now)
        before = now
