"""Benchmark: the own SAD matcher against cv2.StereoBM, side by side, plus the best pipeline.

Run with `make bench`. Each side runs in blocks of back-to-back calls, the blocks alternating
(own, StereoBM, own, ...) in one process; a time is the median over blocks of the mean call
time in a block. The figure that matters is the ratio own / StereoBM with the same window and
disparity range, both on grey input.
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from pathlib import Path

import cv2
import numpy as np

from host.stereo import MatcherParams, compute_disparity, evaluate, load_scene
from host.stereo.grey import to_grey
from host.stereo.matcher import warm_up
from host.stereo.scenes import default_scene

BLOCKS = 7
CALLS = 10


def _block(fn) -> float:
    t0 = time.perf_counter()
    for _ in range(CALLS):
        fn()
    return (time.perf_counter() - t0) * 1000 / CALLS


def ratio(name: str, left: np.ndarray, right: np.ndarray, window: int, nd: int) -> None:
    gl, gr = to_grey(left), to_grey(right)
    own = MatcherParams(matcher="sad", block_size=window, num_disparities=nd, colour=False)
    bm = cv2.StereoBM_create(nd, window)
    warm_up(own)
    compute_disparity(gl, gr, own)
    bm.compute(gl, gr)
    t_own, t_bm = [], []
    for _ in range(BLOCKS):
        t_own.append(_block(lambda: compute_disparity(gl, gr, own)))
        t_bm.append(_block(lambda: bm.compute(gl, gr)))
    a, b = statistics.median(t_own), statistics.median(t_bm)
    print(f"{name:<28} {gl.shape[1]}x{gl.shape[0]} w={window:<3} nd={nd:<4} "
          f"own SAD+subpixel {a:7.2f} ms   StereoBM {b:7.2f} ms   ratio {a / b:5.2f}")


BEST = MatcherParams(matcher="ncc", block_size=5, border="clip", lr_check=1.0, fill=True,
                     median=5)


def main() -> int:
    data = os.environ.get("STEREO_SERVO_DATA")
    mb = Path(data) / "middlebury" if data else None
    print(f"cv2 {cv2.__version__}, threads {cv2.getNumThreads()}, {BLOCKS} blocks of {CALLS}")
    if mb and mb.is_dir():
        cones = load_scene(mb / "cones")
        for w in (5, 9, 15, 21):
            ratio("cones", cones.left, cones.right, w, 64)
    moto = default_scene()
    l640 = cv2.resize(moto.left, (640, 480), interpolation=cv2.INTER_AREA)
    r640 = cv2.resize(moto.right, (640, 480), interpolation=cv2.INTER_AREA)
    for w in (5, 9, 15, 21):
        ratio("motorcycle resized", l640, r640, w, 64)
    if mb and mb.is_dir():
        print("\nbest local pipeline:", BEST.matcher, f"window {BEST.block_size}",
              f"lr {BEST.lr_check}", "fill", f"median {BEST.median}", f"border {BEST.border}")
        for scene in ("cones", "teddy"):
            s = load_scene(mb / scene)
            d = compute_disparity(s.left, s.right, BEST.replace(num_disparities=64))
            for region in ("nonocc", "all", "disc"):
                sc = evaluate(d, s.gt, s.masks[region])
                print(f"  {scene:<6} {region:<7} bad {sc.bad:6.2f}%  density {sc.density:6.2f}%")
    else:
        print("\n(no STEREO_SERVO_DATA: Cones/Teddy figures skipped)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
