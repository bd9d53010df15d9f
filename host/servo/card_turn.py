"""The card's signed turn from its two views (issue 23, branch sign).

The card's aspect (width / height, `Blob.aspect`) says how far the body is turned, never which
way. The two views can: a card turned by theta has its edges at depths z -/+ w sin(theta) / 2,
and the nearer edge the larger disparity. With the disc's left and right edges at columns
xl1, xl2 in the left view and xr1, xr2 in the right one, the disparity across the disc is

    (xl2 - xr2) - (xl1 - xr1) = width_left - width_right,

positive when the edge toward +x (the image's right) is the nearer one, which is the robot's
heading theta > 0 in the world's frame (host/sim/world.py: theta positive turns toward +x; the
card across the body's heading at (cos theta, -sin theta) in (x, z)). It does not depend on the
line of sight's bearing: only the edges' depths differ.

The widths are read from the disc's coverage (darkness between the ring's and the disc's grey,
summed inside the ring): both views' rows are the same (rectified), so the coverages'
ratio is the widths' ratio, with sub-pixel resolution from every pixel of the disc.

A pure function; what it is worth (its noise, its sign's error rate against the world's truth
by |theta| and depth) is measured by tools/trace_card_turn.py (docs/servo.md, "sign").
"""

from __future__ import annotations

import math

import numpy as np

from host.servo.marker import RING_RATIO, Blob, MarkerPair


def coverage(grey: np.ndarray, blob: Blob, ring: float = RING_RATIO) -> float:
    """The disc's dark area (px^2) in one view: sum over the ellipse of 1.35 disc radii
    (semi-axes 1.35 radius aspect across, 1.35 radius down: inside the printed ring, which
    reaches `ring` radii) of (light - grey) / (light - dark), clipped to 0..1, light the median
    grey between 1.2 and 1.35 radii (the ring's inner part) and dark the 5th percentile inside
    (the disc). NaN if the ellipse leaves the image or the card shows no contrast."""
    h, w = grey.shape[:2]
    reach = min(1.35, 0.5 + ring / 2)
    ry = blob.radius
    rx = blob.radius * max(blob.aspect, 0.05)
    x0, x1 = int(math.floor(blob.u - reach * rx)) - 1, int(math.ceil(blob.u + reach * rx)) + 2
    y0, y1 = int(math.floor(blob.v - reach * ry)) - 1, int(math.ceil(blob.v + reach * ry)) + 2
    if x0 < 0 or y0 < 0 or x1 > w or y1 > h:
        return math.nan
    patch = np.asarray(grey[y0:y1, x0:x1], dtype=np.float64)
    ys, xs = np.mgrid[y0:y1, x0:x1]
    q = ((xs - blob.u) / rx) ** 2 + ((ys - blob.v) / ry) ** 2
    inside = q <= reach ** 2
    band = inside & (q >= (reach - 0.15) ** 2)
    if not band.any():
        return math.nan
    light = float(np.median(patch[band]))
    dark = float(np.percentile(patch[inside], 5))
    if light - dark < 20:
        return math.nan
    cov = np.clip((light - patch[inside]) / (light - dark), 0.0, 1.0)
    return float(cov.sum())


def across_px(left: np.ndarray, right: np.ndarray, pair: MarkerPair,
              ring: float = RING_RATIO) -> float:
    """The disparity across the disc, px: its right edge's minus its left edge's (positive:
    the card's +x edge nearer, the body turned toward +x), from the two views' coverages
    (width_left - width_right, each width 2 radius aspect scaled by its view's coverage over
    their mean). NaN if either view's coverage is not read."""
    a = coverage(_grey(left), pair.left, ring)
    b = coverage(_grey(right), pair.right, ring)
    if not (math.isfinite(a) and math.isfinite(b)) or a + b <= 0:
        return math.nan
    width = 2 * pair.left.radius * pair.left.aspect  # the disc's mean width, px
    return width * (a - b) / ((a + b) / 2)


def from_square(theta: float) -> float:
    """The card's signed turn from square to the camera axis, rad in (-pi/2, pi/2], for a body
    heading theta (world frame; the card across the body, two-sided): the sign is the one
    across_px reads (its +x edge nearer when positive), whichever way the body faces."""
    return math.atan(math.tan(theta))


def expected_px(turn_rad: float, depth_m: float, disparity_px: float, radius_m: float) -> float:
    """The disparity across a disc of radius_m turned by turn_rad at depth_m seen at
    disparity_px (d = f B / z): d(z - R sin) - d(z + R sin) ~ d 2 R sin(turn) / z."""
    return disparity_px * 2 * radius_m * math.sin(turn_rad) / depth_m


def _grey(image: np.ndarray) -> np.ndarray:
    if image.ndim == 3:
        grey: np.ndarray = np.asarray(image, dtype=np.float64).mean(axis=2)
        return grey
    return image
