"""Own SGM's quality on the ten shared Middlebury scenes against the strongest OpenCV SGBM.

Usage: bench/sgm_quality.py [--noise] [--photometric]
Prints bad % at 1 px (nonocc / all, Middlebury v2 regions) per scene and the mean over the
ten, each matcher at the scene's ground-truth range (as `host eval` gives it), one thread on
both sides: the old `--matcher sgm`, the steps from the former documented best to the
current defaults (what each piece bought), the defaults with one piece taken out, and
OpenCV SGBM's strongest configuration (issue 24), all computed in this run.
--noise adds rows with Gaussian sigma 5 on the right image (seed 0); --photometric rows with
a right camera of gain 0.7 and of gamma 1.5. Needs STEREO_SERVO_DATA (../shared/data).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import cv2
import numba
import numpy as np

from host.stereo import MatcherParams, compute_disparity
from host.stereo.metrics import middlebury
from host.stereo.params import CENSUS_BITS
from host.stereo.scenes import Scene, load_scenes

STRONGEST_SGBM = MatcherParams(matcher="opencv-sgbm", mode="hh4", block_size=1, colour=False,
                               uniqueness_ratio=10, speckle_window_size=100, speckle_range=2,
                               lr_check=1.0, fill=True, median=5)
DEFAULT = MatcherParams.for_matcher("sgm")
OLD_DEFAULT = MatcherParams(matcher="sgm")  # what `--matcher sgm` gave before (window 9 ...)
FORMER_BEST = MatcherParams(matcher="sgm", block_size=1, border="clip", lr_check=1.0,
                            fill=True)
CENSUS_ONLY = {"intensity_weight": 0.0, "outside_cost": 11}  # census alone, its own outside cost

_8 = FORMER_BEST.replace(paths=8, median=5, subpixel=False)
_MIXED = _8.replace(outside_cost=23, intensity_weight=1.0, p1=8, p2=32)
STEPS = [
    ("former documented best (window 1, clip, LR 1, fill, 5 paths)", FORMER_BEST),
    ("+ 8 paths, median 5, whole pixels", _8),
    ("+ outside cost 11 (census alone)", _8.replace(outside_cost=11)),
    ("+ intensity term on grey (weight 1, cap 20), outside 23", _MIXED.replace(colour=False)),
    ("+ the intensity term on colour", _MIXED),
    ("+ LR 0, uniqueness 30", _MIXED.replace(lr_check=0.0, uniqueness_ratio=30)),
    ("+ P1 18 / P2 72, 4 paths (the defaults before)", DEFAULT.replace(p2_adapt=0.0)),
    ("+ adaptive P2, 128 / (1 + grey step / 16) = the defaults", DEFAULT),
]
WITHOUT = [
    ("defaults with census alone (outside cost 11, P1 8, P2 56 adaptive)",
     DEFAULT.replace(**CENSUS_ONLY)),
    ("the same with a fixed P2 (32)", DEFAULT.replace(p2_adapt=0.0, **CENSUS_ONLY)),
    ("defaults with a fixed P2 (72)", DEFAULT.replace(p2_adapt=0.0)),
    ("defaults with the intensity term on grey (--no-colour)", DEFAULT.replace(colour=False)),
    ("defaults with the census maximum outside", DEFAULT.replace(outside_cost=CENSUS_BITS)),
    ("defaults with LR 1", DEFAULT.replace(lr_check=1.0)),
    ("defaults without uniqueness", DEFAULT.replace(uniqueness_ratio=0.0)),
    ("defaults with 8 paths", DEFAULT.replace(paths=8)),
    ("defaults with 5 paths", DEFAULT.replace(paths=5)),
    ("defaults with the parabola sub-pixel fit", DEFAULT.replace(subpixel=True)),
    ("defaults without median", DEFAULT.replace(median=0)),
]


def scores(scenes: list[Scene], p: MatcherParams, change=None) -> list[tuple[float, float]]:
    out = []
    for s in scenes:
        multiple = 16 if p.matcher.startswith("opencv") else 1
        right = s.right if change is None else change(s.right)
        d = compute_disparity(s.left, right, p.replace(num_disparities=s.num_disparities(multiple)))
        r = middlebury(d, s.gt, s.masks)
        out.append((r["nonocc"].bad, r["all"].bad))
    return out


def row(label: str, res: list[tuple[float, float]]) -> None:
    mean = np.mean(res, axis=0)
    cells = " | ".join(f"{a:5.2f}/{b:5.2f}" for a, b in res)
    print(f"| {label:<62} | {mean[0]:5.2f} | {mean[1]:5.2f} | {cells} |", flush=True)


def noisy(img: np.ndarray) -> np.ndarray:
    rng = np.random.default_rng(0)
    return np.clip(img + rng.normal(0, 5.0, img.shape), 0, 255).astype(np.uint8)


def gain(img: np.ndarray) -> np.ndarray:
    return (img.astype(np.float32) * 0.7).astype(np.uint8)


def gamma(img: np.ndarray) -> np.ndarray:
    return (255 * (img.astype(np.float32) / 255) ** 1.5).astype(np.uint8)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--noise", action="store_true", help="add rows with sigma 5 noise")
    ap.add_argument("--photometric", action="store_true", help="add gain 0.7 / gamma 1.5 rows")
    args = ap.parse_args(argv)
    root = os.environ.get("STEREO_SERVO_DATA")
    if not root or not (Path(root) / "middlebury").is_dir():
        print("bench/sgm_quality.py: set STEREO_SERVO_DATA to shared/data", file=sys.stderr)
        return 2
    numba.set_num_threads(1)
    cv2.setNumThreads(1)
    scenes = load_scenes([Path(root) / "middlebury"])
    print(f"load {' '.join(f'{v:.2f}' for v in os.getloadavg())}; one thread; bad % at 1 px")
    print(f"| configuration | nonocc | all | {' | '.join(s.name for s in scenes)} |")
    row("old `--matcher sgm` (window 9, border invalid, 5 paths)", scores(scenes, OLD_DEFAULT))
    for label, p in STEPS:
        row(label, scores(scenes, p))
    for label, p in WITHOUT:
        row(label, scores(scenes, p))
    row("strongest OpenCV SGBM (HH4, block 1, grey, u10, speckle 100, LR 1, fill, med 5)",
        scores(scenes, STRONGEST_SGBM))
    extra = []
    if args.noise:
        extra.append(("noise sigma 5 on the right", noisy))
    if args.photometric:
        extra += [("right gain 0.7", gain), ("right gamma 1.5", gamma)]
    for what, change in extra:
        row(f"defaults, {what}", scores(scenes, DEFAULT, change))
        row(f"defaults with census alone, {what}",
            scores(scenes, DEFAULT.replace(**CENSUS_ONLY), change))
        row(f"strongest SGBM, {what}", scores(scenes, STRONGEST_SGBM, change))
    return 0


if __name__ == "__main__":
    sys.exit(main())
