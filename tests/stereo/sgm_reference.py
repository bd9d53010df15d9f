"""The reference for sgm.match's outputs: fixed inputs, configurations, and the maps they gave.

`python -m tests.stereo.sgm_reference` writes sgm_reference.npz from the sgm.match of the
checkout it runs in; the committed file was written at commit 711cc8e (before the aggregation
was reworked for speed), so test_sgm checks that no later change moved a single disparity.
The census is computed here in numpy, not by sgm.census, so the reference holds the
aggregation (sgm.match) to its outputs whatever the cost side does.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from host.stereo import sgm

FILE = Path(__file__).with_name("sgm_reference.npz")
H, W = 60, 176  # more rows than twice sgm.OVERLAP: the 5-path stripes start warm
# (paths, dmin, nd, box, uniqueness, fit, p1, p2): box 0 = the Hamming cost straight from the
# census rows, else a box-summed cost volume; every candidate count from 16 to 100 at which the
# old code had a different speed, and both packings of the right view's minimum (p2 3000)
CONFIGS = [(paths, dmin, nd, 0, 0.0, 0, 8, 32)
           for paths in (5, 8, 4) for dmin, nd in ((0, 16), (3, 24), (0, 33), (0, 48),
                                                   (2, 56), (0, 64), (0, 65), (1, 100))]
CONFIGS += [(5, 0, 48, 3, 0.0, 0, 72, 288), (8, 0, 40, 3, 0.0, 0, 72, 288),
            (5, 0, 56, 0, 10.0, 1, 8, 32), (5, 4, 40, 0, 0.0, 2, 8, 32),
            (8, 0, 56, 0, 15.0, 1, 8, 32), (5, 0, 50, 0, 0.0, 0, 3, 3000),
            (4, 0, 30, 0, 5.0, 2, 11, 60)]


def images() -> tuple[np.ndarray, np.ndarray]:
    """A textured pair with a few depth steps (smooth noise, a slanted plane, a near box)."""
    rng = np.random.default_rng(24)
    base = rng.integers(0, 256, (H, W + 120)).astype(np.float64)
    k = np.ones(3) / 3
    base = np.apply_along_axis(lambda r: np.convolve(r, k, "same"), 1, base)
    left = np.empty((H, W))
    right = np.empty((H, W))
    for y in range(H):
        for x in range(W):
            d = 20 + x // 30 + (25 if 20 <= y < 45 and 60 <= x < 120 else 0)
            left[y, x] = base[y, x + 100]
            if x + d < W:
                right[y, x] = base[y, x + d + 100]
            else:
                right[y, x] = base[y, x + 100 - 3]
    noise = rng.normal(0, 2, (2, H, W))
    return tuple(np.clip(v + n, 0, 255).astype(np.uint8) for v, n in zip((left, right), noise))


def census(img: np.ndarray) -> np.ndarray:
    """9x7 census in numpy (replicated border), bit order as sgm.census."""
    hh, ww = sgm.CENSUS_H, sgm.CENSUS_W
    p = np.pad(img, ((hh, hh), (ww, ww)), mode="edge")
    h, w = img.shape
    centre = p[hh:hh + h, ww:ww + w]
    out = np.zeros((h, w), np.uint64)
    for dy in range(2 * hh + 1):
        for dx in range(2 * ww + 1):
            if dy == hh and dx == ww:
                continue
            bit = (p[dy:dy + h, dx:dx + w] < centre).astype(np.uint64)
            out = (out << np.uint64(1)) | bit
    return out


def box_cost(cl: np.ndarray, cr: np.ndarray, dmin: int, nd: int, box: int) -> np.ndarray:
    """Hamming cost volume (far = CENSUS_BITS where x - d leaves the image), box-summed."""
    h, w = cl.shape
    vol = np.full((h, w, nd), sgm.CENSUS_BITS, np.int64)
    for j in range(nd):
        d = dmin + j
        if d < w:
            x = np.bitwise_xor(cl[:, d:], cr[:, :w - d])
            bits = np.zeros(x.shape, np.int64)
            for b in range(64):
                bits += ((x >> np.uint64(b)) & np.uint64(1)).astype(np.int64)
            vol[:, d:, j] = bits
    r = box // 2
    p = np.pad(vol, ((r, r), (r, r), (0, 0)))
    s = np.zeros_like(vol)
    for dy in range(box):
        for dx in range(box):
            s += p[dy:dy + h, dx:dx + w]
    return s.astype(np.uint16)


def run(config, rows: bool = False, lr: float = -1.0) -> tuple[np.ndarray, np.ndarray]:
    """(left, right) maps of sgm.match for one configuration on images(); rows (census-row
    configurations only): sgm.match is given the padded grey images and makes the census rows
    itself; lr: its LR tolerance (row by row; the right map is then empty)."""
    paths, dmin, nd, box, uniq, fit, p1, p2 = config
    cl, cr = (census(v) for v in images())
    vol = box_cost(cl, cr, dmin, nd, box) if box else np.empty((0, 0, 0), np.uint16)
    sums = np.empty((H, W, nd) if paths != 5 else (0, 0, nd), np.uint16)
    crrev = sgm.reversed_right(cr, dmin, nd)
    gl, gr = sgm.NO_GREY, sgm.NO_GREY
    if rows:
        gl, gr = (np.pad(v, ((sgm.CENSUS_H,) * 2, (sgm.CENSUS_W,) * 2), mode="edge")
                  for v in images())
        cl, crrev = sgm.NO_CENSUS, sgm.NO_CENSUS
    return sgm.match(cl, crrev, vol, sums, dmin, np.uint16(p1), np.uint16(p2), paths, uniq,
                     fit, True, False, gl=gl, gr=gr, lr=lr)


def pack(disp: np.ndarray) -> np.ndarray:
    """Whole-pixel maps as uint8 (255 = NaN: a tenth of the file), fractional ones as they are."""
    if np.nanmax(disp) < 255 and np.array_equal(disp[np.isfinite(disp)],
                                                np.round(disp[np.isfinite(disp)])):
        return np.where(np.isfinite(disp), disp, 255).astype(np.uint8)
    return disp


def unpack(stored: np.ndarray) -> np.ndarray:
    if stored.dtype == np.uint8:
        return np.where(stored == 255, np.nan, stored).astype(np.float32)
    return stored


def freeze(file: Any, configs: Sequence[Any],
           run: Callable[[Any], tuple[np.ndarray, np.ndarray]],
           pack: Callable[[np.ndarray], np.ndarray]) -> int:
    """Each configuration's left and right maps, packed, into file (an .npz): the reference."""
    out = {}
    for i, config in enumerate(configs):
        left, right = run(config)
        out[f"left{i}"], out[f"right{i}"] = pack(left), pack(right)
    np.savez_compressed(file, **out)
    print(f"{file}: {len(configs)} configurations", file=sys.stderr)
    return 0


def assert_frozen(file: Any, configs: Sequence[Any],
                  run: Callable[[Any], tuple[np.ndarray, np.ndarray]], i: int) -> None:
    """Configuration i's left and right maps equal those freeze wrote into file (NaN where
    the reference has no disparity): freeze's check, for each reference module's test."""
    stored = np.load(file)
    left, right = run(configs[i])
    np.testing.assert_array_equal(left, unpack(stored[f"left{i}"]))
    np.testing.assert_array_equal(right, unpack(stored[f"right{i}"]))


def main() -> int:
    return freeze(FILE, CONFIGS, run, pack)


if __name__ == "__main__":
    sys.exit(main())
