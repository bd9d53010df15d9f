"""Benchmark: own SAD against cv2.StereoBM and own SGM against cv2 SGBM 3WAY, side by side.

`python bench/matcher.py --help` lists the sections. Each pair of matchers runs in blocks of
back-to-back calls, the blocks alternating (own, OpenCV, own, ...) in one process, on the same
input (the Motorcycle pair resized: grey for SAD / StereoBM; colour for own SGM at `--matcher
sgm`'s defaults, which match on colour, and SGBM 3WAY, which converts it to grey) with the same
disparity range; a time is
the median over blocks of the mean call time in a block, and the figure that matters is the
ratio own / OpenCV: as process CPU time on one thread (what the call costs a core, which other
work on the shared machine moves little) and as wall time on two threads. The load average
(`uptime`) is printed beside every row. Peak memory runs each matcher once in a fresh process.
Then quality on Cones and Teddy (Middlebury v2 metric, rho 1 px) and the sub-pixel fits.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
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
# (width, height, disparities): the sizes and candidate counts of issue 24
SIZES = [(320, 240, 32)] + [(640, 480, nd) for nd in (16, 32, 48, 56, 64, 96, 128)] + [
    (1280, 960, 128)]
MEMORY_SIZES = [(640, 480, 64), (2560, 1920, 256)]


def load() -> str:
    return "load {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def _block(fn, calls: int) -> tuple[float, float]:
    w0, c0 = time.perf_counter(), time.process_time()
    for _ in range(calls):
        fn()
    return ((time.perf_counter() - w0) * 1000 / calls, (time.process_time() - c0) * 1000 / calls)


def side_by_side_cpu(own, ref, blocks: int = BLOCKS) -> tuple[float, float, float, float]:
    """Two callables run in alternating blocks: (wall own, wall ref, CPU own, CPU ref), ms per
    call, medians over blocks (CPU: the process time). On one thread the CPU time is what the
    call would take on an idle core, so its ratio holds up when other work shares the machine."""
    own()
    ref()
    t0 = time.perf_counter()
    ref()
    calls = max(2, int(CALL_MS / max(1.0, (time.perf_counter() - t0) * 1000)))
    a, b = [], []
    for _ in range(blocks):
        a.append(_block(own, calls))
        b.append(_block(ref, calls))
    med = [statistics.median(v[k] for v in x) for k in (0, 1) for x in (a, b)]
    return med[0], med[1], med[2], med[3]


def side_by_side(own, ref) -> tuple[float, float]:
    """Median block times (ms per call) of two callables run in alternating blocks."""
    return side_by_side_cpu(own, ref)[:2]


def set_threads(n: int) -> None:
    numba.set_num_threads(n)
    cv2.setNumThreads(n)


def opencv_range(nd: int) -> int:
    """OpenCV's matchers take a multiple of 16 candidates: the least that covers nd."""
    return -(-nd // 16) * 16


def resized_pair(w: int, h: int, colour: bool = False) -> tuple[np.ndarray, np.ndarray]:
    moto = default_scene()
    views = (cv2.resize(v, (w, h), interpolation=cv2.INTER_AREA) for v in (moto.left, moto.right))
    return tuple(v if colour else to_grey(v) for v in views)


SGBM_3WAY = MatcherParams(matcher="opencv-sgbm", mode="sgbm3way", block_size=3,
                          uniqueness_ratio=10, speckle_window_size=100, speckle_range=2,
                          lr_check=1.0, fill=True, num_disparities=64)
OWN_SGM = MatcherParams.for_matcher("sgm").replace(num_disparities=64)  # `--matcher sgm`
BEST_LOCAL = MatcherParams(matcher="ncc", block_size=5, border="clip", lr_check=1.0, fill=True,
                           median=5, num_disparities=64)
SGM_PATHS = (OWN_SGM.paths, *(n for n in (4, 5, 8) if n != OWN_SGM.paths))  # default first
SAD_WINDOW = 9


def pair_params(kind: str, nd: int, paths: int = OWN_SGM.paths) -> tuple[MatcherParams, object]:
    """(own params, OpenCV callable maker) for 'sad' or 'sgm' at nd candidates."""
    if kind == "sad":
        own = MatcherParams(matcher="sad", block_size=SAD_WINDOW, num_disparities=nd,
                            colour=False)
        return own, lambda gl, gr: (lambda bm=cv2.StereoBM_create(opencv_range(nd), SAD_WINDOW):
                                    bm.compute(gl, gr))
    own = OWN_SGM.replace(num_disparities=nd, paths=paths)
    ref = SGBM_3WAY.replace(num_disparities=opencv_range(nd), colour=False)
    return own, lambda gl, gr: (lambda: compute_disparity(gl, gr, ref))


def speed(kind: str, paths: tuple[int, ...] = (OWN_SGM.paths,),
          sizes: list[tuple[int, int, int]] | None = None) -> None:
    """Rows of own / OpenCV at every size: CPU time on one thread, wall time on two."""
    other = "StereoBM" if kind == "sad" else "SGBM 3WAY"
    what = (f"own SAD (window {SAD_WINDOW}, default sub-pixel) / cv2.StereoBM" if kind == "sad"
            else "own SGM at `--matcher sgm`'s defaults / cv2 SGBM 3WAY (block 3, grey, LR 1 + "
                 "fill)")
    what += ", grey" if kind == "sad" else ", colour pair (each matcher takes what it uses)"
    print(f"\n## {what}; CPU ms on 1 thread, wall ms on 2 threads")
    for w, h, nd in SIZES if sizes is None else sizes:
        gl, gr = resized_pair(w, h, colour=kind == "sgm")
        for pth in paths:
            own, maker = pair_params(kind, nd, pth)
            warm_up(own)
            ref = maker(gl, gr)
            cells = []
            for threads in (1, 2):
                set_threads(threads)
                a, b, ca, cb = side_by_side_cpu(lambda: compute_disparity(gl, gr, own),  # noqa: B023
                                                ref)
                if threads == 1:
                    cells.append(f"1 thread CPU {ca:6.1f} / {cb:6.1f} ms = {ca / cb:4.2f}")
                else:
                    cells.append(f"2 threads wall {a:6.1f} / {b:6.1f} ms = {a / b:4.2f}")
            label = f"{w}x{h} / {nd}" + (f" ({other} {opencv_range(nd)})"
                                         if opencv_range(nd) != nd else "")
            label += f" paths {pth}" if kind == "sgm" else ""
            print(f"{label:<34} " + "   ".join(cells) + f"   ({load()})", flush=True)
    set_threads(2)


PEAK = """
import ctypes, ctypes.util, json, sys
import numpy as np
import numba
import cv2
from host.stereo import MatcherParams, compute_disparity
numba.set_num_threads(1)
cv2.setNumThreads(1)
w, h, p = int(sys.argv[1]), int(sys.argv[2]), MatcherParams(**json.loads(sys.argv[3]))
rng = np.random.default_rng(0)
small = rng.integers(0, 256, (48, 32 + p.num_disparities, 3), dtype=np.uint8)
compute_disparity(small, small, p.replace(num_disparities=16))  # load the kernels
wide = rng.integers(0, 256, (h, w + 32, 3), dtype=np.uint8)  # colour: the SGM default uses it
left, right = np.ascontiguousarray(wide[:, 32:]), np.ascontiguousarray(wide[:, :w])
# give back the heap that loading (or compiling) the kernels freed: kept (host.stereo.heap),
# it would serve the first call's arrays and hide them from RssAnon
ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6").malloc_trim(0)
print("go", flush=True)
sys.stdin.readline()
for _ in range(int(sys.argv[4])):
    compute_disparity(left, right, p)
print("done", flush=True)
sys.stdin.readline()
"""


def _anon_bytes(pid: int) -> int:
    """Anonymous resident memory of a process (file pages, which memory pressure on a shared
    machine drops and reads back, left out)."""
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("RssAnon:"):
                return int(line.split()[1]) * 1024
    raise OSError(f"no RssAnon in /proc/{pid}/status")


def peak_bytes_per_pixel(p: MatcherParams, w: int, h: int, calls: int = 3) -> float:
    """Peak anonymous memory a call adds, in bytes per pixel: a fresh process (one thread)
    runs the matcher `calls` times while this one samples its RssAnon every 0.2 ms."""
    fields = p.to_dict()
    child = subprocess.Popen([sys.executable, "-c", PEAK, str(w), str(h), json.dumps(fields),
                              str(calls)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                             text=True)
    try:
        if child.stdout.readline().strip() != "go":
            raise RuntimeError("the memory probe did not start")
        before = _anon_bytes(child.pid)
        child.stdin.write("\n")
        child.stdin.flush()
        peak = before
        os.set_blocking(child.stdout.fileno(), False)
        while not child.stdout.readline():
            peak = max(peak, _anon_bytes(child.pid))
            time.sleep(0.0002)
        child.stdin.write("\n")
        child.stdin.flush()
    finally:
        child.wait(timeout=60)
    return (peak - before) / (w * h)


def memory() -> None:
    print("\n## peak anonymous memory a call adds (one thread, fresh process, random colour "
          "pair, sampled every 0.2 ms), B / pixel; own SGM at its defaults")
    for w, h, nd in MEMORY_SIZES:
        own = peak_bytes_per_pixel(OWN_SGM.replace(num_disparities=nd), w, h)
        ref = peak_bytes_per_pixel(SGBM_3WAY.replace(num_disparities=nd, colour=False), w, h)
        sad = peak_bytes_per_pixel(MatcherParams(matcher="sad", block_size=SAD_WINDOW,
                                                 num_disparities=nd, colour=False), w, h)
        print(f"{w}x{h} / {nd}: own SGM {own:5.1f}  SGBM 3WAY {ref:5.1f}  ratio {own / ref:4.2f}"
              f"   own SAD {sad:5.1f}   ({load()})", flush=True)


def quality(mb: Path) -> None:
    print("\n## quality, bad % at 1 px (density %), nonocc / all / disc")
    rows = [(f"own SGM defaults, {paths} paths", OWN_SGM.replace(paths=paths))
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
                # own SGM's defaults leave the fit off (subpixel False): a fit's row turns it on
                p = base.replace(subpixel=False) if fit == "none" else base.replace(
                    subpixel=True, subpixel_fit=fit)
                d = compute_disparity(s.left, s.right, p)
                half = evaluate(d, s.gt, region, rho=0.5)
                one = evaluate(d, s.gt, region, rho=1.0)
                hi, lo = flatness(d, region & np.isfinite(s.gt))
                print(f"{scene_name:<6} {label:<16} {fit:<12} bad0.5 {half.bad:6.2f}  "
                      f"bad1 {one.bad:6.2f}  rms {one.rms:5.3f}  bins {hi:5.1f} / {lo:4.1f}")


SECTIONS = {"sad": "own SAD / StereoBM at every size",
            "sgm": "own SGM at its defaults / SGBM 3WAY at every size",
            "paths": "own SGM's defaults with 4, 5 and 8 paths / SGBM 3WAY at every size",
            "memory": "peak memory per pixel of own SGM, SGBM 3WAY and own SAD",
            "quality": "bad % on Cones and Teddy (needs STEREO_SERVO_DATA)",
            "subpixel": "the sub-pixel fits on Cones and Teddy (needs STEREO_SERVO_DATA)"}
DEFAULT = ("sad", "sgm", "memory", "quality", "subpixel")


def parse(argv: list[str]) -> argparse.Namespace:
    sizes = ", ".join(f"{w}x{h}/{nd}" for w, h, nd in SIZES)
    ap = argparse.ArgumentParser(
        prog="bench/matcher.py", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Own matchers against OpenCV's, in alternating blocks in one process: "
                    "the ratio own / OpenCV as CPU time on one thread and wall time on two, "
                    f"at {sizes} (OpenCV takes a multiple of 16 candidates: 56 runs it at 64).",
        epilog="sections:\n" + "\n".join(f"  {k:<9} {v}" for k, v in SECTIONS.items())
               + f"\nwith none named: {' '.join(DEFAULT)}")
    ap.add_argument("sections", nargs="*", metavar="SECTION",
                    help="which to run (see below); default all but 'paths'")
    ap.add_argument("--blocks", type=int, default=BLOCKS,
                    help=f"alternating blocks per ratio, median taken (default {BLOCKS})")
    ap.add_argument("--size", dest="sizes", action="append", metavar="WxH/ND", default=None,
                    help="the speed sections at this size only, e.g. 640x480/96; repeat for "
                         "more (default: the nine above)")
    args = ap.parse_args(argv)
    unknown = [v for v in args.sections if v not in SECTIONS]
    if unknown:
        ap.error(f"unknown section {unknown[0]!r} (choose from {', '.join(SECTIONS)})")
    if args.blocks < 1:
        ap.error(f"--blocks must be at least 1, got {args.blocks}")
    if args.sizes is not None:
        try:
            args.sizes = [parse_size(v) for v in args.sizes]
        except ValueError:
            ap.error(f"--size takes WxH/ND (e.g. 640x480/64), got {' '.join(args.sizes)}")
    return args


def parse_size(text: str) -> tuple[int, int, int]:
    """'640x480/64' -> (640, 480, 64); ValueError unless all three are positive."""
    wh, nd = text.split("/")
    w, h = wh.split("x")
    out = (int(w), int(h), int(nd))
    if min(out) < 1:
        raise ValueError(text)
    return out


def main(argv: list[str] | None = None) -> int:
    args = parse(sys.argv[1:] if argv is None else argv)
    global BLOCKS
    BLOCKS = args.blocks
    only = set(args.sections) or set(DEFAULT)
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"cv2 {cv2.__version__}, numba {numba.__version__}, {BLOCKS} alternating blocks, "
          f"{load()}")
    if "sad" in only:
        speed("sad", sizes=args.sizes)
    if "sgm" in only:
        speed("sgm", sizes=args.sizes)
    if "paths" in only:
        speed("sgm", SGM_PATHS, sizes=args.sizes)
    if "memory" in only:
        memory()
    set_threads(2)
    data = os.environ.get("STEREO_SERVO_DATA")
    mb = Path(data) / "middlebury" if data else None
    if mb and (mb / "cones").is_dir():
        if "quality" in only:
            quality(mb)
        if "subpixel" in only:
            subpixel(mb)
    elif only & {"quality", "subpixel"}:
        print("\n(no STEREO_SERVO_DATA: Cones/Teddy figures skipped)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
