"""One suite, run against the native emulator and the real ELF under simavr, so the two stand-ins
for the robot cannot drift apart. Everything goes through the host's RobotLink on a pty."""

from __future__ import annotations

import time

import pytest

from host.link import protocol_gen as gen
from host.link.client import LinkError, RobotLink
from host.link.frame import encode_frame
from host.link.messages import pack


def test_handshake_reports_the_spec_hash_and_power_on(robot_port: str) -> None:
    with RobotLink(robot_port) as robot:
        assert robot.hello.schema_hash == gen.SCHEMA_HASH
        assert robot.hello.reset_cause == gen.ResetCause.POWER_ON
        assert robot.hello.link_timeout_ms == gen.DEFAULT_LINK_TIMEOUT_MS


def test_drive_status_and_stop(robot_port: str) -> None:
    with RobotLink(robot_port) as robot:
        robot.set_config(link_timeout_ms=250, accel_limit=0)  # no ramp: the duty lands at once
        robot.drive(420, -130)
        s = robot.status()
        assert (s.left, s.right) == (420, -130) and s.flags & gen.StatusFlag.DRIVING
        robot.stop()
        s = robot.status()
        assert (s.left, s.right) == (0, 0) and not s.flags & gen.StatusFlag.DRIVING


def test_link_loss_stops_the_motors(robot_port: str) -> None:
    with RobotLink(robot_port) as robot:
        robot.set_config(link_timeout_ms=100, accel_limit=0)
        robot.drive(500, 500)
        time.sleep(0.03)
        assert robot.status().left == 500
        time.sleep(0.3)  # no frame for longer than the timeout
        s = robot.status()
        assert (s.left, s.right) == (0, 0) and s.flags & gen.StatusFlag.LINK_LOST


def test_keepalive_holds_the_drive_past_the_timeout(robot_port: str) -> None:
    with RobotLink(robot_port, keepalive_s=0.03) as robot:
        # slack for a loaded test machine (a 200 ms timeout failed under load 15): a keepalive
        # every 30 ms against a 500 ms timeout, held for more than three timeouts
        robot.set_config(link_timeout_ms=500)
        robot.drive(300, 300)
        end = time.monotonic() + 1.6
        while time.monotonic() < end:
            robot.keepalive()
            time.sleep(0.005)
        s = robot.status()
        assert s.left == 300 and not s.flags & gen.StatusFlag.LINK_LOST


def test_a_resent_command_is_not_applied_twice(robot_port: str) -> None:
    with RobotLink(robot_port) as robot:
        robot.drive(100, 100)
        frame = encode_frame(77, *pack(gen.SetDrive(left=200, right=200)))
        replies = []
        for _ in range(2):
            robot.write_raw(frame)
            replies.append(robot.wait_for(lambda m: isinstance(m, gen.Ack) and m.seq == 77, 0.5))
        assert [r.result for r in replies] == [gen.AckResult.APPLIED, gen.AckResult.DUPLICATE]


def test_status_polls_do_not_hold_the_drive_past_the_timeout(robot_port: str) -> None:
    with RobotLink(robot_port) as robot:
        robot.set_config(link_timeout_ms=100, accel_limit=0)
        robot.drive(300, 300)
        # a host that only polls is not driving the robot: polled every 10 ms, it still stops
        # (2 s of polling at most, ample for a 100 ms timeout on a loaded machine)
        end = time.monotonic() + 2.0
        while time.monotonic() < end:
            s = robot.status()
            if s.flags & gen.StatusFlag.LINK_LOST:
                break
            time.sleep(0.01)
        assert (s.left, s.right) == (0, 0) and s.flags & gen.StatusFlag.LINK_LOST


def test_a_new_command_with_an_old_seq_is_applied_not_taken_for_a_resend(
        robot_port: str) -> None:
    """The issue's counterexample: SET_DRIVE seq 10 at +300, 255 polls, SET_DRIVE seq 10 at
    -300 must reverse the robot, not be acknowledged as a duplicate."""
    with RobotLink(robot_port) as robot:
        robot.set_config(link_timeout_ms=5000, accel_limit=0)
        replies = []
        for left in (300, -300):
            robot.write_raw(encode_frame(10, *pack(gen.SetDrive(left=left, right=left))))
            # the answers to 255 polls take over half a second of line time: wait long enough
            replies.append(robot.wait_for(lambda m: isinstance(m, gen.Ack) and m.seq == 10, 3.0))
            for seq in range(11, 11 + 255 if left > 0 else 11):
                robot.write_raw(encode_frame(seq & 0xFF, *pack(gen.GetStatus())))
        assert [r.result for r in replies] == [gen.AckResult.APPLIED, gen.AckResult.APPLIED]
        time.sleep(0.05)  # past the coast interval of the reversal
        assert robot.status().left == -300


def test_out_of_range_and_wrong_direction_are_refused(robot_port: str) -> None:
    with RobotLink(robot_port) as robot:
        robot.write_raw(encode_frame(9, gen.SetDrive.ID, (1500).to_bytes(2, "little", signed=True)
                                  + bytes(2)))
        nack = robot.wait_for(lambda m: isinstance(m, gen.Nack) and m.seq == 9, 0.5)
        assert nack.error == gen.Error.OUT_OF_RANGE
        robot.write_raw(encode_frame(10, *pack(gen.Ack(seq=1, result=0))))
        nack = robot.wait_for(lambda m: isinstance(m, gen.Nack) and m.seq == 10, 0.5)
        assert nack.error == gen.Error.WRONG_DIRECTION


def test_a_robot_of_another_spec_is_refused(robot_port: str) -> None:
    with pytest.raises(LinkError, match="protocol mismatch"):
        RobotLink(robot_port, expected_hash=gen.SCHEMA_HASH ^ 1).open()
