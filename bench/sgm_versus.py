"""Own SGM's CPU time with this tree's sgm.py against another tree's, side by side (issue 24).

Usage: bench/sgm_versus.py OLD_SGM_PY NEW_SGM_PY [--blocks N] [--rounds R] [--sizes WxH/ND ...]
OLD_SGM_PY is an sgm.py exported from another commit (`git archive COMMIT
host/stereo/sgm.py | tar -x -C DIR`), NEW_SGM_PY a copy of this tree's (outside the tree: a
module loaded from a file runs ~10 % apart from the imported one, seen old = new at
640x480/64, so both are loaded the same way); each is loaded under its own module name and
swapped in for host.stereo.matcher's sgm while it runs, so both run the same pre- and
post-processing. On one numba and one OpenCV thread, at `--matcher sgm`'s defaults on
the colour Motorcycle pair resized (bench/matcher.py's input), old, new and SGBM 3WAY run
in alternating blocks in one process; each time is the median over blocks of the process CPU
time a call. Prints per size and round new / old and each one's ratio to SGBM, with the load.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import statistics
import sys
import time

import cv2
import numba

import host.stereo.matcher as hm
from host.stereo import compute_disparity

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from matcher import CALL_MS, OWN_SGM, SIZES, pair_params, resized_pair  # noqa: E402


def _cpu(fn, calls: int) -> float:
    c0 = time.process_time()
    for _ in range(calls):
        fn()
    return (time.process_time() - c0) * 1000 / calls


def _load(name: str, path: str):  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod  # numba's cache rebuilds a kernel's environment by module name
    spec.loader.exec_module(mod)
    return mod


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="bench/sgm_versus.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old", help="an sgm.py from another commit")
    ap.add_argument("new", help="a copy of this tree's sgm.py")
    ap.add_argument("--blocks", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--sizes", nargs="*", default=None, help="e.g. 640x480/64 (default: the "
                    "bench's nine)")
    a = ap.parse_args(argv)
    old, new = _load("sgm_old_version", a.old), _load("sgm_new_version", a.new)
    this = hm.sgm
    sizes = SIZES if a.sizes is None else [
        (int(s.split("x")[0]), int(s.split("x")[1].split("/")[0]), int(s.split("/")[1]))
        for s in a.sizes]
    numba.set_num_threads(1)
    cv2.setNumThreads(1)
    for rnd in range(a.rounds):
        for w, h, nd in sizes:
            left, right = resized_pair(w, h, colour=True)
            own, maker = pair_params("sgm", nd, OWN_SGM.paths)
            ref = maker(left, right)

            def run(mod, left=left, right=right, own=own):  # type: ignore[no-untyped-def]
                hm.sgm = mod
                try:
                    return compute_disparity(left, right, own)
                finally:
                    hm.sgm = this

            run(old)
            run(new)
            ref()
            t0 = time.perf_counter()
            run(new)
            calls = max(2, int(CALL_MS / max(1.0, (time.perf_counter() - t0) * 1000)))
            t_old, t_new, t_cv = [], [], []
            for _ in range(a.blocks):
                t_old.append(_cpu(lambda: run(old), calls))
                t_new.append(_cpu(lambda: run(new), calls))
                t_cv.append(_cpu(ref, calls))
            mo, mn, mc = (statistics.median(v) for v in (t_old, t_new, t_cv))
            print(f"round {rnd + 1} {w}x{h}/{nd}: new/old {mn / mo:.2f}  old/SGBM {mo / mc:.2f}"
                  f"  new/SGBM {mn / mc:.2f}  ({mo:.1f} / {mn:.1f} / {mc:.1f} ms)  load "
                  + " ".join(f"{v:.1f}" for v in os.getloadavg()), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
