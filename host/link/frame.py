"""Framing of the serial protocol: START LEN SEQ ID PAYLOAD CRC (docs/protocol.md).

The decoder mirrors the firmware's parser (protocol/c/frame.c): it rejects an oversize LEN as
soon as it is read, never accepts a frame whose CRC fails, and after a rejected frame searches
for the next START from the byte after the rejected frame's START.
"""

from __future__ import annotations

from dataclasses import dataclass

import crcmod.predefined

from host.link import protocol_gen as gen

_crc = crcmod.predefined.mkCrcFun(gen.CRC_NAME)


def crc(data: bytes) -> int:
    """The protocol's CRC (gen.CRC_NAME, CRC-32C) of LEN SEQ ID PAYLOAD."""
    return int(_crc(data))


@dataclass(frozen=True)
class Frame:
    seq: int
    id: int
    payload: bytes


def encode_frame(seq: int, msg_id: int, payload: bytes) -> bytes:
    """The bytes on the wire for one frame."""
    if len(payload) > gen.MAX_PAYLOAD:
        raise ValueError(f"payload of {len(payload)} bytes exceeds {gen.MAX_PAYLOAD}")
    body = bytes([len(payload), seq & 0xFF, msg_id & 0xFF]) + payload
    return bytes([gen.START]) + body + crc(body).to_bytes(gen.CRC_LEN, "little")


class FrameDecoder:
    """Byte-stream decoder; feed() returns the frames completed by the new bytes."""

    def __init__(self) -> None:
        self._buf = bytearray()  # from a START on; empty while searching for one
        self.good_frames = 0
        self.crc_errors = 0
        self.framing_errors = 0

    def feed(self, data: bytes) -> list[Frame]:
        frames: list[Frame] = []
        pending = bytearray(data)
        while pending:
            byte = pending.pop(0)
            if not self._buf:
                if byte == gen.START:
                    self._buf.append(byte)
                continue
            if len(self._buf) == 1 and byte > gen.MAX_PAYLOAD:
                self.framing_errors += 1
                self._buf.clear()
                if byte == gen.START:  # the rejected LEN may itself start the next frame
                    self._buf.append(byte)
                continue
            self._buf.append(byte)
            need = gen.HEADER_LEN + self._buf[1] + gen.CRC_LEN
            if len(self._buf) < need:
                continue
            body = bytes(self._buf[1:-gen.CRC_LEN])
            if crc(body) == int.from_bytes(self._buf[-gen.CRC_LEN:], "little"):
                self.good_frames += 1
                frames.append(Frame(body[1], body[2], body[3:]))
                self._buf.clear()
            else:
                self.crc_errors += 1
                pending[0:0] = self._buf[1:]  # look again after the false START
                self._buf.clear()
        return frames
