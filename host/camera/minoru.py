"""The Minoru 3D webcam: two UVC sensors (USB 0ac8:3410 / 0ac8:3420) behind one USB 2.0 hub.

Both sensors send YUYV only (no MJPEG), so both at 640x480 and 30 fps exceed one USB 2.0 bus
(2 x 640 x 480 x 2 bytes x 30/s = 36.9 MB/s): the driver refuses with VIDIOC_STREAMON: No space
left on device. Offered modes: 320x240 at 30 fps (the default) and 640x480 at 15 fps.
The two streams are not synchronised: both are grabbed, then both retrieved, and a pair whose
buffer timestamps differ by more than max_skew_ms is dropped (the older frame is grabbed again).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import cv2

from host.camera.discovery import resolve
from host.camera.source import CameraError, StereoFrame, StereoSource

MODES = {(320, 240): 30, (640, 480): 15}


def open_v4l2(device: str, width: int, height: int, fps: int) -> Any:
    cap = cv2.VideoCapture(device, cv2.CAP_V4L2)
    if not cap.isOpened():
        raise CameraError(f"cannot open {device} (is it plugged in, and are you in the video "
                          f"group?)")
    cap.set(cv2.CAP_PROP_FOURCC, cv2.VideoWriter_fourcc(*"YUYV"))
    cap.set(cv2.CAP_PROP_FRAME_WIDTH, width)
    cap.set(cv2.CAP_PROP_FRAME_HEIGHT, height)
    cap.set(cv2.CAP_PROP_FPS, fps)
    cap.set(cv2.CAP_PROP_BUFFERSIZE, 1)  # the newest frame, not a queue of old ones
    return cap


class MinoruSource(StereoSource):
    """Pairs from the Minoru; devices, swap and the capture factory can be overridden."""

    def __init__(self, size: tuple[int, int] = (320, 240), devices: tuple[str, str] | None = None,
                 swap: bool = False, max_skew_ms: float | None = None, spec: str = "minoru",
                 open_capture: Callable[[str, int, int, int], Any] = open_v4l2) -> None:
        if size not in MODES:
            raise CameraError(f"the Minoru streams {', '.join(f'{w}x{h}' for w, h in MODES)} "
                              f"(both sensors share one USB 2.0 bus), not {size[0]}x{size[1]}")
        self.size, self.fps = size, MODES[size]
        self.max_skew_ms = 0.5e3 / self.fps if max_skew_ms is None else max_skew_ms
        if devices is None:
            left, right = resolve(spec).nodes
            devices = (left, right)
        if swap:
            devices = (devices[1], devices[0])
        self.devices = devices
        self.dropped = 0
        self._caps = [open_capture(d, size[0], size[1], self.fps) for d in devices]

    def _grab(self, i: int) -> float:
        if not self._caps[i].grab():
            raise CameraError(f"{self.devices[i]} stopped delivering frames (unplugged? if it "
                              f"never started: VIDIOC_STREAMON: No space left on device means "
                              f"the USB bus is full; use 320x240 or another USB controller)")
        return self._caps[i].get(cv2.CAP_PROP_POS_MSEC) / 1000.0

    def _read(self) -> StereoFrame | None:
        t = [self._grab(0), self._grab(1)]
        for _ in range(4):  # re-grab the older side until the pair is close in time
            if abs(t[0] - t[1]) * 1000 <= self.max_skew_ms:
                break
            self.dropped += 1
            older = 0 if t[0] < t[1] else 1
            t[older] = self._grab(older)
        else:
            raise CameraError(f"the two sensors drift apart by {abs(t[0] - t[1]) * 1000:.0f} ms"
                              f" (more than {self.max_skew_ms:.0f} ms)")
        frames = []
        for i, cap in enumerate(self._caps):
            ok, img = cap.retrieve()
            if not ok or img is None:
                raise CameraError(f"{self.devices[i]} gave no image")
            frames.append(img)
        return StereoFrame(frames[0], frames[1], t[0], t[1])

    def close(self) -> None:
        for cap in self._caps:
            cap.release()
