"""The robot's health on the wire: STATUS polled before driving shows a reset whose BOOT frame was
lost and a stop of the robot's own for link loss; after any reset the link says HELLO again and
re-applies its configuration; fault draws on the line do not shift with resends; a write that
times out on a starved host is tried again. All on the simulated clock (host.emulator.lockstep)."""

from __future__ import annotations

import pytest
import serial

from host.emulator.emulator import Emulator, Faults
from host.emulator.lockstep import LockstepLine
from host.link import protocol_gen as gen
from host.link.client import LinkError, RobotLink, RobotReset


class Clock:
    """The simulated time of a robot alone (no world): the emulator's own clock."""

    def __init__(self, emu: Emulator) -> None:
        self.emu, self.ms = emu, 0

    def advance(self, ms: int) -> None:
        self.emu.advance(ms)
        self.ms += ms


def line(faults: Faults = Faults()) -> tuple[Emulator, Clock, LockstepLine]:
    emu = Emulator(faults)
    clock = Clock(emu)
    return emu, clock, LockstepLine(emu, clock.advance, lambda: clock.ms)


def drive_for(robot: RobotLink, clock: Clock, seconds: float, duty: int = 300) -> None:
    """Drive at duty, a command every 30 ms, for `seconds` of simulated time."""
    end = clock.ms + seconds * 1000
    while clock.ms < end:
        robot.drive(duty, duty)
        clock.advance(30)


@pytest.mark.parametrize("boot_lost", [True, False])
def test_a_reset_is_seen_and_the_configuration_re_applied_before_driving(boot_lost) -> None:
    emu, clock, port = line(Faults(reset_at_ms=1200, boot_lost=boot_lost))
    with RobotLink(port, status_s=0.5) as robot:
        robot.set_config(link_timeout_ms=1000, accel_limit=0)
        with pytest.raises(RobotReset, match="reset during the session" +
                           (" without its BOOT frame" if boot_lost else ": watchdog")):
            drive_for(robot, clock, 5.0)
        # seen within one poll of the reset (or at once from its BOOT frame)
        assert 1200 <= clock.ms <= 1200 + 500 + 100
        assert robot.resets == 1 and robot.hello.reset_cause == gen.ResetCause.WATCHDOG
        s = robot.status()  # the board forgot its configuration; the link set it again
        assert (s.link_timeout_ms, s.accel_limit) == (1000, 0)
        assert emu.motors() == (0, 0)  # the link raised before driving the reset board again
        robot.drive(200, 200)  # a caller that goes on drives with the configuration in force
        clock.advance(gen.DEFAULT_REVERSE_COAST_MS + 2)  # the coast after STOP
        assert emu.motors() == (200, 200)


def test_a_stop_of_the_robots_own_for_link_loss_is_noted() -> None:
    emu, clock, port = line()
    with RobotLink(port, status_s=0.5) as robot:
        robot.set_config(link_timeout_ms=100, accel_limit=0)
        drive_for(robot, clock, 0.6)
        clock.advance(300)  # the host falls silent: the firmware stops the motors
        assert emu.motors() == (0, 0)
        robot.drive(300, 300)
        assert robot.link_losses == 1 and "stopped itself for link loss" in robot.notes[0]
        assert emu.motors() == (300, 300)


def test_line_faults_hit_the_same_byte_positions_whatever_was_resent() -> None:
    """Which bytes a fault hits depends on (seed, direction, position) only: two lines with the
    same seed fed different bytes lose and corrupt the same positions."""
    a, b = Emulator(Faults(drop=0.05, corrupt=0.05, seed=9)), Emulator(Faults(drop=0.05,
                                                                          corrupt=0.05, seed=9))
    data_a, data_b = bytes(range(256)) * 8, bytes([0x55]) * 2048
    out_a = a._faulty(data_a, 0)
    out_b = b._faulty(data_b, 0)
    assert len(out_a) == len(out_b) < len(data_a)
    kept_a = [x ^ y for x, y in zip(out_a, [d for i, d in enumerate(data_a)
                                            if a._draws.at(0, i)[0] >= 0.05])]
    kept_b = [x ^ y for x, y in zip(out_b, [d for i, d in enumerate(data_b)
                                            if b._draws.at(0, i)[0] >= 0.05])]
    assert kept_a == kept_b and any(kept_a)  # the same xor at the same kept positions


