"""host calibrate DIR: stereo calibration from chessboard pairs saved by host capture."""

from __future__ import annotations

import argparse
from pathlib import Path

from host.camera.calibration import calibrate
from host.camera.replay import ReplaySource
from host.commands.options import POSITIVE
from host.errors import HostError
from host.files import check_output


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("calibrate", help="calibrate and rectify the stereo camera")
    p.add_argument("folder", type=Path, help="left_*/right_* chessboard pairs")
    p.add_argument("--board", default="9x6", help="inner corners, columns x rows")
    p.add_argument("--square", type=POSITIVE, default=25.0, help="square size (mm)")
    p.add_argument("--out", type=Path, default=Path("calib.yml"), help="calibration file")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    try:
        cols, rows = (int(v) for v in args.board.lower().split("x"))
    except ValueError:
        raise HostError(f"--board must look like 9x6, got {args.board!r}") from None
    if cols < 2 or rows < 2:
        raise HostError(f"--board needs at least 2x2 inner corners, got {args.board!r}")
    check_output(args.out, "yml", "--out")
    pairs = list(ReplaySource(args.folder))
    calib, used = calibrate(pairs, (cols, rows), args.square)
    calib.save(args.out)
    g = calib.geometry
    print(f"{args.out}: {used} of {len(pairs)} pairs used, {calib.size[0]}x{calib.size[1]}")
    print(f"  reprojection RMS {calib.rms:.3f} px, row error after rectification "
          f"{calib.epipolar_rms:.3f} px RMS")
    print(f"  rectified focal length {g.focal_px:.1f} px, baseline {calib.baseline_mm:.1f} mm")
    return 0
