"""Own SAD's CPU time with this tree's sad.py against another tree's, and both against
cv2.StereoBM, side by side in one process (issue 24).

Usage: bench/sad_versus.py OLD_SAD_PY NEW_SAD_PY [--blocks N] [--rounds R] [--sizes WxH/ND ...]
OLD_SAD_PY is a sad.py exported from another commit (`git archive COMMIT | tar -x -C DIR`:
its own imports resolve in this tree, so block_matching.py must be the same at both), NEW_SAD_PY
a copy of this tree's (outside the tree: both are loaded from a file the same way, as
bench/sgm_versus.py does); each is loaded under its own module name and swapped in for
host.stereo.matcher's sad while it runs. On one numba and one OpenCV thread, at `bench/matcher.py
sad`'s configuration (grey Motorcycle resized, window 9, default sub-pixel, StereoBM window 9 at
the least multiple of 16 candidates), old, new and StereoBM run in alternating blocks; each time
is the median over blocks of the process CPU time a call. `--servo` adds the servo's matches
(colour, window 9, 64 candidates, 320x240; the lane window's LR check on a 120x100 crop at 32)
as new / old only. Prints per size and round new / old and each one's ratio to StereoBM, with
the load.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import cv2
import numba

import host.stereo.matcher as hm
from host.stereo import MatcherParams, compute_disparity

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from matcher import CALL_MS, SIZES, pair_params, parse_size, resized_pair  # noqa: E402
from sgm_versus import _cpu, _load  # noqa: E402  (the same timing and loading as for SGM)


def _load_avg() -> str:
    return "load " + " ".join(f"{v:.1f}" for v in os.getloadavg())


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="bench/sad_versus.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old", help="a sad.py from another commit")
    ap.add_argument("new", help="a copy of this tree's sad.py")
    ap.add_argument("--blocks", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--sizes", nargs="*", type=parse_size, default=None,
                    help="e.g. 640x480/64 (default: the bench's nine)")
    ap.add_argument("--servo", action="store_true", help="add the servo's matches (new / old)")
    a = ap.parse_args(argv)
    old, new = _load("sad_old_version", a.old), _load("sad_new_version", a.new)
    this = hm.sad
    sizes = SIZES if a.sizes is None else a.sizes
    numba.set_num_threads(1)
    cv2.setNumThreads(1)

    def run(mod, left, right, own):  # type: ignore[no-untyped-def]
        hm.sad = mod
        try:
            return compute_disparity(left, right, own)
        finally:
            hm.sad = this

    def calls_for(fn) -> int:  # type: ignore[no-untyped-def]
        fn()
        t0 = time.perf_counter()
        fn()
        return max(2, int(CALL_MS / max(1.0, (time.perf_counter() - t0) * 1000)))

    servo = MatcherParams(block_size=9, num_disparities=64)  # the servo's frame match
    for rnd in range(a.rounds):
        for w, h, nd in sizes:
            left, right = resized_pair(w, h)
            own, maker = pair_params("sad", nd)
            ref = maker(left, right)
            run(old, left, right, own)
            ref()
            calls = calls_for(lambda: run(new, left, right, own))  # noqa: B023
            t_old, t_new, t_bm = [], [], []
            for _ in range(a.blocks):
                t_old.append(_cpu(lambda: run(old, left, right, own), calls))  # noqa: B023
                t_new.append(_cpu(lambda: run(new, left, right, own), calls))  # noqa: B023
                t_bm.append(_cpu(ref, calls))
            mo, mn, mb = (statistics.median(v) for v in (t_old, t_new, t_bm))
            print(f"round {rnd + 1} {w}x{h}/{nd}: new/old {mn / mo:.2f}  old/BM {mo / mb:.2f}"
                  f"  new/BM {mn / mb:.2f}  ({mo:.2f} / {mn:.2f} / {mb:.2f} ms)  {_load_avg()}",
                  flush=True)
        if not a.servo:
            continue
        cl, cr = resized_pair(320, 240, colour=True)
        crop = (cl[100:200, 120:240], cr[100:200, 120:240])
        for label, (lv, rv), p in (("servo frame 320x240/64", (cl, cr), servo),
                                   ("lane window 120x100/32 LR", crop,
                                    servo.replace(num_disparities=32, lr_check=1.0))):
            run(old, lv, rv, p)
            calls = calls_for(lambda: run(new, lv, rv, p))  # noqa: B023
            t_old, t_new = [], []
            for _ in range(a.blocks):
                t_old.append(_cpu(lambda: run(old, lv, rv, p), calls))  # noqa: B023
                t_new.append(_cpu(lambda: run(new, lv, rv, p), calls))  # noqa: B023
            mo, mn = statistics.median(t_old), statistics.median(t_new)
            print(f"round {rnd + 1} {label}: new/old {mn / mo:.2f}  ({mo:.3f} / {mn:.3f} ms)"
                  f"  {_load_avg()}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
