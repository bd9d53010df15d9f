"""Compile every numba kernel signature users hit into numba's cache (run at installation).

`python -m host.warm` (the Makefile's venv step runs it) calls each own matcher on a small
random pair with every lane width, channel count and option that selects a different compiled
signature, the self-supervised tuner's census and terms (host tune --objective self), and the
simulated servo's renderer and marker search, so the first `host eval`, `host tune` or `host
servo --sim` loads machine code instead of compiling it. The jobs are
shared among `--processes` processes (default: one per core, at most 2): compiling is
single-threaded, and the two 4-path SGM signatures alone take most of the time. It sits above
host.stereo and host.tuning, whose kernels it compiles.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import numpy as np

from host.stereo.matcher import compute_disparity
from host.stereo.params import MatcherParams
from host.tuning.self_supervised import terms_of_maps


def variants() -> list[MatcherParams]:
    """Parameter sets covering the compiled signatures (lane types, LR check, box sums). The
    two slowest to compile come first, so that two processes (part 0 and 1, every other
    variant) each take one of them."""
    sgm = MatcherParams.for_matcher("sgm")
    # SGM: the defaults (4 paths, costs and P2 within a byte: 1-byte stored rows), then
    # 4 paths with a window over 1 (box-summed costs over a byte: 2-byte stored rows, as
    # P2 or the intensity weight raised far enough give too), then 5 paths with the LR check
    out = [sgm, sgm.replace(block_size=3),
           MatcherParams(matcher="sgm", block_size=1, lr_check=1.0, fill=True),
           MatcherParams(matcher="sgm", block_size=3, uniqueness_ratio=10)]
    # SAD lanes: (uint16, uint16), (uint16, int32) and (int32, int32) column/window sums
    for colour, window in [(False, 5), (False, 21), (True, 9), (True, 15), (True, 87)]:
        out.append(MatcherParams(matcher="sad", block_size=window, colour=colour))
    out += [MatcherParams(matcher="sad", lr_check=1.0, uniqueness_ratio=10, fill=True, median=5,
                          border="clip"),
            MatcherParams(matcher="ssd", lr_check=1.0),
            MatcherParams(matcher="ncc", block_size=5, lr_check=1.0, border="clip"),
            # grey: the census + intensity volume (a window over 1) on a contiguous plane
            # rather than a view of a colour image
            sgm.replace(block_size=3, colour=False)]
    return out


def _tuner(rng: np.random.Generator) -> None:
    """The self-supervised objective's kernels (census, terms) on a pair and a map of the
    dtypes its score passes (uint8 BGR pair, float32 map with NaN where no disparity)."""
    left = rng.integers(0, 256, (40, 96, 3), dtype=np.uint8)
    disp = np.full(left.shape[:2], 3.0, np.float32)
    disp[:, :8] = np.nan
    terms_of_maps(left, np.roll(left, -3, axis=1), disp)


def _servo_sim() -> None:
    """The simulated servo's own kernels: a lensed view of the default world drawn (marker
    coverage, the lens's redraw boxes) in grey and in colour, and the marker searched in it
    (specks, centroid, ring and disc), so the first `host servo --sim` does not compile them."""
    from host.servo.inputs import _row_mode
    from host.servo.marker import find_discs
    from host.sim.faults import CameraFaults
    from host.sim.renderer import Renderer
    from host.sim.world import World

    world = World.for_size(320, 240, seed=0)
    for grey in (True, False):
        frame = Renderer(world, CameraFaults(distortion=(-0.05, -0.05)), seed=0,
                         grey=grey).frame()
        find_discs(frame.left)
    # the floor-shift check's row mode (inputs._extremes, _fullest_bin; float32 map rows)
    _row_mode(np.linspace(3.0, 9.0, 50, dtype=np.float32))


def warm(part: int = 0, parts: int = 1) -> int:
    """Run every parts-th matcher variant from part on once on a small random colour pair, and
    in the last part the tuner's kernels; returns how many jobs ran."""
    rng = np.random.default_rng(0)
    ps = variants()[part::parts]
    for p in ps:
        size = (40, 64 + p.block_size + 16, 3)
        left = rng.integers(0, 256, size, dtype=np.uint8)
        right = np.roll(left, -3, axis=1)
        compute_disparity(left, right, p.replace(num_disparities=16))
    if part == parts - 1:
        _tuner(rng)
    if part == 0:
        _servo_sim()
    return len(ps) + (part == parts - 1) + (part == 0)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m host.warm", description=__doc__)
    ap.add_argument("--processes", type=int, default=min(2, os.cpu_count() or 1),
                    help="processes compiling at once (default: cores, at most 2)")
    ap.add_argument("--part", type=int, default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.processes < 1:
        print(f"--processes must be at least 1, got {args.processes}", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    if args.part is not None:  # one of the processes below
        warm(args.part, args.processes)
        return 0
    if args.processes == 1:
        n = warm()
    else:
        parts = [subprocess.Popen([sys.executable, "-m", "host.warm", "--processes",
                                   str(args.processes), "--part", str(k)])
                 for k in range(args.processes)]
        if any(p.wait() for p in parts):
            print("a warm-up process failed (above)", file=sys.stderr)
            return 1
        n = len(variants()) + 2
    print(f"numba kernels compiled or loaded from cache: {n} jobs (matcher variants, the "
          f"self-supervised tuner, the servo simulation) in "
          f"{args.processes} processes, {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
