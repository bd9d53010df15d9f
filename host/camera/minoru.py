"""The Minoru 3D webcam: two UVC sensors (USB 0ac8:3410 / 0ac8:3420) behind one USB 2.0 hub.

Both sensors send YUYV only (no MJPEG), so both at 640x480 and 30 fps exceed one USB 2.0 bus
(2 x 640 x 480 x 2 bytes x 30/s = 36.9 MB/s): the driver refuses with VIDIOC_STREAMON: No space
left on device. Offered modes: 320x240 at 30 fps (the default) and 640x480 at 15 fps.
The two streams are not synchronised: both are grabbed, then both retrieved, and a pair whose
capture times differ by more than max_skew_ms is dropped (the older frame is grabbed again).
"""

from __future__ import annotations

from host.camera import live
from host.camera.controls import Format, request
from host.camera.discovery import resolve
from host.camera.live import LiveSource, OpenCapture
from host.camera.source import CameraError, StereoFrame

MODES = {(320, 240): 30, (640, 480): 15}


class MinoruSource(LiveSource):
    """Pairs from the Minoru; spec (minoru, minoru:PORT) or devices names the sensors."""

    kind = "minoru"

    def __init__(self, size: tuple[int, int] = (320, 240), devices: tuple[str, str] | None = None,
                 swap: bool = False, max_skew_ms: float | None = None, spec: str = "minoru",
                 open_capture: OpenCapture | None = None, lock: bool = True,
                 settle_frames: int = 15, stamps: str = "auto") -> None:
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
        self.spec, self.devices, self.swapped = spec, devices, swap
        self.dropped = 0
        caps = self._caps = live.open_all(devices, open_capture)
        asked = Format("YUYV", size[0], size[1], self.fps, 1)
        try:
            for cap in caps:
                request(cap, asked)
            self._start(caps, asked, lock, settle_frames, stamps)
        except BaseException:
            self.close()
            raise

    def swap_views(self) -> None:
        self.devices = (self.devices[1], self.devices[0])
        self._caps.reverse()
        self._stampers.reverse()
        self.swapped = not self.swapped

    def _grab(self, i: int) -> float:
        if not self._caps[i].grab():
            raise CameraError(f"{self.devices[i]} stopped delivering frames (unplugged? if it "
                              f"never started: VIDIOC_STREAMON: No space left on device means "
                              f"the USB bus is full; use 320x240 or another USB controller)")
        return self._stampers[i](self._caps[i])

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
