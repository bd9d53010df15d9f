"""Open the stereo source a command line names: minoru, or replay:PATH; with --calib applied."""

from __future__ import annotations

import argparse

from host.camera.calibration import Calibration, Rectifier
from host.camera.minoru import MinoruSource
from host.camera.replay import ReplaySource
from host.camera.source import CameraError, StereoSource
from host.errors import HostError


def add_camera_options(p: argparse.ArgumentParser, sim: bool = False) -> None:
    g = p.add_argument_group("camera")
    g.add_argument("--camera", default="minoru",
                   help="minoru, minoru:USB-PORT (host cameras lists them), replay:DIR "
                        "(left_*/right_* images or left.avi/right.avi)"
                        + (", or sim" if sim else ""))
    g.add_argument("--size", default="320x240", help="Minoru mode: 320x240 (30 fps) or "
                                                     "640x480 (15 fps)")
    g.add_argument("--devices", metavar="LEFT,RIGHT", help="the two /dev/video nodes")
    g.add_argument("--swap", action="store_true", help="the Minoru's left and right are swapped")
    g.add_argument("--calib", metavar="CALIB.yml", help="rectify with this calibration")


def parse_size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise HostError(f"--size must look like 320x240, got {text!r}") from None
    return w, h


def open_source(args: argparse.Namespace) -> StereoSource:
    """The source args.camera names (not sim), with rectification when --calib is given."""
    spec = args.camera
    if spec == "minoru" or spec.startswith("minoru:"):
        devices = None
        if args.devices:
            parts = args.devices.split(",")
            if len(parts) != 2:
                raise CameraError(f"--devices needs LEFT,RIGHT, got {args.devices!r}")
            devices = (parts[0], parts[1])
        source: StereoSource = MinoruSource(parse_size(args.size), devices, args.swap,
                                               spec=spec)
    elif spec.startswith("replay:"):
        from pathlib import Path

        source = ReplaySource(Path(spec[len("replay:"):]))
    else:
        raise HostError(f"unknown camera {spec!r} (minoru or replay:DIR)")
    if args.calib:
        source.rectify = Rectifier(Calibration.load(args.calib))
    return source
