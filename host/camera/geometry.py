"""Rectified stereo geometry (Z = f B / d) and the Minoru's nominal one, the single source of
its focal length and baseline."""

from __future__ import annotations

from dataclasses import dataclass

MINORU_FOCAL_PX_320 = 426.0  # Minoru sensor at 320x240, without a calibration
MINORU_BASELINE_M = 0.060


@dataclass(frozen=True)
class Geometry:
    """Rectified stereo geometry: Z = focal_px * baseline_m / disparity_px."""

    focal_px: float
    baseline_m: float
    cx: float
    cy: float

    def depth_m(self, disparity_px: float) -> float:
        return self.focal_px * self.baseline_m / disparity_px

    def disparity_px(self, depth_m: float) -> float:
        return self.focal_px * self.baseline_m / depth_m

    @classmethod
    def minoru_default(cls, width: int, height: int) -> Geometry:
        """The Minoru's nominal geometry at width x height px (focal length scaled from 320 px
        wide, principal point at the centre); says nothing (callers tell the user)."""
        return cls(MINORU_FOCAL_PX_320 * (width / 320.0), MINORU_BASELINE_M, width / 2,
                   height / 2)
