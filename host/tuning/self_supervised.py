"""The self-supervised objective: how well a matcher's disparity explains a stereo pair, from the
pair alone (no ground truth), so a robot can tune on its own frames.

For a pair and parameters it computes the left disparity and scores five terms (each a
fraction, 0 best):
- reconstruction: the right view rebuilt from the left one by the left disparity (each left
  pixel moved to x - d; where several land on one right pixel the nearest, largest disparity
  wins); the mean three-state census (7x7, exposure-robust) distance, over the 48
  neighbours, between each visible left pixel and the right pixel it lands on;
- holes: right pixels that no left pixel lands on (up to the last one landed on in the row;
  beyond it the right view sees what the left image does not), so a map that scatters or
  fattens leaves gaps in the rebuilt view;
- hidden: left pixels that land behind a nearer one (more than 1 px nearer); a true map hides
  only the half-occluded background, while each wrong disparity that lands on a pixel of the
  true surface hides it;
- invalid: pixels with no disparity, or pointing outside the right image (a map with no
  disparity at all would otherwise rebuild nothing and pay nothing);
- roughness: disparity jumps (> 1 px) between neighbours where the image has no edge
  (weighted by exp(-|grey step| / 8)), so noise is paid for and object boundaries are free.
The score is their weighted sum in percent; lower is better. The weights were chosen on the ten
shared Middlebury scenes and tested scene by scene on a choice made without that scene
(bench/tuning.py, docs/tuning.md).
"""

from __future__ import annotations

import uuid
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit

from host.stereo.grey import to_grey
from host.stereo.matcher import compute_disparity
from host.stereo.params import MatcherParams
from host.tuning.disparity_range import apply_range

CENSUS_RADIUS = 3  # 7x7 window: 48 comparison bits
CENSUS_BITS = (2 * CENSUS_RADIUS + 1) ** 2 - 1
EDGE_SIGMA = 8.0  # grey levels


@dataclass(frozen=True)
class Weights:
    """Weights of the terms in the score (reconstruction has weight 1), chosen by the rule in
    bench/tuning.py (DESIGN_GRID, design_rule) on the ten shared Middlebury scenes: the most
    scenes whose pick is within 1.5 pt of ground-truth tuning, then the least mean gap, then
    the best rank correlation with bad %."""

    holes: float = 0.2
    hidden: float = 0.3
    invalid: float = 0.5
    roughness: float = 0.1


TERMS = ("reconstruction", "holes", "hidden", "invalid", "roughness")


@njit(cache=True)
def census(grey: np.ndarray, radius: int) -> np.ndarray:
    """Three-state census transform: for each pixel two masks, bit k set in the first where the
    k-th neighbour is darker than the centre, in the second where it is brighter (equal sets
    neither, so a flat or clipped patch does not pass for one brighter all round; pixels beyond
    the border repeat the edge)."""
    h, w = grey.shape
    out = np.zeros((h, w, 2), np.uint64)
    for y in range(h):
        for x in range(w):
            c = grey[y, x]
            darker = np.uint64(0)
            brighter = np.uint64(0)
            for dy in range(-radius, radius + 1):
                yy = min(max(y + dy, 0), h - 1)
                for dx in range(-radius, radius + 1):
                    if dy == 0 and dx == 0:
                        continue
                    xx = min(max(x + dx, 0), w - 1)
                    darker = (darker << np.uint64(1)) | np.uint64(grey[yy, xx] < c)
                    brighter = (brighter << np.uint64(1)) | np.uint64(grey[yy, xx] > c)
            out[y, x, 0] = darker
            out[y, x, 1] = brighter
    return out


@njit(cache=True)
def _popcount(v: np.uint64) -> int:
    n = 0
    while v:
        v &= v - np.uint64(1)
        n += 1
    return n


