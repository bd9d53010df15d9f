"""A cv2.VideoCapture stand-in that behaves like a V4L2 driver: it grants some formats and
refuses others, offers some controls and not others, and stamps frames on a given clock."""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np

AUTO_EXPOSURE_ON = 3.0


class FakeCapture:
    def __init__(self, frames: list[np.ndarray], controls: dict[int, float] | None = None,
                 fixed: dict[int, float] | None = None,
                 stamp: Callable[[int], float] | None = None) -> None:
        """frames: what grab/retrieve deliver in turn; controls: offered controls and their
        auto-chosen values; fixed: properties the driver keeps at its own value;
        stamp(i): the driver's timestamp (ms) of frame i, or None for no driver stamps."""
        h, w = frames[0].shape[:2]
        self.frames, self.i = frames, -1
        self.props: dict[int, float] = {
            cv2.CAP_PROP_FOURCC: cv2.VideoWriter_fourcc(*"YUYV"), cv2.CAP_PROP_FRAME_WIDTH: w,
            cv2.CAP_PROP_FRAME_HEIGHT: h, cv2.CAP_PROP_FPS: 30.0, cv2.CAP_PROP_BUFFERSIZE: 4.0,
            cv2.CAP_PROP_POS_MSEC: 0.0}
        self.props.update(controls or {})
        self.fixed = fixed or {}
        self.props.update(self.fixed)
        self.stamp = stamp
        self.released = False

    def get(self, prop: int) -> float:
        return float(self.props.get(prop, -1.0))

    def set(self, prop: int, value: float) -> bool:
        if prop in self.fixed or prop not in self.props and prop not in (
                cv2.CAP_PROP_FOURCC, cv2.CAP_PROP_FRAME_WIDTH, cv2.CAP_PROP_FRAME_HEIGHT):
            return False
        self.props[prop] = float(value)
        return True

    def grab(self) -> bool:
        self.i += 1
        if self.i >= len(self.frames):
            return False
        if self.stamp is not None:
            self.props[cv2.CAP_PROP_POS_MSEC] = self.stamp(self.i)
        return True

    def retrieve(self) -> tuple[bool, np.ndarray]:
        return True, self.frames[self.i]

    def release(self) -> None:
        self.released = True


def sensor_controls(exposure: float, gain: float, wb: float) -> dict[int, float]:
    """A UVC sensor on auto that offers exposure, gain and white balance."""
    return {cv2.CAP_PROP_AUTO_EXPOSURE: AUTO_EXPOSURE_ON, cv2.CAP_PROP_EXPOSURE: exposure,
            cv2.CAP_PROP_GAIN: gain, cv2.CAP_PROP_AUTO_WB: 1.0,
            cv2.CAP_PROP_WB_TEMPERATURE: wb}
