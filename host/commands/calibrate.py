"""host calibrate DIR: stereo calibration from chessboard pairs saved by host capture, with
badly fitting views rejected, a coverage report, and OpenCV and ROS camera_info files."""

from __future__ import annotations

import argparse
from pathlib import Path

from host.camera.calib_files import save_ros
from host.camera.calib_report import check_picture, coverage, coverage_lines
from host.camera.calibration import MIN_VIEWS, CalibrationRun, View, calibrate
from host.camera.replay import image_pairs
from host.camera.source import StereoFrame
from host.commands.options import COUNT, POSITIVE
from host.errors import HostError
from host.files import check_folder, check_output, write_image_atomic
from host.stereo.scenes import read_image


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("folder", type=Path, help="left_*/right_* chessboard pairs")
    p.add_argument("--board", default="9x6", help="inner corners, columns x rows")
    p.add_argument("--square", type=POSITIVE, default=25.0, help="square size (mm)")
    p.add_argument("--out", type=Path, default=Path("calib.yml"), help="calibration file")
    p.add_argument("--ros", type=Path, metavar="DIR",
                   help="also write DIR/left.yaml and DIR/right.yaml (ROS camera_info)")
    p.add_argument("--picture", type=Path, metavar="PNG",
                   help="the first used pair rectified, with horizontal lines to check by eye")
    p.add_argument("--min-views", type=COUNT, default=MIN_VIEWS,
                   help="least number of well-fitting chessboard pairs")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    try:
        cols, rows = (int(v) for v in args.board.lower().split("x"))
    except ValueError:
        raise HostError(f"--board must look like 9x6, got {args.board!r}") from None
    if cols < 2 or rows < 2:
        raise HostError(f"--board needs at least 2x2 inner corners, got {args.board!r}")
    if args.min_views < 3:
        raise HostError("--min-views must be at least 3")
    if args.ros is not None:
        check_folder(args.ros, "--ros", create=True)
    check_output(args.out, "yml", "--out")
    if args.picture is not None:
        check_output(args.picture, "image", "--picture")
    files = image_pairs(args.folder)
    pairs = [StereoFrame(read_image(lf), read_image(rf), 0.0, 0.0) for lf, rf in files]
    result = calibrate(pairs, (cols, rows), args.square, [lf.name[5:] for lf, _ in files],
                       args.min_views)
    calib = result.calibration
    calib.save(args.out)
    written = [str(args.out)]
    if args.ros is not None:
        written += [str(p) for p in save_ros(calib, args.ros)]
    used = [v for v in result.views if v.status == "used"]
    if args.picture is not None:
        first = next(i for i, v in enumerate(result.views) if v.status == "used")
        write_image_atomic(args.picture, check_picture(calib, pairs[first]))
        written.append(str(args.picture))
    _report(result, len(pairs), used, written)
    return 0


def _report(result: CalibrationRun, n_pairs: int, used: list[View], written: list[str]
            ) -> None:
    calib, g = result.calibration, result.calibration.geometry
    print(f"{', '.join(written)}: {len(used)} of {n_pairs} pairs used, "
          f"{calib.size[0]}x{calib.size[1]}")
    for v in result.views:
        if v.status == "no board":
            print(f"  {v.name}: no board found in both views")
        elif v.status == "rejected":
            print(f"  {v.name}: rejected, reprojection error {v.error_px:.2f} px (the board "
                  f"moved between the views, was bent, or the corners were misread)")
    errors = sorted(v.error_px for v in used)
    print(f"  per-view reprojection error of the pairs used: median {errors[len(errors) // 2]:.3f}"
          f" px, worst {errors[-1]:.3f} px")
    print(f"  reprojection RMS {calib.rms:.3f} px, row error after rectification "
          f"{calib.epipolar_rms:.3f} px RMS")
    print(f"  rectified focal length {g.focal_px:.1f} px, baseline {calib.baseline_mm:.1f} mm")
    for side, k in (("left", 0), ("right", 1)):
        counts = coverage([v.corners[k] for v in used if v.corners is not None], calib.size)
        print("\n".join(coverage_lines(counts, side)))
    if result.problem:  # the lens model beyond the boards' reach (calibration.edge_problem)
        print(f"  warning: {result.problem}")
