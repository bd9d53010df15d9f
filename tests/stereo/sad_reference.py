"""The reference for sad.match_sad's outputs: fixed inputs, configurations, and the maps they gave.

`python -m tests.stereo.sad_reference` writes sad_reference.npz from the sad.match_sad of the
checkout it runs in; the committed file was written at commit 85cf046 (before the SAD kernel was
reworked for speed), so test_block_matching checks that no later change moved a single
disparity, on both maps, at every lane type, border rule, fit and candidate count below.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from host.stereo import sad
from tests.stereo import sgm_reference

FILE = Path(__file__).with_name("sad_reference.npz")
ROWS = 40  # of sgm_reference's 60; its 176 columns hold 128 candidates and several tiles
# (channels, dmin, nd, window, clip, uniqueness, fit, lr, bands): candidate counts around the
# vector widths (16, 17, 33, 65, 100, 128), grey and colour in uint16 and int32 lanes (grey
# window 17 and colour window 11 overflow uint16), one band of rows and three; whole-pixel
# maps where a fit would only make the file larger
CONFIGS = [(1, dmin, nd, 9, clip, 0.0, 0 if clip else 1, False, 1)
           for dmin, nd in ((0, 16), (0, 17), (3, 24), (0, 33), (0, 48), (2, 56), (0, 64),
                            (0, 65), (1, 100), (0, 128))
           for clip in (False, True)]
CONFIGS += [(1, 0, 32, 3, False, 0.0, 0, False, 1), (1, 0, 40, 5, True, 0.0, 2, True, 1),
            (1, 0, 48, 15, False, 0.0, 1, False, 3), (1, 0, 48, 17, False, 0.0, 1, True, 1),
            (1, 0, 24, 17, True, 0.0, 2, False, 3), (3, 0, 48, 9, False, 0.0, 1, False, 1),
            (3, 0, 40, 9, True, 0.0, 1, True, 3), (3, 0, 64, 11, False, 0.0, 1, False, 1),
            (3, 4, 31, 11, True, 0.0, 2, True, 1), (1, 0, 64, 9, False, 10.0, 1, False, 1),
            (1, 0, 56, 7, True, 15.0, 1, True, 3), (3, 0, 32, 5, False, 5.0, 0, True, 1),
            (1, 0, 64, 9, False, 0.0, 1, True, 3), (1, 5, 128, 9, True, 0.0, 1, True, 1)]


def images(channels: int) -> tuple[np.ndarray, np.ndarray]:
    """(left, right) uint8 (channels, rows, cols): the top ROWS of sgm_reference's textured pair
    with depth steps; colour adds two more planes, the pair scaled and shifted by fixed noise."""
    left, right = (v[:ROWS] for v in sgm_reference.images())
    if channels == 1:
        return left[None], right[None]
    rng = np.random.default_rng(3)
    planes = []
    for v in (left, right):
        more = [np.clip(v * s + rng.normal(0, 3, v.shape), 0, 255).astype(np.uint8)
                for s in (0.7, 1.2)]
        planes.append(np.stack([v, *more]))
    return planes[0], planes[1]


def run(config) -> tuple[np.ndarray, np.ndarray]:
    """(left, right) maps of sad.match_sad for one configuration on images()."""
    channels, dmin, nd, window, clip, uniq, fit, lr, bands = config
    left, right = images(channels)
    cdt, wdt = sad.lane_types(channels, window)
    return sad.match_sad(left, right, dmin, nd, window // 2, uniq, fit, lr, clip,
                         np.empty(0, cdt), np.empty(0, wdt), np.iinfo(wdt).max, bands)


def pack(disp: np.ndarray) -> np.ndarray:
    """sgm_reference.pack, and a map without a disparity (the right one without LR) as bytes."""
    if not np.isfinite(disp).any():
        return np.full(disp.shape, 255, np.uint8)
    return sgm_reference.pack(disp)


def main() -> int:
    return sgm_reference.freeze(FILE, CONFIGS, run, pack)


if __name__ == "__main__":
    sys.exit(main())
