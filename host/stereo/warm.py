"""Compile every numba kernel signature users hit into numba's cache (run at installation).

`python -m host.stereo.warm` (the Makefile's venv step runs it) calls each own matcher on a
small random pair with every lane width, channel count and option that selects a different
compiled signature, so the first `host eval` loads machine code instead of compiling it.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from host.stereo.matcher import compute_disparity
from host.stereo.params import MatcherParams


def variants() -> list[MatcherParams]:
    """Parameter sets covering the compiled signatures (lane types, LR check, box sums)."""
    out = []
    # SAD lanes: (uint16, uint16), (uint16, int32) and (int32, int32) column/window sums
    for colour, window in [(False, 5), (False, 21), (True, 9), (True, 15), (True, 87)]:
        out.append(MatcherParams(matcher="sad", block_size=window, colour=colour))
    out += [MatcherParams(matcher="sad", lr_check=1.0, uniqueness_ratio=10, fill=True, median=5,
                          border="clip"),
            MatcherParams(matcher="ssd", lr_check=1.0),
            MatcherParams(matcher="ncc", block_size=5, lr_check=1.0, border="clip"),
            MatcherParams(matcher="sgm", block_size=1, lr_check=1.0, fill=True),
            MatcherParams(matcher="sgm", block_size=3, uniqueness_ratio=10),
            MatcherParams.for_matcher("sgm")]  # the cost volume with the intensity term
    return out


def warm() -> int:
    """Run every variant once on a small random colour pair; returns how many ran."""
    rng = np.random.default_rng(0)
    ps = variants()
    for p in ps:
        size = (40, 64 + p.block_size + 16, 3)
        left = rng.integers(0, 256, size, dtype=np.uint8)
        right = np.roll(left, -3, axis=1)
        compute_disparity(left, right, p.replace(num_disparities=16))
    return len(ps)


def main() -> int:
    t0 = time.perf_counter()
    n = warm()
    print(f"numba kernels compiled or loaded from cache: {n} matcher variants, "
          f"{time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
