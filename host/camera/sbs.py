"""Side-by-side stereo cameras: one UVC device whose every frame holds the left view in its
left half and the right view in its right half (e.g. 2560x720 = two 1280x720 views), usually
MJPEG because two raw views exceed USB 2.0. Both views share one exposure and one timestamp.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from host.camera import live
from host.camera.controls import Format, request
from host.camera.discovery import resolve
from host.camera.live import LiveSource, OpenCapture
from host.camera.source import CameraError, StereoFrame


def split(frame: Any) -> tuple[Any, Any]:
    """The left and right halves of a side-by-side frame."""
    w = frame.shape[1]
    if w % 2:
        raise CameraError(f"a side-by-side frame {w} px wide cannot be split in two halves")
    return (np.ascontiguousarray(frame[:, :w // 2]),
            np.ascontiguousarray(frame[:, w // 2:]))


class SideBySideSource(LiveSource):
    """Pairs from a side-by-side camera; size is that of each view (the frame is twice as
    wide); device or spec (sbs, sbs:PORT, sbs:/dev/videoN) names the camera."""

    kind = "sbs"

    def __init__(self, size: tuple[int, int] = (320, 240), spec: str = "sbs",
                 swap: bool = False, fps: float | None = None, fourcc: str = "MJPG",
                 open_capture: OpenCapture | None = None, lock: bool = True,
                 settle_frames: int = 15, stamps: str = "auto") -> None:
        camera = resolve(spec)
        w, h = size
        if camera.modes:
            offered = [m for m in camera.modes if (m.width, m.height) == (2 * w, h)]
            if not offered:
                views = ", ".join(sorted({f"{m.width // 2}x{m.height}" for m in camera.modes}))
                raise CameraError(f"{spec} offers views of {views}, not {w}x{h} (--size is the "
                                  f"size of one view)")
            mjpeg = [m for m in offered if m.fourcc == fourcc] or offered
            fourcc = mjpeg[0].fourcc
            fps = fps or mjpeg[0].max_fps
        self.spec, self.devices, self.swapped = spec, camera.nodes, swap
        caps = self._caps = live.open_all(camera.nodes, open_capture)
        asked = Format(fourcc, 2 * w, h, fps or 30.0, 1)
        try:
            request(caps[0], asked)
            self._start(caps, asked, lock, settle_frames, stamps)
        except BaseException:
            self.close()
            raise

    def swap_views(self) -> None:
        self.swapped = not self.swapped

    def _read(self) -> StereoFrame | None:
        cap = self._caps[0]
        if not cap.grab():
            raise CameraError(f"{self.devices[0]} stopped delivering frames (unplugged?)")
        t = self._stampers[0](cap)
        ok, img = cap.retrieve()
        if not ok or img is None:
            raise CameraError(f"{self.devices[0]} gave no image")
        left, right = split(img)
        if self.swapped:
            left, right = right, left
        return StereoFrame(left, right, t, t)
