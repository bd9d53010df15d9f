"""Where own SGM's CPU goes at `--matcher sgm`'s defaults, piece by piece (issue 24).

Usage: bench/sgm_profile.py [--sizes WxH/ND ...] [--calls N]
On one numba and one OpenCV thread, the colour Motorcycle pair resized (bench/matcher.py's
input): the whole call (`compute_disparity`), `sgm.match` alone on the arguments the call
gives it, the 4-path pass's path from the bottom alone (`sgm._vertical`), one pass of cost
rows over the image (`sgm._cost_row` at every row), the same without the intensity term
(census rows and Hamming distances) and the census rows alone, and SGBM 3WAY; each the median
over calls of the process CPU time, with the load.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import cv2
import numba
import numpy as np
from numba import njit

import host.stereo.matcher as hm
from host.stereo import compute_disparity, sgm

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from matcher import pair_params, parse_size, resized_pair  # noqa: E402


@njit(cache=False)
def cost_pass(cl, crrev, gl, gr, vol, pl, prrev, term, dmin, nd):
    """_cost_row at every row of the image (one pass of the 4-path scheme)."""
    h, w = gl.shape[0] - 2 * sgm.CENSUS_H, gl.shape[1] - 2 * sgm.CENSUS_W
    cs = sgm._census_scratch(gl, dmin, nd)
    crow = np.empty((w, sgm.padded(nd)), dtype=np.uint16)
    s = 0
    for y in range(h):
        sgm._cost_row(cl, crrev, gl, gr, vol, pl, prrev, term, y, dmin, crow, cs)
        s += crow[y % w, 0]
    return s


@njit(cache=False)
def census_pass(gl, gr, dmin, nd):
    """The census rows of both images at every row."""
    h = gl.shape[0] - 2 * sgm.CENSUS_H
    cs = sgm._census_scratch(gl, dmin, nd)
    s = np.uint64(0)
    for y in range(h):
        sgm._census_rows(gl, gr, y, cs)
        s += cs[0][0]
    return s


def _cpu(fn, calls: int) -> float:
    t = []
    for _ in range(calls):
        c0 = time.process_time()
        fn()
        t.append((time.process_time() - c0) * 1000)
    return statistics.median(t)


def profile(w: int, h: int, nd: int, calls: int) -> None:
    """Print the rows of one size (see the module's docstring)."""
    left, right = resized_pair(w, h, colour=True)
    own, maker = pair_params("sgm", nd)
    ref = maker(left, right)
    got: dict[str, tuple] = {}
    real = sgm.match

    def spy(*args, **kw):  # type: ignore[no-untyped-def]
        got["args"], got["kw"] = args, kw
        return real(*args, **kw)

    hm.sgm.match = spy
    try:
        compute_disparity(left, right, own)
    finally:
        hm.sgm.match = real
    args, kw = got["args"], got["kw"]
    cl, crrev, vol, S, dmin = args[:5]
    pl, prrev, term = args[12], args[13], args[14]
    four, gl, gr = args[16], args[17], args[18]
    p1, p2, p2_adapt, grey = args[5], args[6], args[20], args[21]
    T = sgm.penalty_table(int(p1), int(p2), p2_adapt)
    census_only = sgm.census_term(int(term[0]))
    rows = {
        "compute_disparity": lambda: compute_disparity(left, right, own),
        "sgm.match": lambda: real(*args, **kw),
        "_vertical": lambda: sgm._vertical(cl, crrev, gl, gr, vol, pl, prrev, term, False,
                                           max(h - four.K, 0), four.K, four.ck, four.ckm,
                                           p1, T, grey, dmin),
        "cost rows (one pass)": lambda: cost_pass(cl, crrev, gl, gr, vol, pl, prrev, term,
                                                  dmin, nd),
        "cost rows, census alone": lambda: cost_pass(cl, crrev, gl, gr, vol, sgm.NO_PLANES,
                                                     sgm.NO_PLANES, census_only, dmin, nd),
        "census rows": lambda: census_pass(gl, gr, dmin, nd),
        "SGBM 3WAY": ref,
    }
    for fn in rows.values():
        fn()
    print(f"{w}x{h}/{nd}, one thread, median of {calls} calls, CPU ms:", flush=True)
    for name, fn in rows.items():
        print(f"  {name:26s} {_cpu(fn, calls):7.2f}", flush=True)
    print("  load " + " ".join(f"{v:.2f}" for v in os.getloadavg()), flush=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="bench/sgm_profile.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", nargs="*", default=["640x480/64"])
    ap.add_argument("--calls", type=int, default=7)
    a = ap.parse_args(argv)
    numba.set_num_threads(1)
    cv2.setNumThreads(1)
    for text in a.sizes:
        profile(*parse_size(text), a.calls)
    return 0


if __name__ == "__main__":
    sys.exit(main())
