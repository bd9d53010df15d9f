"""Benchmark: own SAD against cv2.StereoBM and own SGM against cv2 SGBM 3WAY, side by side.

Run with `make bench`. Each pair of matchers runs in blocks of back-to-back calls, the blocks
alternating (own, OpenCV, own, ...) in one process, both on the same grey input with the same
window and disparity range; a time is the median over blocks of the mean call time in a block,
and the figure that matters is the ratio own / OpenCV. Thread counts are set for both sides
(numba.set_num_threads, cv2.setNumThreads); the machine's load (`uptime`) is printed beside
every figure, since other work on the machine moves absolute times. The SGM rows on one
thread also give the ratio of process CPU time, which other work moves much less. Then
quality on Cones and Teddy (Middlebury v2 metric, rho 1 px) and the sub-pixel fits compared.
"""

from __future__ import annotations

import os
import platform
import statistics
import sys
import time
from pathlib import Path

import cv2
import numba
import numpy as np

from host.stereo import MatcherParams, compute_disparity, evaluate, load_scene
from host.stereo.grey import to_grey
from host.stereo.matcher import warm_up
from host.stereo.scenes import default_scene

BLOCKS = 7
CALL_MS = 300  # each block runs about this long


def load() -> str:
    return "load {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def _cpu_block(fn, calls: int) -> tuple[float, float]:
    w0, c0 = time.perf_counter(), time.process_time()
    for _ in range(calls):
        fn()
    return ((time.perf_counter() - w0) * 1000 / calls, (time.process_time() - c0) * 1000 / calls)


def side_by_side_cpu(own, ref) -> tuple[float, float, float, float]:
    """Two callables run in alternating blocks: (wall own, wall ref, CPU own, CPU ref), ms per
    call, medians over blocks (CPU: the process time). On one thread the CPU time is what the
    call would take on an idle core, so its ratio holds up when other work shares the machine."""
    own()
    ref()
    t0 = time.perf_counter()
    ref()
    calls = max(2, int(CALL_MS / max(1.0, (time.perf_counter() - t0) * 1000)))
    a, b = [], []
    for _ in range(BLOCKS):
        a.append(_cpu_block(own, calls))
        b.append(_cpu_block(ref, calls))
    med = [statistics.median(v[k] for v in x) for k in (0, 1) for x in (a, b)]
    return med[0], med[1], med[2], med[3]


def side_by_side(own, ref) -> tuple[float, float]:
    """Median block times (ms per call) of two callables run in alternating blocks."""
    return side_by_side_cpu(own, ref)[:2]


def set_threads(n: int) -> None:
    numba.set_num_threads(n)
    cv2.setNumThreads(n)


def pairs() -> list[tuple[str, np.ndarray, np.ndarray, int]]:
    out = []
    data = os.environ.get("STEREO_SERVO_DATA")
    if data and (Path(data) / "middlebury" / "cones").is_dir():
        c = load_scene(Path(data) / "middlebury" / "cones")
        out.append(("Cones", to_grey(c.left), to_grey(c.right), 64))
    moto = default_scene()
    for (w, h), nd in (((640, 480), 64), ((1280, 960), 128)):
        lr = [to_grey(cv2.resize(v, (w, h), interpolation=cv2.INTER_AREA))
              for v in (moto.left, moto.right)]
        out.append((f"Motorcycle {w}x{h}", lr[0], lr[1], nd))
    return out


def sad_vs_stereobm(window: int = 9) -> dict[tuple[str, int], float]:
    print(f"\n## own SAD (default sub-pixel) / cv2.StereoBM, grey, window {window}")
    own_ms = {}
    for name, gl, gr, nd in pairs():
        for threads in (1, 2):
            set_threads(threads)
            own = MatcherParams(matcher="sad", block_size=window, num_disparities=nd,
                                colour=False)
            warm_up(own)
            bm = cv2.StereoBM_create(nd, window)
            a, b = side_by_side(lambda: compute_disparity(gl, gr, own),  # noqa: B023
                                lambda: bm.compute(gl, gr))  # noqa: B023
            own_ms[(name, threads)] = a
            print(f"{name:<22} {gl.shape[1]}x{gl.shape[0]} nd {nd:<4} threads {threads}  "
                  f"own {a:7.2f} ms  StereoBM {b:7.2f} ms  ratio {a / b:5.2f}  ({load()})",
                  flush=True)
    big = [k for k in own_ms if k[0].endswith("1280x960")]
    if len(big) == 2:
        name = big[0][0]
        print(f"thread scaling 1 -> 2 on {name}: own "
              f"{own_ms[(name, 1)] / own_ms[(name, 2)]:.2f}x")
    return own_ms


SGBM_3WAY = MatcherParams(matcher="opencv-sgbm", mode="sgbm3way", block_size=3,
                          uniqueness_ratio=10, speckle_window_size=100, speckle_range=2,
                          lr_check=1.0, fill=True, num_disparities=64)
