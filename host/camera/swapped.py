"""Are a pair's left and right views swapped? Both readings of the pair compared, so a correct
rig (whatever it looks at) is never called swapped.

A correct pair puts a scene point further right in the left view: its textured pixels match at
disparity >= 0, so read the other way round they match at <= 0. A pair is called swapped only
when both readings say so, each clearly: read as given, the median disparity is at or below
-MIN_PX; read with the views exchanged, at or above +MIN_PX, each over at least MIN_SHARE of the
image. A correct rig can only meet the first when half its textured pixels match more than
MIN_PX beyond infinity: a scene all at infinity seen through a calibration 3 px off, which is
a broken calibration rather than a rig. A scene too far or too plain for either reading is
inconclusive, never swapped (the simulated room's wall, 3.2 m away, is 8 px at 320x240).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from host.camera.lr_check import handedness

MIN_PX = 3.0  # each reading's median disparity is at least this far from 0 (px)
MIN_SHARE = 0.01  # each reading over at least this share of the image (textured, matched)


@dataclass(frozen=True)
class SwapVerdict:
    """given_px / back_px: median disparity (px) of the pair read as given and with its views
    exchanged; given_share / back_share: the share of the image each is taken over."""

    given_px: float
    given_share: float
    back_px: float
    back_share: float

    @property
    def conclusive(self) -> bool:
        return min(self.given_share, self.back_share) >= MIN_SHARE and (
            abs(self.given_px) >= MIN_PX or abs(self.back_px) >= MIN_PX)

    @property
    def swapped(self) -> bool:
        return self.conclusive and self.given_px <= -MIN_PX and self.back_px >= MIN_PX

    def describe(self) -> str:
        """One phrase: what the two readings found."""
        return (f"median disparity {self.given_px:+.1f} px as given, {self.back_px:+.1f} px "
                f"with left and right exchanged, over {100 * self.given_share:.0f} % of the "
                f"image")


def swap_verdict(left: np.ndarray, right: np.ndarray) -> SwapVerdict:
    """Both readings of a rectified pair (uint8 grey or BGR, the same size)."""
    given, back = handedness(left, right), handedness(right, left)
    return SwapVerdict(given.median_px, given.share, back.median_px, back.share)
