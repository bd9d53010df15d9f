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
    from the phase correlation of the two whole images under a Hann window."""
    grey = to_grey(left).astype(np.float32)
    window = cv2.createHanningWindow(grey.shape[::-1], cv2.CV_32F)
    (_, dy), _ = cv2.phaseCorrelate(reference, grey, window)
    return float(dy)
