"""What the firmware's simavr tests share: a millisecond in CPU cycles, the configuration with
the ramp off and the length of its frame, and `first`, the event a test waits for."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TypeVar

from host.emulator.simavr import CYCLES_PER_MS as MS
from host.link import protocol_gen as gen
from host.link.frame import encode_frame
from host.link.messages import pack

__all__ = ["FRAME", "MS", "NO_RAMP", "first"]

NO_RAMP = gen.SetConfig(link_timeout_ms=gen.DEFAULT_LINK_TIMEOUT_MS, accel_limit=0)
FRAME = len(encode_frame(0, *pack(NO_RAMP)))  # bytes of a SET_CONFIG or SET_DRIVE frame

T = TypeVar("T")


def first(items: Iterable[T], what: str = "the expected event") -> T:
    """The first of items; a failed assertion (not StopIteration) when there is none: what the
    test waits for never happened, which is the firmware's behaviour, not the test's."""
    for x in items:
        return x
    raise AssertionError(f"never happened: {what}")
