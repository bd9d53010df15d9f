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


REGIONS = ("nonocc", "all", "disc")  # Middlebury v2's three regions, in its table's order


def regions(gt: np.ndarray, masks: dict[str, np.ndarray]) -> dict[str, np.ndarray | None]:
    """Middlebury v2's regions of a scene as evaluate's masks (None = every pixel with known
    ground truth): nonocc and disc from their masks (absent: not scored, left out), all from
    all.png where the scene has it, else every known pixel."""
    out: dict[str, np.ndarray | None] = {}
    if "nonocc" in masks:
        out["nonocc"] = masks["nonocc"]
    out["all"] = masks.get("all")
    if "disc" in masks:
        out["disc"] = masks["disc"]
    return out


def round_submission(disp: np.ndarray, scale: float) -> np.ndarray:
    """disp as an 8-bit Middlebury v2 submission stores it: value round(d * scale) clipped to
    0..255, read back as value / scale px. A pixel with no disparity stays NaN (bad)."""
    if not (np.isfinite(scale) and scale > 0):
        raise HostError(f"ground-truth scale must be positive to round as 8 bits, got {scale}")
    out = np.clip(np.rint(disp.astype(np.float64) * scale), 0, 255) / scale
    return out.astype(np.float32)


def middlebury(disp: np.ndarray, gt: np.ndarray, masks: dict[str, np.ndarray],
               rho: float = 1.0) -> dict[str, Score]:
    """Scores over each of Middlebury v2's regions the scene has (see regions)."""
    return {name: evaluate(disp, gt, mask, rho) for name, mask in regions(gt, masks).items()}
