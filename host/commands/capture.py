"""host capture: save stereo pairs (for calibration, or to replay later)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from host.camera.open import add_camera_options, open_source
from host.commands.options import COUNT, NON_NEGATIVE
from host.errors import HostError
from host.files import check_folder, write_image_atomic


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("capture", help="save stereo image pairs from the camera")
    p.add_argument("--count", type=COUNT, default=20, help="pairs to save")
    p.add_argument("--interval", type=NON_NEGATIVE, default=2.0, metavar="S",
                   help="seconds between saved pairs (time to move the chessboard)")
    p.add_argument("--out", type=Path, required=True, help="folder for left_NNN/right_NNN.png")
    add_camera_options(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    check_folder(args.out, "--out", create=True)
    with open_source(args) as source:
        saved, next_t = 0, time.monotonic()
        for frame in source:
            if time.monotonic() < next_t:
                continue
            for side, img in (("left", frame.left), ("right", frame.right)):
                write_image_atomic(args.out / f"{side}_{saved:03d}.png", img)
            saved += 1
            print(f"saved pair {saved}/{args.count} (skew {frame.skew_ms:.1f} ms)",
                  file=sys.stderr)
            if saved == args.count:
                return 0
            next_t = time.monotonic() + args.interval
    raise HostError(f"the camera ended after {saved} of {args.count} pairs")
