"""Own SGM's maps at `--matcher sgm`'s defaults, saved or compared bit for bit (issue 24).

Usage: bench/sgm_maps.py save FILE.npz | compare FILE.npz
The maps: the ten shared scenes at their ground-truth ranges (STEREO_SERVO_DATA), and the
bench's colour Motorcycle pair resized at every size and candidate count of bench/matcher.py
plus 640x480 at 17, 40, 80 and 200 candidates; one numba thread. `compare` prints each map
that differs (NaN equal to NaN) and the mean nonocc / all bad % over the ten, and exits 1 if
any map differs. A speed change of the kernels must leave every map as it was.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numba
import numpy as np

from host.stereo import MatcherParams, compute_disparity
from host.stereo.metrics import middlebury
from host.stereo.scenes import load_scenes

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from matcher import SIZES, resized_pair  # noqa: E402

DEFAULT = MatcherParams.for_matcher("sgm")
EXTRA = [(640, 480, nd) for nd in (17, 40, 80, 200)]


def maps() -> tuple[dict[str, np.ndarray], list[tuple[float, float]]]:
    numba.set_num_threads(1)
    out: dict[str, np.ndarray] = {}
    bad = []
    for s in load_scenes([Path(os.environ["STEREO_SERVO_DATA"]) / "middlebury"]):
        d = compute_disparity(s.left, s.right, DEFAULT.replace(
            num_disparities=s.num_disparities(1)))
        out[s.name] = d
        r = middlebury(d, s.gt, s.masks)
        bad.append((r["nonocc"].bad, r["all"].bad))
    for w, h, nd in SIZES + EXTRA:
        gl, gr = resized_pair(w, h, colour=True)
        out[f"moto{w}x{h}_{nd}"] = compute_disparity(gl, gr, DEFAULT.replace(num_disparities=nd))
    return out, bad


def main(argv: list[str]) -> int:
    if len(argv) != 2 or argv[0] not in ("save", "compare"):
        print(__doc__)
        return 2
    got, bad = maps()
    mean = np.mean(bad, axis=0)
    print(f"ten scenes, mean bad % nonocc / all: {mean[0]:.4f} / {mean[1]:.4f}")
    if argv[0] == "save":
        np.savez_compressed(argv[1], **got)
        print(f"saved {len(got)} maps")
        return 0
    ref = np.load(argv[1])
    diff = [k for k in ref.files if not np.array_equal(ref[k], got[k], equal_nan=True)]
    for k in diff:
        print(f"DIFFERS: {k}")
    print(f"{len(ref.files) - len(diff)} of {len(ref.files)} maps equal bit for bit")
    return 1 if diff else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
