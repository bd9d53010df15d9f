"""The host's end of the serial link: handshake, numbered commands with ACK and resend, status.

    with RobotLink("/dev/ttyACM0") as robot:   # opens, says HELLO, checks the schema hash
        robot.drive(300, 300)                  # permille duty; resent until acknowledged
        robot.keepalive()                      # for a caller that drives less often than
                                               # link_timeout_ms / 3 (the servo sends
                                               # SET_DRIVE every frame)
    # leaving the block sends STOP, also on an exception or Ctrl-C

Every failure is a LinkError with a one-line message. Before driving, every status_s the link
asks the robot's STATUS: a reset (also one whose BOOT frame was lost), a stop of its own for
link loss, or a state that is not the one commanded is seen there. After any reset it learns
of, the link says HELLO again and re-applies its configuration, then raises RobotReset.
Timeouts are measured on the port's clock: the wall clock for a serial port, the simulated
clock for the simulation's in-process line.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from typing import Any

from host.errors import HostError
from host.link import protocol_gen as gen
from host.link.frame import FrameDecoder, encode_frame
from host.link.messages import ProtocolError, pack, unpack
from host.link.port import Port, PortError, SerialPort


class LinkError(HostError):
    """The serial link or the robot failed; the message is one line."""


UPTIME_SLACK_MS = 250


class RobotReset(LinkError):
    """The robot reset during the session; the link has said HELLO again, re-applied its
    configuration and sent STOP: the robot stands."""


_RESET_EXPLAINED = {
    gen.ResetCause.WATCHDOG: "watchdog: the firmware hung; the watchdog stopped the motors and "
                             "reset the board",
    gen.ResetCause.POWER_ON: "power-on: the board lost its supply",
    gen.ResetCause.EXTERNAL: "external: its reset pin (the reset button, or another program "
                             "opening the port)",
    gen.ResetCause.BROWN_OUT: "brown-out: its supply voltage dropped",
    gen.ResetCause.UNKNOWN: "cause unknown (behind the Uno's bootloader: the reset pin or a "
                            "brown-out that kept RAM)",
}


def explain_reset(cause: int) -> str:
    """One phrase for a proto reset cause, naming it and what it means for the user."""
    try:
        return _RESET_EXPLAINED[gen.ResetCause(cause)]
    except ValueError:
        return f"cause {cause} (not in this host's protocol)"


SERVO_DRIVE_BUDGET_S = 0.2  # s: a servo's drive is two tries of the default reply timeout


class RobotLink:
    """A session with the robot over a serial port (a device path or a pyserial URL) or an
    open Port (host.link.port); rng numbers the frames and draws the HELLO nonces (seed it for
    a repeatable simulation)."""

    def __init__(self, port: str | Port, *, baud: int = gen.BAUD, reply_timeout_s: float = 0.1,
                 retries: int = 8, handshake_s: float = 3.0, keepalive_s: float = 0.08,
                 status_s: float = 0.5, drive_budget_s: float | None = None,
                 expected_hash: int = gen.SCHEMA_HASH,
                 rng: random.Random | None = None) -> None:
        self.port = port if isinstance(port, str) else getattr(port, "name", "the robot's line")
        self._port_arg = port
        self.status_s = status_s  # how often drive() first checks the robot's STATUS; 0: never
        # a drive() not confirmed within this long (its STATUS check included) is given up and
        # the robot sent STOP instead: while the host resends, the robot runs on the command
        # before, on an observation that grows old (None: the retries alone bound it; the
        # servo's links use SERVO_DRIVE_BUDGET_S)
        self.drive_budget_s = drive_budget_s
        self.unconfirmed = 0  # drives given up for a STOP (drive_budget_s)
        self.baud = baud
        self.reply_timeout_s = reply_timeout_s
        self.retries = retries
        self.handshake_s = handshake_s
        self.keepalive_s = keepalive_s
        self.expected_hash = expected_hash
        self.hello: Any = None
        self.duplicates = 0  # resends the robot had already applied
        self.received_bytes = 0  # every byte read, frame or not (the handshake reports it)
        self.resends = 0  # commands sent again after silence or a CRC NACK
        self.nacks = 0  # NACKs received
        self.resets = 0  # resets the robot went through during the session (BOOT or STATUS)
        self.link_losses = 0  # stops of the robot's own for link loss, seen in STATUS
        self.notes: list[str] = []  # what the link saw and the user should know
        self._ser: Port | None = None
        self._dec = FrameDecoder()
        self._rng = rng or random.Random()
        # commands and polls are numbered from separate counters (docs/protocol.md, "Sequence
        # numbers and resends"), so polls can never bring a command's SEQ round again
        self._seq = self._rng.randrange(256)
        self._poll_seq = self._rng.randrange(256)
        self._last_command = b""  # the last command frame written, for judging DUPLICATE
        self._last_drive: tuple[int, int] | None = None
        self._last_drive_sent = 0.0
        self._config: tuple[int, int] | None = None  # (link timeout, accel limit) last set
        self._uptime: tuple[int, float] | None = None  # robot's uptime (ms) at the last STATUS
        # and when (s) on this host's clock
        self._status_t = 0.0
        self._resyncing = False

    # ----------------------------------------------------------------------------- port I/O

    def open(self) -> RobotLink:
        if isinstance(self._port_arg, str):
            try:
                self._ser = SerialPort(self._port_arg, self.baud)
            except PortError as e:
                raise LinkError(f"cannot open {self.port}: {e}") from None
        else:
            self._ser = self._port_arg
        try:
            self.hello = self._handshake()
            self._learn_uptime()
        except BaseException:
            self.close()  # a failed handshake leaves the port closed (and an Uno's DTR off)
            raise
        return self

    def _now(self) -> float:
        assert self._ser is not None
        return self._ser.now()

    def _write(self, data: bytes) -> None:
        assert self._ser is not None
        try:
            self._ser.write(data)
        except PortError as e:
            raise LinkError(f"lost the serial port {self.port}: {e}") from None

    def _messages(self, wait_s: float = 0.005) -> list[Any]:
        assert self._ser is not None
        try:
            data = self._ser.read(wait_s)
        except PortError as e:
            raise LinkError(f"lost the serial port {self.port}: {e}") from None
        self.received_bytes += len(data)
        out = []
        for f in self._dec.feed(data):
            try:
                msg = unpack(f.id, f.payload)
            except ProtocolError:
                continue  # a frame from a robot of another spec; the handshake says so
            if isinstance(msg, gen.Boot) and self.hello is not None and not self._resyncing:
                raise self._resync(f"the robot reset during the session: "
                                   f"{explain_reset(msg.reset_cause)}")
            out.append(msg)
        return out

    def _await(self, match: Callable[[Any], bool], timeout_s: float) -> Any:
        deadline = self._now() + timeout_s
        while (now := self._now()) < deadline:
            for msg in self._messages(deadline - now):
                if match(msg):
                    return msg
        return None

    def write_raw(self, data: bytes) -> None:
        """Send bytes as given, framed or not (conformance checks and tools: a frame the client
        would never build, a reply out of place)."""
        self._write(data)

    def wait_for(self, match: Callable[[Any], bool], timeout_s: float) -> Any:
        """The first message from the robot that `match` accepts within timeout_s, else None."""
        return self._await(match, timeout_s)

    def _resync(self, why: str) -> RobotReset:
        """After a reset: HELLO again and the configuration re-applied, so nothing is driven on
        a board that forgot it; the RobotReset to raise (a LinkError if the robot is gone)."""
        self.resets += 1
        self._last_drive, self._last_command, self._uptime = None, b"", None
        self._resyncing = True
        try:
            self.hello = self._handshake()
            if self._config is not None:
                self.set_config(*self._config)
            self.stop()  # what it did since the reset was driven on a board that had forgotten
            self._learn_uptime()
        finally:
            self._resyncing = False
        return RobotReset(why)

    def _learn_uptime(self) -> None:
        """After a handshake: the robot has been up for 0 ms at least by now, what later STATUS
        uptimes are judged against."""
        self._status_t = self._now()
        self._uptime = (0, self._status_t)

    # ----------------------------------------------------------------------------- protocol

    def _handshake(self) -> Any:
        # An Uno resets when the port opens; its bootloader needs a moment, so HELLO is resent
        # until the reply with this nonce comes or handshake_s runs out.
        nonce = self._rng.getrandbits(32)
        deadline = self._now() + self.handshake_s
        dec = self._dec
        good0, bad0 = dec.good_frames, dec.crc_errors + dec.framing_errors
        bytes0 = self.received_bytes
        read = [0, 0]  # frames that decoded to a message of this host's spec; of them, HELLOs

        def is_reply(m: Any) -> bool:
            read[0] += 1
            read[1] += isinstance(m, gen.Hello)  # our own HELLO: the line echoes
            return isinstance(m, gen.HelloReply) and m.nonce == nonce

        while self._now() < deadline:
            self._write(encode_frame(self._next_poll_seq(), *pack(gen.Hello(nonce=nonce))))
            reply = self._await(is_reply, min(0.25, max(0.0, deadline - self._now())))
            if reply is None:
                continue
            if reply.schema_hash != self.expected_hash:
                raise LinkError(f"protocol mismatch: the robot's firmware was built from spec "
                                f"0x{reply.schema_hash:08X}, this host from 0x"
                                f"{self.expected_hash:08X}; flash the firmware built from this "
                                f"checkout")
            return reply
        good, bad = dec.good_frames - good0, dec.crc_errors + dec.framing_errors - bad0
        noise = self.received_bytes - bytes0
        raise LinkError(f"no answer from a robot on {self.port} within "
                        f"{self.handshake_s:g} s: "
                        f"{_seen(noise, good, bad, good - read[0], read[1], self.baud)}")

    def _next_seq(self) -> int:
        self._seq = (self._seq + 1) & 0xFF
        return self._seq

    def _next_poll_seq(self) -> int:
        self._poll_seq = (self._poll_seq + 1) & 0xFF
        return self._poll_seq

    def _transact(self, msg: Any, match: Callable[[Any, int], bool], seq: int,
                  until: float | None = None) -> Any:
        """Send msg as seq and wait for the reply match accepts; resend on silence or a CRC
        NACK. With until (this link's clock), no resend whose wait would end after it: None
        when no reply came by then (the first try is always made)."""
        frame = encode_frame(seq, *pack(msg))
        sent_before = frame == self._last_command
        for attempt in range(self.retries):
            if attempt and until is not None and self._now() + self.reply_timeout_s > until:
                return None
            self.resends += attempt > 0
            self._write(frame)
            if msg.ID != gen.GetStatus.ID:
                self._last_command = frame
            reply = self._await(lambda m: match(m, seq), self.reply_timeout_s)
            if reply is None:
                continue
            if isinstance(reply, gen.Nack):
                self.nacks += 1
                if reply.error == gen.Error.BAD_CRC:
                    continue
                raise LinkError(f"the robot refused {msg.NAME}: "
                                f"{gen.Error(reply.error).name.lower().replace('_', ' ')}")
            if (isinstance(reply, gen.Ack) and reply.result == gen.AckResult.DUPLICATE
                    and not (attempt or sent_before)):
                # the robot took a frame it had never been sent for a resend: the command
                # was not applied, and it is still doing something else
                raise LinkError(f"the robot answered {msg.NAME} (seq {seq}) as a duplicate of "
                                f"another command: it was not applied")
            return reply
        raise LinkError(f"the robot did not answer {msg.NAME} after {self.retries} tries "
                        f"({self.reply_timeout_s * 1000:.0f} ms each)")

    def command(self, msg: Any, until: float | None = None) -> Any:
        """Send a command and return its ACK (None: none came by until, see _transact)."""
        ack = self._transact(msg, lambda m, seq: isinstance(m, (gen.Ack, gen.Nack))
                             and m.seq == seq, self._next_seq(), until)
        if ack is not None and ack.result == gen.AckResult.DUPLICATE:
            self.duplicates += 1
        return ack

    def drive(self, left: int, right: int) -> None:
        """Set both motors' duty in permille (-1000..1000, positive = forward). The robot's
        STATUS is checked first (check_health) every status_s, and when no drive was sent for
        the robot's link timeout. Not confirmed within drive_budget_s (the check included),
        the drive is given up: the robot is sent STOP and a note says so."""
        now = self._now()
        until = now + self.drive_budget_s if self.drive_budget_s is not None else None
        timeout_s = (self._config[0] if self._config else self.hello.link_timeout_ms) / 1000
        if self.status_s and (now - self._status_t >= self.status_s or self._last_drive
                              and now - self._last_drive_sent >= timeout_s):
            # when due, and when the robot may have stopped for link loss
            self.check_health(until)
        if self.command(gen.SetDrive(left=int(left), right=int(right)), until) is None:
            self.unconfirmed += 1
            self.notes.append(f"SET_DRIVE {left} {right} not confirmed within "
                              f"{(self.drive_budget_s or 0.0) * 1000:.0f} ms: STOP sent instead")
            self.stop()
            return
        self._last_drive = (int(left), int(right))
        self._last_drive_sent = self._now()

    def check_health(self, until: float | None = None) -> None:
        """Ask STATUS and judge it against what this host did: a reset (uptime back, another
        cause, the configuration back at its defaults) re-handshakes and raises RobotReset; a
        stop for link loss is counted and noted (the next SET_DRIVE drives again); a robot that
        drives after STOP raises LinkError. A robot that does not answer is left to the next
        command to report."""
        asked = self._status_t = self._now()
        try:
            s = self.status(until)
            if s is None:  # no answer by until: the next check asks again
                return
        except RobotReset:
            raise
        except LinkError as e:
            if "did not answer" in str(e):
                return
            raise
        least = None
        if self._uptime is not None:  # what the uptime must have reached when this STATUS was
            # first asked for, less a slack for the robot's crystal and for a robot whose clock
            # lags (an emulator's thread starved on a loaded machine): a reset within the slack
            # after a handshake is seen by the other checks only
            elapsed_ms = (asked - self._uptime[1]) * 1000
            least = self._uptime[0] + int(elapsed_ms * 0.98) - UPTIME_SLACK_MS
        why = health_problem(s, self.hello, least, self._config)
        if why:
            raise self._resync(f"the robot reset during the session without its BOOT frame "
                               f"({why}): {explain_reset(s.reset_cause)}")
        self._uptime = (s.uptime_ms, self._now())  # that uptime was read by now
        driving = bool(s.flags & gen.StatusFlag.DRIVING)
        if self._last_drive is not None and s.flags & gen.StatusFlag.LINK_LOST:
            self.link_losses += 1
            self.notes.append(f"the robot stopped itself for link loss (no SET_DRIVE within "
                              f"its {s.link_timeout_ms} ms) before {s.uptime_ms} ms of uptime")
        elif self._last_drive is None and driving:
            raise LinkError(f"the robot drives at {s.left} {s.right} though this host stopped "
                            f"it")

    def stop(self) -> None:
        self.command(gen.Stop())
        self._last_drive = None

    def keepalive(self) -> None:
        """Send the drive command again when none was sent for keepalive_s, well inside the
        firmware's link-loss timeout (only SET_DRIVE restarts it, not status polls); does
        nothing while stopped."""
        if self._last_drive and self._now() - self._last_drive_sent >= self.keepalive_s:
            self.drive(*self._last_drive)

    def set_config(self, link_timeout_ms: int,
                   accel_limit: int = gen.DEFAULT_ACCEL_LIMIT) -> None:
        self.command(gen.SetConfig(link_timeout_ms=link_timeout_ms, accel_limit=accel_limit))
        self._config = (link_timeout_ms, accel_limit)

    def status(self, until: float | None = None) -> Any:
        """The robot's STATUS message (None: none came by until, see _transact)."""
        return self._transact(gen.GetStatus(), lambda m, seq: isinstance(m, gen.Status) or (
            isinstance(m, gen.Nack) and m.seq == seq), self._next_poll_seq(), until)

    def close(self) -> None:
        """Stop the motors (best effort) and close the port."""
        if self._ser is None:
            return
        try:
            if self.hello is not None:
                self.stop()
        except LinkError:
            pass  # the port is gone or the robot silent: its link-loss timeout stops it
        finally:
            self._ser.close()
            self._ser = None

    def __enter__(self) -> RobotLink:
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()


def health_problem(s: Any, hello: Any, least_uptime_ms: int | None,
                   config: tuple[int, int] | None) -> str:
    """Why a STATUS shows a reset the host was not told of, or "": the uptime is below the least
    it must have reached by now (modulo its 32-bit wrap), the reset cause is not the one of the
    handshake, or the link timeout and ramp are not what this host set."""
    least = least_uptime_ms
    if least is not None and 0 < (least - s.uptime_ms) % (1 << 32) < 1 << 31:
        return f"uptime {s.uptime_ms} ms where it must have reached {least} ms"
    if s.reset_cause != hello.reset_cause:
        return f"reset cause {s.reset_cause}, {hello.reset_cause} at the handshake"
    if config is not None and (s.link_timeout_ms, s.accel_limit) != config:
        return (f"link timeout {s.link_timeout_ms} ms and ramp {s.accel_limit}, set to "
                f"{config[0]} ms and {config[1]}")
    return ""


def _seen(nbytes: int, good: int, bad: int, unreadable: int, echoed: int, baud: int) -> str:
    """What arrived during a failed handshake, and what that suggests."""
    if unreadable:
        return (f"{unreadable} frame(s) arrived that this host cannot read: a robot built from "
                f"another protocol spec? flash the firmware built from this checkout")
    if good and echoed == good:
        return "only our own HELLO came back: the line echoes (a loopback, not the robot)"
    if good:
        return f"{good} frame(s) arrived but none answered HELLO"
    if nbytes:
        return (f"only garbled frames arrived ({nbytes} bytes, {bad} frame(s) with a bad CRC "
                f"or length): a wrong baud rate (the robot talks at {baud}), a noisy line, or "
                f"another device on the port")
    return "nothing arrived (is the firmware flashed, the robot powered and the port right?)"
