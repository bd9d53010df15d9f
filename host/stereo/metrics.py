"""The paper's metrics (eqs. 4 and 5): bad-pixel rate, RMS error and density over a region."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from host.errors import HostError


@dataclass(frozen=True)
class Score:
    """bad and density in percent of the region; rms in px over pixels valid in both maps.

    n is the region's pixel count. rms is NaN when no pixel is valid in both maps.
    """

    bad: float
    density: float
    rms: float
    n: int


def evaluate(disp: np.ndarray, gt: np.ndarray, mask: np.ndarray | None = None,
             rho: float = 1.0) -> Score:
    """Score a disparity map (px, NaN = none) against ground truth (px, NaN = unknown).

    The region is every pixel with known ground truth, intersected with mask when given. A
    pixel of the region with no computed disparity counts as bad (Middlebury v2 convention).
    """
    if disp.shape != gt.shape:
        raise HostError(f"disparity {disp.shape[1]}x{disp.shape[0]} and ground truth "
                        f"{gt.shape[1]}x{gt.shape[0]} differ in size")
    region = np.isfinite(gt)
    if mask is not None:
        if mask.shape != gt.shape:
            raise HostError("mask and ground truth differ in size")
        region &= mask.astype(bool)
    n = int(region.sum())
    if n == 0:
        return Score(bad=float("nan"), density=float("nan"), rms=float("nan"), n=0)
    d = disp[region].astype(np.float64)
    g = gt[region].astype(np.float64)
    has = np.isfinite(d)
    err = np.abs(d[has] - g[has])
    bad = (n - has.sum() + (err > rho).sum()) / n
    rms = float(np.sqrt(np.mean(err * err))) if err.size else float("nan")
    return Score(bad=100.0 * float(bad), density=100.0 * float(has.mean()), rms=rms, n=n)
