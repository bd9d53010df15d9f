"""Whether the camera rig moved since the reference: the left image's vertical shift against the
reference phase's, by phase correlation (a pitch of a moves the whole picture by f tan a rows;
an object put down or a person walking through covers only part of it)."""

from __future__ import annotations

import cv2
import numpy as np

from host.stereo.grey import to_grey


def reference_image(left: np.ndarray) -> np.ndarray:
    """The reference phase's left image as the comparison needs it (grey, float32)."""
    return to_grey(left).astype(np.float32)


def vertical_shift_px(reference: np.ndarray, left: np.ndarray) -> float:
    """How many rows (px, positive: down) the picture moved since reference (reference_image),
    from the phase correlation of the two whole images under a Hann window. The reference is
    left as it was: OpenCV's phaseCorrelate multiplies its inputs by the window in place, so it
    is given a copy (else every call darkens the reference's edges by the window again, and
    after a few the target's picture near an edge is gone: rereference.target_shift_rows)."""
    grey = to_grey(left).astype(np.float32)
    window = cv2.createHanningWindow(grey.shape[::-1], cv2.CV_32F)
    (_, dy), _ = cv2.phaseCorrelate(reference.copy(), grey, window)
    return float(dy)
