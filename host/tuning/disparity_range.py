"""The disparity range as a policy derived from each scene, never a tuned constant.

Policies (text form in brackets, as --range takes it and params files store it):
- ground-truth [ground-truth]: the 0.1st to 99.9th percentile of the scene's known disparities
  in its nonocc region (all known pixels when it has no mask), widened by the margin, so a few
  stray pixels do not widen the search.
- depth [depth:NEAR:FAR]: the calibration's depth range in metres, d = focal * baseline / Z.
- coarse [coarse]: a quick ZNCC pass at half size over half the image width, with a left-right
  and uniqueness check; of its confident matches (away from the border, agreeing with most of
  their 5x5 neighbours) the 0.5th to 99.5th percentile, scaled back up, widened by one coarse
  pixel and the margin.
- fixed [fixed:N]: disparities 0..N-1 (for a user who knows the rig).
A range is (min_disparity, num_disparities) in px, as MatcherParams takes them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import cv2
import numpy as np

from host.errors import HostError

if TYPE_CHECKING:
    from host.stereo.params import MatcherParams

KINDS = ("ground-truth", "depth", "coarse", "fixed")
COARSE_FACTOR = 2
COARSE_WINDOW = 7  # px at half size
COARSE_SUPPORT = 16  # of the 24 neighbours in 5x5 within 1 coarse px: not a speckle
COARSE_PERCENTILES = (0.5, 99.5)
GT_PERCENTILES = (0.1, 99.9)  # of the nonocc ground truth: loses <= 0.03 % on the ten scenes


@dataclass(frozen=True)
class RangePolicy:
    """How to find a scene's disparity range; margin_px widens it on both sides."""

    kind: str = "ground-truth"
    margin_px: float = 4.0
    near_m: float | None = None  # depth policy
    far_m: float | None = None
    num: int | None = None  # fixed policy

    @classmethod
    def parse(cls, text: str, margin_px: float = 4.0) -> RangePolicy:
        """ground-truth | coarse | depth:NEAR:FAR (m) | fixed:N (px)."""
        kind, _, rest = text.partition(":")
        try:
            if kind == "depth":
                near, far = (float(v) for v in rest.split(":"))
                return cls(kind, margin_px, near_m=near, far_m=far).check()
            if kind == "fixed":
                return cls(kind, 0.0, num=int(rest)).check()
        except ValueError:
            raise HostError(f"disparity range {text!r}: expected depth:NEAR:FAR (m) or "
                            "fixed:N (px)") from None
        if kind in ("ground-truth", "coarse") and not rest:
            return cls(kind, margin_px).check()
        raise HostError(f"unknown disparity range {text!r} (choose from ground-truth, coarse, "
                        "depth:NEAR:FAR, fixed:N)")

    def check(self) -> RangePolicy:
        if self.margin_px < 0:
            raise HostError(f"range margin must be >= 0 px, got {self.margin_px}")
        if self.kind == "depth" and not (self.near_m and self.far_m
                                         and 0 < self.near_m < self.far_m):
            raise HostError(f"depth range needs 0 < near < far, got {self.near_m}:{self.far_m}")
        if self.kind == "fixed" and not (self.num and self.num > 0):
            raise HostError(f"fixed range needs N > 0, got {self.num}")
        return self

    def __str__(self) -> str:
        if self.kind == "depth":
            return f"depth:{self.near_m:g}:{self.far_m:g}"
        if self.kind == "fixed":
            return f"fixed:{self.num}"
        return self.kind

    def to_table(self) -> dict[str, Any]:
        """What a params file stores under [disparity_range]."""
        out: dict[str, Any] = {"policy": str(self)}
        if self.kind != "fixed":
            out["margin_px"] = float(self.margin_px)
        return out

    @classmethod
    def from_table(cls, table: dict[str, Any]) -> RangePolicy:
        if "policy" not in table:
            raise HostError("[disparity_range] has no policy")
        return cls.parse(str(table["policy"]), float(table.get("margin_px", 4.0)))

    def resolve(self, left: np.ndarray, right: np.ndarray, gt: np.ndarray | None = None,
                focal_baseline: float | None = None, multiple: int = 1,
                nonocc: np.ndarray | None = None) -> tuple[int, int]:
        """(min_disparity, num_disparities) for this pair; num rounded up to `multiple`.

        gt: ground truth (px, NaN unknown) and nonocc (bool mask, optional) for ground-truth;
        focal_baseline: focal_px * baseline_m for depth."""
        if self.kind == "fixed":
            assert self.num is not None
            return 0, _round_up(self.num, multiple)
        if self.kind == "ground-truth":
            if gt is None or not np.isfinite(gt).any():
                raise HostError("the ground-truth disparity range needs a scene with ground "
                                "truth (use --range coarse)")
            lo, hi = gt_range(gt, nonocc)
        elif self.kind == "depth":
            if focal_baseline is None:
                raise HostError("the depth range needs a calibration (--calib)")
            assert self.near_m is not None and self.far_m is not None
            lo, hi = focal_baseline / self.far_m, focal_baseline / self.near_m
        else:
            lo, hi = coarse_range(left, right)
        lo = max(0, math.floor(lo - self.margin_px))
        top = math.ceil(hi + self.margin_px)
        width = left.shape[1]
        num = _round_up(max(top - lo + 1, multiple), multiple)
        if lo + num > width // 2:  # never search more than half the image
            num = max(multiple, (width // 2 - lo) // multiple * multiple)
        return lo, num


def gt_range(gt: np.ndarray, nonocc: np.ndarray | None = None) -> tuple[float, float]:
    """(low, high) px: robust percentiles of the known disparities in the nonocc region."""
    known = np.isfinite(gt)
    region = known & nonocc if nonocc is not None and (known & nonocc).any() else known
    lo, hi = np.percentile(gt[region], GT_PERCENTILES)
    return float(lo), float(hi)


def _round_up(n: int, multiple: int) -> int:
    return -(-n // multiple) * multiple


def coarse_range(left: np.ndarray, right: np.ndarray) -> tuple[float, float]:
    """(low, high) disparity in full-size px from a quick half-size ZNCC pass.

    Only confident matches count: left-right consistent, unique, inside the image by the window,
    and supported by at least COARSE_SUPPORT of their 24 neighbours (within 1 coarse px), so that
    the speckles of wrong matches, which spread over the whole search, do not widen the range;
    the matcher's border pixels (which clip to disparity 0) are left out too."""
    from host.stereo.matcher import compute_disparity
    from host.stereo.params import MatcherParams

    f = COARSE_FACTOR
    small = [cv2.resize(im, (im.shape[1] // f, im.shape[0] // f), interpolation=cv2.INTER_AREA)
             for im in (left, right)]
    h, width = small[0].shape[:2]
    p = MatcherParams(matcher="ncc", block_size=COARSE_WINDOW, num_disparities=max(4, width // 2),
                      border="clip", lr_check=1.0, uniqueness_ratio=10.0)
    disp = compute_disparity(small[0], small[1], p)
    confident = np.isfinite(disp) & (_support(disp) >= COARSE_SUPPORT)
    r = COARSE_WINDOW // 2 + 1
    confident[:r] = confident[h - r:] = False
    confident[:, :r] = confident[:, width - r:] = False
    if confident.sum() < 0.05 * disp.size:
        return 0.0, float(width // 2 * f)  # featureless: search the whole coarse range
    lo, hi = np.percentile(disp[confident], COARSE_PERCENTILES)
    return float(lo * f - f), float(hi * f + f)


def _support(disp: np.ndarray) -> np.ndarray:
    """How many of each pixel's 24 neighbours in 5x5 have a disparity within 1 px of its own."""
    h, w = disp.shape
    d = np.nan_to_num(disp, nan=-1e9)
    pad = np.pad(d, 2, constant_values=-1e9)
    count = np.zeros((h, w), np.int32)
    for dy in range(5):
        for dx in range(5):
            if dy != 2 or dx != 2:
                count += np.abs(pad[dy:dy + h, dx:dx + w] - d) <= 1.0
    return count


def apply_range(params: MatcherParams, rng: tuple[int, int]) -> MatcherParams:
    """params with the range; OpenCV's matchers get num rounded up to 16."""
    lo, num = rng
    if params.matcher.startswith("opencv"):
        num = _round_up(num, 16)
    return params.replace(min_disparity=lo, num_disparities=num)
