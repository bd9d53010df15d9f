"""Capture times of grabbed frames, in seconds on time.monotonic()'s clock.

OpenCV's V4L2 backend gives the driver's buffer timestamp as CAP_PROP_POS_MSEC; uvcvideo stamps
buffers with CLOCK_MONOTONIC (the clock of time.monotonic) when the frame's first bytes
arrive, which is closer to the exposure than the moment grab() returns. Where the property is
missing or on another clock (some backends, video files), the time grab() returned stands in.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import cv2

STAMPS = ("auto", "driver", "grab")


class Stamper:
    """Call right after cap.grab(): the frame's capture time (s). mode: auto decides on the
    first frame between the driver's stamp and the grab time; driver and grab force one."""

    def __init__(self, mode: str = "auto", clock: Callable[[], float] = time.monotonic,
                 max_offset_s: float = 2.0) -> None:
        if mode not in STAMPS:
            raise ValueError(f"timestamps must be one of {', '.join(STAMPS)}, not {mode!r}")
        self.mode, self.clock, self.max_offset_s = mode, clock, max_offset_s
        self.kind = None if mode == "auto" else mode

    def __call__(self, cap: Any) -> float:
        now = self.clock()
        if self.kind == "grab":
            return now
        driver = float(cap.get(cv2.CAP_PROP_POS_MSEC)) / 1000.0
        if self.kind is None:
            on_clock = driver > 0 and abs(driver - now) < self.max_offset_s
            self.kind = "driver" if on_clock else "grab"
            if self.kind == "grab":
                return now
        return driver
