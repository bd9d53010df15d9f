"""Messages of the serial protocol: pack to and unpack from payload bytes, with range checks.

The message classes, ids and layouts come from host/link/protocol_gen.py, generated from
protocol/spec.toml; nothing here repeats them.
"""

from __future__ import annotations

import struct
from dataclasses import fields
from typing import Any

from host.errors import HostError
from host.link import protocol_gen as gen


class ProtocolError(HostError):
    """A payload that is not a valid message; code is the protocol's error code (a HostError:
    one line and exit status 2 when it reaches the CLI)."""

    def __init__(self, code: gen.Error, message: str) -> None:
        super().__init__(message)
        self.code = code


def pack(msg: Any) -> tuple[int, bytes]:
    """(id, payload) of a message object; raises ProtocolError when a field is out of range."""
    values = []
    for f in fields(msg):
        v = getattr(msg, f.name)
        lo, hi = msg.RANGES[f.name]
        if not lo <= v <= hi:
            raise ProtocolError(gen.Error.OUT_OF_RANGE,
                                f"{msg.NAME}.{f.name} = {v} is outside {lo}..{hi}")
        values.append(v)
    return msg.ID, struct.pack(msg.FORMAT, *values)


def unpack(msg_id: int, payload: bytes) -> Any:
    """The message object for a frame's id and payload, checked as the receiver checks it."""
    cls: Any = gen.MESSAGES.get(msg_id)  # a generated message class: ID, SIZE, FORMAT ...
    if cls is None:
        raise ProtocolError(gen.Error.UNKNOWN_ID, f"unknown message id 0x{msg_id:02X}")
    if len(payload) != cls.SIZE:
        raise ProtocolError(gen.Error.BAD_LENGTH,
                            f"{cls.NAME} needs {cls.SIZE} payload bytes, got {len(payload)}")
    msg = cls(*struct.unpack(cls.FORMAT, payload))
    for f in fields(msg):
        lo, hi = cls.RANGES[f.name]
        if not lo <= getattr(msg, f.name) <= hi:
            value = getattr(msg, f.name)
            raise ProtocolError(gen.Error.OUT_OF_RANGE,
                                f"{cls.NAME}.{f.name} = {value} is outside {lo}..{hi}")
    return msg


def describe(msg_id: int, payload: bytes) -> str:
    """Text form "NAME field=value ..." (the same text the C side's proto_format writes);
    for a payload that does not decode, "error NAME" with the protocol's error name."""
    try:
        msg = unpack(msg_id, payload)
    except ProtocolError as e:
        return f"error {e.code.name}"
    return " ".join([msg.NAME] + [f"{f.name}={getattr(msg, f.name)}" for f in fields(msg)])
