"""host disparity LEFT RIGHT -o OUT.png: one disparity map as a picture (and --npy raw)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import cv2
import numpy as np

from host.commands.options import add_matcher_options, params_from_args
from host.errors import HostError
from host.files import IMAGE, all_or_nothing, check_output, write_image_atomic, write_npy_atomic
from host.stereo.matcher import compute_disparity
from host.stereo.picture import picture
from host.stereo.scenes import read_image


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("left", type=Path, help="left image of a rectified pair")
    p.add_argument("right", type=Path, help="right image, same size and kind")
    p.add_argument("-o", "--out", type=Path, required=True,
                   help="picture with a colour bar (.png, .jpg ...)")
    p.add_argument("--npy", type=Path, help="also write the raw float32 map (px, NaN = none)")
    add_matcher_options(p)
    p.set_defaults(run=run)


def _eight_bit(path: Path, img: np.ndarray) -> np.ndarray:
    """The image as the matchers take it (8-bit grey or BGR, alpha dropped), or one line."""
    if img.dtype != np.uint8:
        raise HostError(f"{path}: a {8 * img.itemsize}-bit image: the matchers take 8-bit "
                        "views (convert both, e.g. convert IN -depth 8 OUT)")
    if img.ndim == 3 and img.shape[2] == 4:
        return cv2.cvtColor(img, cv2.COLOR_BGRA2BGR)
    return img


def run(args: argparse.Namespace) -> int:
    check_output(args.out, IMAGE, "--out")
    if args.npy:
        check_output(args.npy, "npy", "--npy")
    params = params_from_args(args)
    left, right = (_eight_bit(path, read_image(path, cv2.IMREAD_UNCHANGED))
                   for path in (args.left, args.right))
    if left.ndim != right.ndim and params.colour:  # colour matching needs two colour views
        kinds = {2: "grey", 3: "colour"}
        raise HostError(f"{args.left} is {kinds[left.ndim]} and {args.right} "
                        f"{kinds[right.ndim]}: give a pair of one kind, or --no-colour")
    t0 = time.perf_counter()
    disp = compute_disparity(left, right, params)
    ms = (time.perf_counter() - t0) * 1000
    top = params.min_disparity + params.num_disparities
    with all_or_nothing():
        write_image_atomic(args.out, picture(disp, top))
        if args.npy:
            write_npy_atomic(args.npy, disp)
    density = 100.0 * float((disp == disp).mean())
    print(f"{args.out}: {disp.shape[1]}x{disp.shape[0]}, density {density:.1f}%, "
          f"{ms:.1f} ms ({params.matcher}, block size {params.block_size})", file=sys.stderr)
    return 0