@njit(cache=True)
def _terms(disp_l: np.ndarray, cl: np.ndarray, cr: np.ndarray, grey: np.ndarray, bits: int,
           sigma: float) -> tuple[float, float, float, float, float]:
    h, w = disp_l.shape
    cost = np.full((h, w), -1.0)  # census distance of each left pixel landing in the right view
    nearest = np.full((h, w), -1.0)  # the largest disparity landing on each right pixel
    invalid = 0
    rough = 0.0
    pairs = 0
    for y in range(h):
        for x in range(w):
            d = disp_l[y, x]
            xr = int(np.floor(x - d + 0.5)) if not np.isnan(d) else -1
            if xr < 0 or xr >= w:
                invalid += 1
            else:
                cost[y, x] = _popcount((cl[y, x, 0] ^ cr[y, xr, 0])
                                       | (cl[y, x, 1] ^ cr[y, xr, 1])) / bits
                nearest[y, xr] = max(nearest[y, xr], d)
            for dy, dx in ((0, 1), (1, 0)):
                y2, x2 = y + dy, x + dx
                if y2 >= h or x2 >= w:
                    continue
                pairs += 1
                d2 = disp_l[y2, x2]
                if np.isnan(d) or np.isnan(d2) or abs(d - d2) > 1.0:
                    step = abs(float(grey[y, x]) - float(grey[y2, x2]))
                    rough += np.exp(-step / sigma)
    recon = 0.0
    visible = 0
    hidden = 0
    holes = 0
    for y in range(h):
        for x in range(w):
            if cost[y, x] >= 0:
                d = disp_l[y, x]
                if nearest[y, int(np.floor(x - d + 0.5))] > d + 1.0:
                    hidden += 1
                else:
                    recon += cost[y, x]
                    visible += 1
        last = -1
        for x in range(w - 1, -1, -1):
            if nearest[y, x] >= 0:
                last = x
                break
        for x in range(last + 1):
            if nearest[y, x] < 0:
                holes += 1
    n = h * w
    return (recon / max(visible, 1), holes / n, hidden / n, invalid / n, rough / max(pairs, 1))


class Pair:
    """A rectified pair with what every evaluation on it shares: grey images and census."""

    def __init__(self, left: np.ndarray, right: np.ndarray) -> None:
        self.left, self.right = left, right
        self.grey = to_grey(left)
        self.census_left = census(self.grey, CENSUS_RADIUS)
        self.census_right = census(to_grey(right), CENSUS_RADIUS)

    def terms(self, disp_l: np.ndarray) -> dict[str, float]:
        """The terms (fractions, 0 best) of a left disparity map (px, NaN = none)."""
        return dict(zip(TERMS, _terms(np.ascontiguousarray(disp_l, np.float32),
                                      self.census_left, self.census_right, self.grey,
                                      CENSUS_BITS, EDGE_SIGMA)))


def terms_of_maps(left: np.ndarray, right: np.ndarray, disp_l: np.ndarray) -> dict[str, float]:
    """The terms for a given left disparity map (px, NaN = none)."""
    return Pair(left, right).terms(disp_l)


def score_of(t: dict[str, float], w: Weights = Weights()) -> float:
    """The weighted sum of the terms, in percent."""
    return 100 * (t["reconstruction"] + w.holes * t["holes"] + w.hidden * t["hidden"]
                  + w.invalid * t["invalid"] + w.roughness * t["roughness"])


_PREPARED: dict[str, list[Pair]] = {}  # this process's census of each score's pairs, by key
_KEEP = 4  # scores whose census a process keeps


class SelfSupervisedScore:
    """params -> self-supervised score per pair (lower is better); picklable for any backend.

    pairs are (left, right) uint8 images; ranges their (min_disparity, num_disparities). The
    census of the pairs is made once per process, on first use, and kept under a key that
    travels with the score: worker processes and Ray tasks (which unpickle a fresh copy of the
    score for every task) share it, and it is never sent."""

    name = ("self-supervised (census reconstruction of the right view, holes, hidden, invalid, "
            "roughness)")

    def __init__(self, pairs: Sequence[tuple[np.ndarray, np.ndarray]],
                 ranges: Sequence[tuple[int, int]], weights: Weights = Weights()) -> None:
        self.pairs, self.ranges, self.weights = list(pairs), list(ranges), weights
        self.key = uuid.uuid4().hex

    def prepared(self) -> list[Pair]:
        """This process's census of the pairs (made on first use)."""
        if self.key not in _PREPARED:
            while len(_PREPARED) >= _KEEP:
                _PREPARED.pop(next(iter(_PREPARED)))
            _PREPARED[self.key] = [Pair(left, right) for left, right in self.pairs]
        return _PREPARED[self.key]

    def __call__(self, params: MatcherParams) -> list[float]:
        return [score_of(pair.terms(compute_disparity(pair.left, pair.right,
                                                      apply_range(params, r))), self.weights)
                for pair, r in zip(self.prepared(), self.ranges)]
