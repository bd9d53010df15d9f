"""host capture: save stereo pairs (for calibration, or to replay later) with a manifest."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

from host.camera.manifest import write_manifest
from host.camera.open import add_camera_options, default_geometry, open_source
from host.commands.options import COUNT, NON_NEGATIVE
from host.errors import HostError
from host.files import check_folder, write_image_atomic
from host.record import add_record_options, check_record, recording


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--count", type=COUNT, default=20, help="pairs to save")
    p.add_argument("--interval", type=NON_NEGATIVE, default=2.0, metavar="S",
                   help="seconds between saved pairs (time to move the chessboard)")
    p.add_argument("--out", type=Path, required=True,
                   help="folder for left_NNN/right_NNN.png and manifest.json")
    add_camera_options(p)
    add_record_options(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    if args.out.exists() and not args.out.is_dir():
        raise HostError(f"--out {args.out}: not a folder")
    if args.out.is_dir() and any(args.out.glob("left_*")):
        raise HostError(f"--out {args.out}: already holds pairs; choose another folder")
    # writable now, but made only once the camera delivers (nothing left behind on failure)
    existing = next(p for p in (args.out, *args.out.parents) if p.exists())
    check_folder(existing, "--out", target=args.out)
    check_record(args)
    with open_source(args) as source, recording(args, time.monotonic) as rec:
        if rec is not None:  # every pair the camera delivers, not only those saved
            from host.camera.calib_files import Calibration
            from host.camera.open import parse_size
            from host.record.tap import RecordingSource

            geometry = (Calibration.load(args.calib).geometry if args.calib
                        else default_geometry(*parse_size(args.size)))
            source = RecordingSource(source, rec, geometry)
        camera = {**source.describe(), "calib": args.calib}
        pairs: list[dict[str, Any]] = []
        next_t = time.monotonic()
        for frame in source:
            if time.monotonic() < next_t:
                continue
            args.out.mkdir(parents=True, exist_ok=True)  # only once the camera delivers
            names = {side: f"{side}_{len(pairs):03d}.png" for side in ("left", "right")}
            for side, img in (("left", frame.left), ("right", frame.right)):
                write_image_atomic(args.out / names[side], img)
            pairs.append({**names, "t_left": frame.t_left, "t_right": frame.t_right})
            write_manifest(args.out, camera, pairs)
            print(f"saved pair {len(pairs)}/{args.count} (skew {frame.skew_ms:.1f} ms)",
                  file=sys.stderr)
            if len(pairs) == args.count:
                print(source.skew_summary(), file=sys.stderr)
                return 0
            next_t = time.monotonic() + args.interval
    raise HostError(f"the camera ended after {len(pairs)} of {args.count} pairs")
