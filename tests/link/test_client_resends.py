"""The client's numbering and its judgement of ACK DUPLICATE, against a scripted robot that
recognises resends by (SEQ, ID) only, as the old firmware did."""

from __future__ import annotations

import dataclasses

import pytest

from host.link import protocol_gen as gen
from host.link.client import LinkError, RobotLink
from host.link.frame import FrameDecoder, encode_frame
from host.link.messages import pack, unpack


class OldRobot:
    """A serial port with a robot behind it that answers at once; `lose` ACKs are swallowed."""

    def __init__(self) -> None:
        self.out = b""
        self.dec = FrameDecoder()
        self.last: tuple[int, int] | None = None
        self.applied: list[tuple[int, object]] = []
        self.seqs: list[tuple[str, int]] = []
        self.lose = 0
        self.tx_seq = 0

    def _send(self, msg) -> None:
        self.out += encode_frame(self.tx_seq & 0xFF, *pack(msg))
        self.tx_seq += 1

    def write(self, data: bytes) -> int:
        for f in self.dec.feed(data):
            msg = unpack(f.id, f.payload)
            self.seqs.append((msg.NAME, f.seq))
            if isinstance(msg, gen.Hello):
                self._send(gen.HelloReply(nonce=msg.nonce, schema_hash=gen.SCHEMA_HASH,
                                          fw_version=0x100, reset_cause=1, link_timeout_ms=250))
            elif isinstance(msg, gen.GetStatus):
                self._send(gen.Status(*[0] * len(dataclasses.fields(gen.Status))))
            else:
                result = gen.AckResult.APPLIED
                if self.last == (f.seq, f.id):
                    result = gen.AckResult.DUPLICATE
                else:
                    self.applied.append((f.seq, msg))
                self.last = (f.seq, f.id)
                if self.lose:
                    self.lose -= 1
                else:
                    self._send(gen.Ack(seq=f.seq, result=result))
        return len(data)

    @property
    def in_waiting(self) -> int:
        return len(self.out)

    def read(self, n: int) -> bytes:
        data, self.out = self.out[:n], self.out[n:]
        return data

    def close(self) -> None:
        pass


@pytest.fixture
def robot(monkeypatch) -> tuple[RobotLink, OldRobot]:
    fake = OldRobot()
    monkeypatch.setattr("serial.serial_for_url", lambda *a, **k: fake)
    # the fake answers at once: the timeout only runs out on a lost ACK, or when a loaded
    # machine (two test workers beside other jobs) pauses this process longer than it
    link = RobotLink("fake://", reply_timeout_s=0.5).open()
    return link, fake


def test_a_duplicate_answer_to_a_command_never_sent_before_is_an_error(robot) -> None:
    """The issue's counterexample at the host: SET_DRIVE seq 10 at +300, then a new SET_DRIVE
    that again gets seq 10 at -300; a robot that answers DUPLICATE has not reversed."""
    link, fake = robot
    link._seq = 9
    link.drive(300, 300)
    for _ in range(255):
        link.status()
    link._seq = 9  # the counter came round to 10 again
    with pytest.raises(LinkError, match="duplicate of another command: it was not applied"):
        link.drive(-300, -300)
    assert [m.left for _, m in fake.applied] == [300]


def test_a_duplicate_answer_to_a_resend_is_believed(robot) -> None:
    link, fake = robot
    fake.lose = 1  # the robot applies the first try, but its ACK is lost: the client resends
    link.drive(200, 200)
    assert link.duplicates == 1 and [m.left for _, m in fake.applied] == [200]


def test_polls_do_not_use_up_command_sequence_numbers(robot) -> None:
    link, fake = robot
    link.drive(100, 100)
    for _ in range(300):
        link.status()
    link.drive(-100, -100)
    commands = [seq for name, seq in fake.seqs if name == "SET_DRIVE"]
    assert commands[1] == (commands[0] + 1) & 0xFF
    assert [m.left for _, m in fake.applied] == [100, -100]
