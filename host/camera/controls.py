"""V4L2 capture set-up through OpenCV: ask for a mode, read back what the driver granted, and
lock exposure, gain and white balance to the same values on every sensor of a stereo camera.

Block matching compares raw intensities, so two sensors that each run their own auto exposure
and white balance make the same surface look different in the two views, and a scene that
brightens changes every cost. After a few frames of auto (to settle on the scene), the left
sensor's values are read and written to all sensors with the auto modes off.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import cv2

# V4L2_CID_EXPOSURE_AUTO as OpenCV's V4L2 backend passes it: 1 manual, 3 aperture priority
EXPOSURE_MANUAL = 1
# (name, the auto switch and its manual value or None, the value's property)
CONTROLS = (("exposure", cv2.CAP_PROP_AUTO_EXPOSURE, EXPOSURE_MANUAL, cv2.CAP_PROP_EXPOSURE),
            ("gain", None, None, cv2.CAP_PROP_GAIN),
            ("white balance", cv2.CAP_PROP_AUTO_WB, 0, cv2.CAP_PROP_WB_TEMPERATURE))


@dataclass(frozen=True)
class Format:
    """A capture format: V4L2 fourcc, size (px), frame rate (fps), driver buffers."""

    fourcc: str
    width: int
    height: int
    fps: float
    buffers: int

    def __str__(self) -> str:
        return (f"{self.fourcc} {self.width}x{self.height} at {self.fps:g} fps, "
                f"{self.buffers} buffer{'s' if self.buffers != 1 else ''}")


def fourcc_text(code: float) -> str:
    c = int(code)
    text = "".join(chr((c >> 8 * i) & 0xFF) for i in range(4))
    return text if text.isprintable() and text.strip() else "?"


def request(cap: Any, asked: Format) -> None:
    """Ask the driver for a format (it may grant another: read it back with granted())."""
    cap.set(cv2.CAP_PROP_FOURCC, cv2.VideoWriter_fourcc(*asked.fourcc))  # type: ignore[attr-defined]  # cv2 stubs lack it
    cap.set(cv2.CAP_PROP_FRAME_WIDTH, asked.width)
    cap.set(cv2.CAP_PROP_FRAME_HEIGHT, asked.height)
    cap.set(cv2.CAP_PROP_FPS, asked.fps)
    cap.set(cv2.CAP_PROP_BUFFERSIZE, asked.buffers)  # few buffers: the newest frame, no queue


def granted(cap: Any) -> Format:
    """The format the driver actually set."""
    return Format(fourcc_text(cap.get(cv2.CAP_PROP_FOURCC)),
                  int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT)),
                  float(cap.get(cv2.CAP_PROP_FPS)), int(cap.get(cv2.CAP_PROP_BUFFERSIZE)))


def differences(asked: Format, got: Format) -> list[str]:
    """What the driver changed, one phrase per field ([] when it granted everything)."""
    out = []
    if got.fourcc != asked.fourcc:
        out.append(f"format {got.fourcc} instead of {asked.fourcc}")
    if (got.width, got.height) != (asked.width, asked.height):
        out.append(f"size {got.width}x{got.height} instead of {asked.width}x{asked.height}")
    if abs(got.fps - asked.fps) > 0.5:
        out.append(f"{got.fps:g} fps instead of {asked.fps:g}")
    if got.buffers != asked.buffers:
        out.append(f"{got.buffers} buffers instead of {asked.buffers}")
    return out


def warn(message: str) -> None:
    print(f"camera: {message}", file=sys.stderr)


def check_granted(device: str, cap: Any, asked: Format,
                  say: Callable[[str], None] = warn) -> Format:
    """Read back the granted format and warn about each thing that differs from the asked."""
    got = granted(cap)
    changed = differences(asked, got)
    if changed:
        say(f"{device}: the driver granted {'; '.join(changed)}")
    return got


def _offered(value: float) -> bool:
    return value == value and value >= 0  # OpenCV's V4L2 backend gives -1 for no such control


def lock_controls(caps: list[Any], devices: list[str],
                  say: Callable[[str], None] = warn) -> dict[str, float]:
    """Set exposure, gain and white balance of every capture to the first one's current values,
    auto modes off; returns {control: value} of those locked, warns about the others."""
    locked = {}
    for name, auto, manual, prop in CONTROLS:
        values = [cap.get(prop) for cap in caps]
        missing = [d for d, v in zip(devices, values) if not _offered(v)]
        if missing:
            say(f"{', '.join(missing)} offers no {name} control: left as the driver runs it")
            continue
        value = values[0]
        for cap in caps:
            if auto is not None:
                cap.set(auto, manual)
            cap.set(prop, value)
        back = [cap.get(prop) for cap in caps]
        off = [f"{d} kept {b:g}" for d, b in zip(devices, back) if abs(b - value) > 1e-6]
        if off:
            say(f"could not lock {name} at {value:g}: {', '.join(off)}")
        else:
            locked[name] = float(value)
    return locked