OWN_SGM = MatcherParams(matcher="sgm", block_size=1, lr_check=1.0, fill=True, border="clip",
                        num_disparities=64)  # default paths (5)
BEST_LOCAL = MatcherParams(matcher="ncc", block_size=5, border="clip", lr_check=1.0, fill=True,
                           median=5, num_disparities=64)


SGM_PATHS = (5, 8, 4)  # the default first


def sgm_vs_sgbm() -> None:
    print("\n## own SGM (LR 1 + fill) / cv2 SGBM 3WAY (block 3, LR 1 + fill), grey")
    for name, gl, gr, nd in pairs()[:2]:
        for threads in (1, 2):
            set_threads(threads)
            for paths in SGM_PATHS:
                own = OWN_SGM.replace(num_disparities=nd, paths=paths)
                ref = SGBM_3WAY.replace(num_disparities=nd, colour=False)
                a, b, ca, cb = side_by_side_cpu(
                    lambda: compute_disparity(gl, gr, own),  # noqa: B023
                    lambda: compute_disparity(gl, gr, ref))  # noqa: B023
                cpu = f"  CPU {ca:6.1f} / {cb:6.1f} ms ratio {ca / cb:5.2f}" if threads == 1 else ""
                print(f"{name:<22} {gl.shape[1]}x{gl.shape[0]} nd {nd:<4} threads {threads}  "
                      f"paths {paths}  own {a:7.2f} ms  SGBM 3WAY {b:7.2f} ms  "
                      f"ratio {a / b:5.2f}{cpu}  ({load()})", flush=True)


def quality(mb: Path) -> None:
    print("\n## quality, bad % at 1 px (density %), nonocc / all / disc")
    rows = [(f"own SGM {paths} paths + LR 1 + fill", OWN_SGM.replace(paths=paths))
            for paths in SGM_PATHS]
    rows += [("SGBM 3WAY colour + LR 1 + fill", SGBM_3WAY),
             ("SGBM 3WAY grey + LR 1 + fill", SGBM_3WAY.replace(colour=False)),
             ("best local: ZNCC 5 + LR + fill + median 5", BEST_LOCAL)]
    for scene_name in ("cones", "teddy"):
        s = load_scene(mb / scene_name)
        for label, p in rows:
            d = compute_disparity(s.left, s.right, p)
            cells = []
            for region in ("nonocc", "all", "disc"):
                sc = evaluate(d, s.gt, s.masks[region])
                cells.append(f"{sc.bad:6.2f} ({sc.density:5.1f})")
            print(f"{scene_name:<6} {label:<42} " + "  ".join(cells))


def flatness(disp: np.ndarray, region: np.ndarray) -> tuple[float, float]:
    """Share (%) of the fullest and the emptiest of 10 bins of the fractional part (ideal 10)."""
    d = disp[region & np.isfinite(disp)]
    hist = np.histogram(d - np.floor(d), bins=10, range=(0.0, 1.0))[0]
    share = 100.0 * hist / max(1, hist.sum())
    return float(share.max()), float(share.min())


def subpixel(mb: Path) -> None:
    print("\n## sub-pixel fits, nonocc: bad at 0.5 px / 1 px, RMS px, fractional-part bins "
          "(fullest / emptiest %, ideal 10)")
    setups = [("SAD 9 clip", MatcherParams(matcher="sad", block_size=9, border="clip",
                                           num_disparities=64)),
              ("SGM + LR + fill", OWN_SGM)]
    for scene_name in ("cones", "teddy"):
        s = load_scene(mb / scene_name)
        region = s.masks["nonocc"]
        for label, base in setups:
            for fit in ("none", "parabola", "equiangular"):
                p = base.replace(subpixel=False) if fit == "none" else base.replace(
                    subpixel_fit=fit)
                d = compute_disparity(s.left, s.right, p)
                half = evaluate(d, s.gt, region, rho=0.5)
                one = evaluate(d, s.gt, region, rho=1.0)
                hi, lo = flatness(d, region & np.isfinite(s.gt))
                print(f"{scene_name:<6} {label:<16} {fit:<12} bad0.5 {half.bad:6.2f}  "
                      f"bad1 {one.bad:6.2f}  rms {one.rms:5.3f}  bins {hi:5.1f} / {lo:4.1f}")


def main() -> int:
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"cv2 {cv2.__version__}, numba {numba.__version__}, {BLOCKS} alternating blocks")
    only = set(sys.argv[1:])
    if not only or "sad" in only:
        sad_vs_stereobm()
    if not only or "sgm" in only:
        sgm_vs_sgbm()
    set_threads(2)
    data = os.environ.get("STEREO_SERVO_DATA")
    mb = Path(data) / "middlebury" if data else None
    if mb and (mb / "cones").is_dir():
        if not only or "quality" in only:
            quality(mb)
        if not only or "subpixel" in only:
            subpixel(mb)
    else:
        print("\n(no STEREO_SERVO_DATA: Cones/Teddy figures skipped)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
