"""Own SAD's maps, saved or compared bit for bit (issue 24).

Usage: bench/sad_maps.py save FILE.npz | compare FILE.npz [--threads N]
The maps (sad.match_sad through compute_disparity, so the LR check, fill and median too):
- the bench's grey Motorcycle pair resized at every size and candidate count of bench/matcher.py
  (window 9, `bench/matcher.py sad`'s configuration), plus 640x480 at 17, 40, 80 and 200;
- the servo's matching (sim/run.py's params: colour, window 9, border clip, 48 candidates; and
  with the lane window's LR check) on the colour pair at 320x240 and 640x480;
- the ten shared scenes (STEREO_SERVO_DATA) at their ground-truth ranges in five configurations:
  the SAD defaults (colour, window 9), grey window 5, grey window 21 and colour window 15
  (int32 window sums), and border clip with LR 1, uniqueness 10, fill and median 5.
Run it at the commit before a speed change (`save`, from that checkout) and after (`compare`):
`compare` prints each map that differs (NaN equal to NaN) and exits 1 if any does.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numba
import numpy as np

from host.stereo import MatcherParams, compute_disparity
from host.stereo.scenes import load_scenes

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from matcher import SAD_WINDOW, SIZES, resized_pair  # noqa: E402

BENCH = MatcherParams(matcher="sad", block_size=SAD_WINDOW, colour=False)  # bench/matcher.py's
SERVO = MatcherParams(block_size=9, num_disparities=48, border="clip")  # host/sim/run.py's
EXTRA = [(640, 480, nd) for nd in (17, 40, 80, 200)]
SCENE_PARAMS = {
    "default": MatcherParams(matcher="sad"),
    "grey5": MatcherParams(matcher="sad", block_size=5, colour=False),
    "grey21": MatcherParams(matcher="sad", block_size=21, colour=False),
    "colour15": MatcherParams(matcher="sad", block_size=15),
    "clip_lr_u10": MatcherParams(matcher="sad", border="clip", lr_check=1.0,
                                 uniqueness_ratio=10, fill=True, median=5),
}


def maps() -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    for w, h, nd in SIZES + EXTRA:
        gl, gr = resized_pair(w, h)
        out[f"moto{w}x{h}_{nd}"] = compute_disparity(gl, gr, BENCH.replace(num_disparities=nd))
    for w, h in ((320, 240), (640, 480)):
        cl, cr = resized_pair(w, h, colour=True)
        out[f"servo{w}x{h}"] = compute_disparity(cl, cr, SERVO)
        out[f"servo{w}x{h}_lr"] = compute_disparity(cl, cr, SERVO.replace(lr_check=1.0))
    for s in load_scenes([Path(os.environ["STEREO_SERVO_DATA"]) / "middlebury"]):
        for name, p in SCENE_PARAMS.items():
            out[f"{s.name}_{name}"] = compute_disparity(s.left, s.right, p.replace(
                num_disparities=s.num_disparities(1)))
    return out


def main(argv: list[str]) -> int:
    if len(argv) not in (2, 4) or argv[0] not in ("save", "compare") or (
            len(argv) == 4 and argv[2] != "--threads"):
        print(__doc__)
        return 2
    numba.set_num_threads(int(argv[3]) if len(argv) == 4 else 1)
    got = maps()
    if argv[0] == "save":
        np.savez_compressed(argv[1], **got)
        print(f"saved {len(got)} maps")
        return 0
    ref = np.load(argv[1])
    diff = [k for k in ref.files if k not in got
            or not np.array_equal(ref[k], got[k], equal_nan=True)]
    for k in diff:
        print(f"DIFFERS: {k}")
    print(f"{len(ref.files) - len(diff)} of {len(ref.files)} maps equal bit for bit")
    return 1 if diff else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
