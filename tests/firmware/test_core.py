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
    """The timer interrupt trips, and before the main loop's next tick a resend of the last
    SET_DRIVE is handled: the stop is caught up first, so the resend is applied (ACK APPLIED,
    motors driven) instead of acknowledged while the motors stay off. (on_set_drive's own
    catch-up holds this too, so no-catch-up-before-a-frame is killed at the wire instead:
    test_races.py::test_a_trip_as_a_status_request_comes_in_is_in_its_answer.)"""
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


def test_stop_after_a_long_pass_still_coasts_the_whole_interval(core) -> None:
    """The core fuzzer's finding (tests/c/corpus/core/stop-after-a-long-pass-coasts-short): the
    coast that STOP starts was counted down from the last tick before it, so after a pass of
    5 ms a reversal drove the bridge again 6 ms after the stop instead of 10."""
    send(core, 0, gen.SetConfig(link_timeout_ms=5000, accel_limit=0), 0)
    send(core, 1, gen.SetDrive(left=500, right=500), 0)
    for t in range(1, 20):
        core.tick(t)
    assert core.motors() == (500, 500)
    # a long main-loop pass: no tick for 5 ms, then STOP and the reverse command in it
    send(core, 2, gen.Stop(), 24)
    stopped = 24
    send(core, 3, gen.SetDrive(left=-500, right=-500), 24)
    t = 24
    while core.motors() == (0, 0):
        t += 1
        core.tick(t)
        assert t < 100
    assert t - stopped >= gen.DEFAULT_REVERSE_COAST_MS, t - stopped


def test_a_reversal_commanded_within_a_pass_coasts_the_whole_interval(core) -> None:
    """Likewise for a reversal without a ramp, which reaches zero as the SET_DRIVE is handled."""
    send(core, 0, gen.SetConfig(link_timeout_ms=5000, accel_limit=0), 0)
    send(core, 1, gen.SetDrive(left=500, right=500), 0)
    for t in range(1, 20):
        core.tick(t)
    send(core, 2, gen.SetDrive(left=-500, right=-500), 23)
    assert core.motors() == (0, 0)
    t = 23
    while core.motors() == (0, 0):
        t += 1
        core.tick(t)
        assert t < 100
    assert t - 23 >= gen.DEFAULT_REVERSE_COAST_MS, t - 23
