"""Stereo sources: one interface for the Minoru, recorded pairs and the simulated world.

A source yields StereoFrame pairs; a Rectifier given to it (from --calib) is applied to every
pair, so what comes out is always a rectified pair ready for the matcher.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from host.errors import HostError


class CameraError(HostError):
    """A camera failed or vanished; the message is one line."""


@dataclass
class StereoFrame:
    """A left/right pair (uint8 BGR or grey) and their capture times in seconds."""

    left: np.ndarray
    right: np.ndarray
    t_left: float
    t_right: float

    @property
    def skew_ms(self) -> float:
        return abs(self.t_left - self.t_right) * 1000


class Rectify(Protocol):
    def __call__(self, frame: StereoFrame) -> StereoFrame: ...


class StereoSource:
    """Base of every source: read() gives the next rectified pair or None at the end."""

    rectify: Rectify | None = None
    _skews_ms: list[float] | None = None

    def _read(self) -> StereoFrame | None:
        raise NotImplementedError

    def read(self) -> StereoFrame | None:
        frame = self._read()
        if frame is None:
            return None
        if frame.left.shape != frame.right.shape:
            raise CameraError(f"left and right frames differ in size: "
                              f"{frame.left.shape[1]}x{frame.left.shape[0]} vs "
                              f"{frame.right.shape[1]}x{frame.right.shape[0]}")
        if self._skews_ms is None:
            self._skews_ms = []
        self._skews_ms.append(frame.skew_ms)
        return self.rectify(frame) if self.rectify else frame

    def describe(self) -> dict[str, Any]:
        """What this source is, for a capture's manifest."""
        return {"kind": type(self).__name__}

    def skew_summary(self) -> str:
        """Left/right capture-time skew over the pairs read so far (ms)."""
        s = sorted(self._skews_ms or [])
        if not s:
            return "no pairs read"
        return (f"left/right skew over {len(s)} pairs: median {s[len(s) // 2]:.1f} ms, "
                f"max {s[-1]:.1f} ms")

    def __iter__(self) -> Iterator[StereoFrame]:
        while (frame := self.read()) is not None:
            yield frame

    def close(self) -> None:
        pass

    def __enter__(self) -> StereoSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