class StarvedPort:
    """A serial port whose writes time out `stalls` times (a starved host, a full pty) before
    the robot behind it (a native core answering at once) gets them."""

    def __init__(self, stalls: int) -> None:
        self.stalls = stalls
        self.emu = Emulator(line_rate=False)
        self.emu.advance(1)

    def write(self, data: bytes) -> int:
        if self.stalls:
            self.stalls -= 1
            raise serial.SerialTimeoutException("Write timeout")
        self.emu.receive(data)
        self.emu.process()
        return len(data)

    @property
    def in_waiting(self) -> int:
        return 64

    def read(self, n: int) -> bytes:
        self.emu.advance(1)
        return self.emu.transmit()

    def close(self) -> None:
        pass


def test_a_write_timeout_is_tried_again_not_a_lost_port(monkeypatch) -> None:
    fake = StarvedPort(stalls=2)
    monkeypatch.setattr("serial.serial_for_url", lambda *a, **k: fake)
    with RobotLink("starved://") as robot:
        robot.drive(250, 250)
        assert fake.emu.motors()[0] > 0


def test_a_port_that_never_takes_a_write_is_lost(monkeypatch) -> None:
    fake = StarvedPort(stalls=10 ** 6)
    monkeypatch.setattr("serial.serial_for_url", lambda *a, **k: fake)
    monkeypatch.setattr("host.link.port.SerialPort.__init__.__defaults__", (1.0, 0.05))
    with pytest.raises(LinkError, match="lost the serial port starved://: write timeout"):
        RobotLink("starved://").open()


def test_a_robot_clock_that_lags_the_host_is_not_taken_for_a_reset() -> None:
    """An emulator's thread starved on a loaded machine answers with an uptime up to a few
    hundred ms behind the host's clock: that is no reset."""
    emu, clock, port = line()
    with RobotLink(port, status_s=0.5) as robot:
        drive_for(robot, clock, 1.0)
        clock.ms += 200  # the host's clock runs on while the robot's stands (starved)
        drive_for(robot, clock, 1.0)
        assert robot.resets == 0


class DeafLine(LockstepLine):
    """A line whose robot-to-host direction can be cut while the host's bytes still arrive (a
    noisy return wire): the robot applies commands whose ACKs the host never sees."""

    deaf = False

    def read(self, wait_s: float) -> bytes:
        data = super().read(wait_s)
        return b"" if self.deaf else data


def test_a_drive_not_confirmed_within_its_budget_becomes_a_stop() -> None:
    """While the host resends an unconfirmed SET_DRIVE the robot runs on the command before, on
    an observation that grows old: the link gives the drive up within drive_budget_s and
    sends STOP, so the robot does not drive on for all the retries (8 x 100 ms)."""
    emu = Emulator(Faults())
    clock = Clock(emu)
    seen: list[tuple[int, tuple[int, int]]] = []

    def advance(ms: int) -> None:
        clock.advance(ms)
        seen.append((clock.ms, emu.motors()))

    port = DeafLine(emu, advance, lambda: clock.ms)
    with RobotLink(port, status_s=0, drive_budget_s=0.2) as robot:
        robot.set_config(link_timeout_ms=1000, accel_limit=0)
        robot.drive(300, 300)
        advance(30)
        port.deaf = True
        t0 = clock.ms
        with pytest.raises(LinkError, match="did not answer STOP"):
            robot.drive(400, 400)  # given up at the budget; the STOP is not answered either
        assert robot.unconfirmed == 1 and "STOP sent instead" in robot.notes[-1]
        stopped_at = next(t for t, m in seen if t > t0 and m == (0, 0))
        assert stopped_at - t0 <= 200 + 20  # the budget, and the first STOP on the line
