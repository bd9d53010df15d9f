"""The modes a UVC camera offers, read from its raw USB descriptors (sysfs `descriptors`).

The kernel exposes each USB device's descriptors as one binary file; the UVC class-specific
VideoStreaming descriptors in it list every format (YUYV, MJPEG, ...) with its frame sizes and
frame intervals (units of 100 ns), the same table `v4l2-ctl --list-formats-ext` prints.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

CS_INTERFACE = 0x24
INTERFACE = 0x04
VS_FORMAT_UNCOMPRESSED, VS_FRAME_UNCOMPRESSED = 0x04, 0x05
VS_FORMAT_MJPEG, VS_FRAME_MJPEG = 0x06, 0x07
VS_FORMAT_FRAME_BASED, VS_FRAME_FRAME_BASED = 0x10, 0x11
VIDEO_CLASS, VIDEO_STREAMING = 0x0E, 0x02
_FOURCC_OF_GUID = {"YUY2": "YUYV", "NV12": "NV12", "M420": "M420", "I420": "YU12"}


@dataclass(frozen=True)
class Mode:
    """One streaming mode: pixel format (V4L2 fourcc), size (px) and frame rates (fps)."""

    fourcc: str
    width: int
    height: int
    fps: tuple[float, ...]

    @property
    def max_fps(self) -> float:
        return max(self.fps) if self.fps else 0.0

    def __str__(self) -> str:
        rates = "/".join(f"{f:g}" for f in sorted(set(self.fps), reverse=True))
        return f"{self.fourcc} {self.width}x{self.height}@{rates}"


def _intervals(desc: bytes, kind: int, at: int) -> tuple[float, ...]:
    """Frame rates from the interval table at byte `at`: kind 0 is continuous, else a count."""
    if kind == 0:  # continuous: min, max, step
        lo, hi, _ = struct.unpack_from("<III", desc, at)
        return tuple(round(1e7 / v, 3) for v in (lo, hi) if v)
    values = struct.unpack_from(f"<{kind}I", desc, at)
    return tuple(round(1e7 / v, 3) for v in values if v)


def parse_modes(blob: bytes) -> list[Mode]:
    """Every (format, size, rates) of the VideoStreaming interfaces in a descriptor blob.

    Malformed or truncated descriptors end the walk: a partial table is better than none.
    """
    modes: list[Mode] = []
    fourcc = ""
    streaming = False
    i = 0
    while i + 2 <= len(blob):
        length, kind = blob[i], blob[i + 1]
        if length < 2 or i + length > len(blob):
            break
        desc = blob[i:i + length]
        i += length
        if kind == INTERFACE and length >= 9:
            streaming = desc[5] == VIDEO_CLASS and desc[6] == VIDEO_STREAMING
            continue
        if kind != CS_INTERFACE or not streaming or length < 3:
            continue
        sub = desc[2]
        if sub in (VS_FORMAT_UNCOMPRESSED, VS_FORMAT_FRAME_BASED) and length >= 21:
            guid = desc[5:9].decode("ascii", "replace")
            fourcc = _FOURCC_OF_GUID.get(guid, guid.strip("\0 ") or "?")
        elif sub == VS_FORMAT_MJPEG:
            fourcc = "MJPG"
        elif sub in (VS_FRAME_UNCOMPRESSED, VS_FRAME_MJPEG, VS_FRAME_FRAME_BASED) and length >= 26:
            w, h = struct.unpack_from("<HH", desc, 5)
            # frame-based frames have no buffer-size field: the interval type sits 4 bytes earlier
            kind = desc[21] if sub == VS_FRAME_FRAME_BASED else desc[25]
            try:
                modes.append(Mode(fourcc, w, h, _intervals(desc, kind, 26)))
            except struct.error:
                break
    return modes

