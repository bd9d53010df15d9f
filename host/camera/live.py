"""What the live cameras (Minoru, side-by-side) share: opening V4L2 nodes, asking for a mode
and reading back what was granted, locking the controls, stamping frames, and describing all
that for a capture's manifest."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import cv2

from host.camera.controls import Format, check_granted, lock_controls
from host.camera.source import CameraError, StereoSource
from host.camera.stamps import Stamper

OpenCapture = Callable[[str], Any]


def open_v4l2(device: str) -> Any:
    cap = cv2.VideoCapture(device, cv2.CAP_V4L2)
    if not cap.isOpened():
        raise CameraError(f"cannot open {device} (is it plugged in, and are you in the video "
                          f"group?)")
    return cap


def open_all(devices: tuple[str, ...], open_capture: OpenCapture | None) -> list[Any]:
    """Open every device, or none: the ones already open are released if one fails."""
    caps: list[Any] = []
    try:
        for d in devices:
            caps.append((open_capture or open_v4l2)(d))
    except BaseException:
        for cap in caps:
            cap.release()
        raise
    return caps


class LiveSource(StereoSource):
    """A source that streams from V4L2 captures; subclasses set kind, spec and _read."""

    kind = "live"
    spec = ""
    devices: tuple[str, ...] = ()
    swapped = False

    def _start(self, caps: list[Any], asked: Format, lock: bool, settle_frames: int,
               stamps: str) -> None:
        """After request(): check the grant, let auto exposure settle, lock, set stampers."""
        self._caps = caps
        self._stampers = [Stamper(stamps) for _ in caps]
        self.asked = asked
        self.granted = [check_granted(d, c, asked) for d, c in zip(self.devices, caps)]
        self.locked: dict[str, float] = {}
        if lock:
            for _ in range(settle_frames):
                for cap in caps:
                    cap.grab()
            self.locked = lock_controls(caps, list(self.devices))

    @property
    def stamps(self) -> list[str]:
        """Per capture: driver or grab (None until the first frame decided it)."""
        return [s.kind or "undecided" for s in self._stampers]

    def describe(self) -> dict[str, Any]:
        """Camera, devices, mode asked and granted, locked controls, timestamp kind."""
        return {"camera": self.spec, "kind": self.kind, "devices": list(self.devices),
                "asked": str(self.asked), "granted": [str(g) for g in self.granted],
                "locked": self.locked, "timestamps": self.stamps,
                "swapped": self.swapped}

    def swap_views(self) -> None:
        """Exchange left and right from the next pair on (each camera kind does it its way)."""
        raise NotImplementedError

    def close(self) -> None:
        for cap in self._caps:
            cap.release()
