"""Open the stereo source a command line names (minoru, sbs, replay), check that left is left,
and apply --calib."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from host.camera.bag import BagSource, is_bag
from host.camera.calib_files import Calibration, is_ideal
from host.camera.calibration import Rectifier
from host.camera.geometry import MINORU_BASELINE_M, Geometry
from host.camera.live import LiveSource
from host.camera.lr_check import CHECKS, handedness
from host.camera.minoru import MinoruSource
from host.camera.replay import ReplaySource
from host.camera.sbs import SideBySideSource
from host.camera.source import CameraError, StereoSource
from host.camera.stamps import STAMPS
from host.errors import HostError


def add_camera_options(p: argparse.ArgumentParser, sim: bool = False) -> None:
    g = p.add_argument_group("camera")
    g.add_argument("--camera", default="minoru",
                   help="minoru or minoru:USB-PORT; sbs, sbs:USB-PORT or sbs:/dev/videoN (a "
                        "side-by-side camera); replay:DIR (left_*/right_* images or "
                        "left.avi/right.avi)" + ("; or sim" if sim else "")
                        + ". host cameras lists what is plugged in")
    g.add_argument("--size", default="320x240",
                   help="size of each view: the Minoru streams 320x240 (30 fps) or 640x480 "
                        "(15 fps); a side-by-side camera what host cameras lists, halved")
    g.add_argument("--devices", metavar="LEFT,RIGHT", help="the Minoru's two /dev/video nodes")
    g.add_argument("--swap", action="store_true", help="the camera's left and right are swapped")
    g.add_argument("--swap-check", choices=CHECKS, default="refuse",
                   help="at start, check that left is left (median disparity sign): refuse a "
                        "swapped pair, swap it (auto), or do not check (off)")
    g.add_argument("--timestamps", choices=STAMPS, default="auto",
                   help="capture times: the driver's buffer stamps, the grab time, or auto")
    g.add_argument("--no-lock", dest="lock", action="store_false",
                   help="leave exposure, gain and white balance on auto")
    g.add_argument("--calib", metavar="CALIB.yml",
                   help="rectify with this calibration (host calibrate --out), or "
                        "LEFT.yaml,RIGHT.yaml (ROS camera_info); a replay:FILE.mcap without "
                        "it is rectified with the bag's CameraInfo")
    g.add_argument("--speed", type=_speed, metavar="X",
                   help="replay:FILE.mcap" + (" and --sim" if sim else "") + ": X times the "
                        "recorded (real) time, 0 as fast as it goes (default: the recorded "
                        "pace" + ("; --sim runs as fast as it goes unless --view" if sim
                                  else "") + ")")


def _speed(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        x = -1.0
    if not (x >= 0 and x < float("inf")):
        raise argparse.ArgumentTypeError(f"must be a number >= 0, got {text!r}")
    return x


def parse_size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise HostError(f"--size must look like 320x240, got {text!r}") from None
    return w, h


def _live(args: argparse.Namespace) -> LiveSource:
    spec, size = args.camera, parse_size(args.size)
    options = {"swap": args.swap, "lock": args.lock, "stamps": args.timestamps}
    if spec == "sbs" or spec.startswith("sbs:"):
        if args.devices:
            raise HostError("--devices is for the Minoru; name a side-by-side camera with "
                            "--camera sbs:/dev/videoN")
        return SideBySideSource(size, spec, **options)
    devices = None
    if args.devices:
        parts = args.devices.split(",")
        if len(parts) != 2:
            raise CameraError(f"--devices needs LEFT,RIGHT, got {args.devices!r}")
        devices = (parts[0], parts[1])
    return MinoruSource(size, devices, spec=spec, **options)


def check_left_right(source: LiveSource, policy: str, frames: int = 3) -> str:
    """Look at a few pairs; refuse (CameraError naming --swap) or swap a pair whose left and
    right are exchanged. Returns what was found, one line."""
    h = None
    for _ in range(frames):
        frame = source.read()
        if frame is None:
            raise CameraError("the camera ended before the left/right check")
        h = handedness(frame.left, frame.right)
        if h.conclusive:
            break
    assert h is not None
    seen = f"median disparity {h.median_px:+.1f} px over {h.pixels} textured pixels"
    if not h.conclusive:
        return f"left/right not checked: too little near texture in view ({seen})"
    if not h.swapped:
        return f"left/right check passed: {seen}"
    if policy == "auto":
        source.swap_views()
        return f"left and right were swapped ({seen}): swapped them back"
    fix = "drop --swap" if source.swapped else "pass --swap"
    raise CameraError(f"left and right look swapped ({seen}): {fix}, or --swap-check auto to "
                      f"swap them at start")


def open_source(args: argparse.Namespace, speed: float = 1.0) -> StereoSource:
    """The source args.camera names (not sim), with rectification when --calib is given (or
    a bag's CameraInfo is not the identity); a bag at args.speed, else speed."""
    spec = args.camera
    rectify = Rectifier(Calibration.load(args.calib)) if args.calib else None  # before a camera
    bag = spec.startswith("replay:") and is_bag(Path(spec[len("replay:"):]))
    if getattr(args, "speed", None) is not None and not bag:
        raise HostError(f"--speed paces a replay:FILE.mcap (or --sim), not --camera {spec}")
    if bag:
        speed = speed if getattr(args, "speed", None) is None else args.speed
        source: StereoSource = BagSource(Path(spec[len("replay:"):]), speed)
        calib = source.calibration  # type: ignore[attr-defined]
        if rectify is None and calib is not None and not is_ideal(calib):
            rectify = Rectifier(calib)
    elif spec.startswith("replay:"):
        source = ReplaySource(Path(spec[len("replay:"):]))
    elif spec.split(":")[0] in ("minoru", "sbs"):
        source = _live(args)
    else:
        raise HostError(f"unknown camera {spec!r} (minoru, sbs, replay:DIR or "
                        f"replay:FILE.mcap)")
    source.rectify = rectify
    try:
        if isinstance(source, LiveSource) and args.swap_check != "off":
            print(f"camera: {check_left_right(source, args.swap_check)}", file=sys.stderr)
    except BaseException:
        source.close()
        raise
    return source


def known_geometry(args: argparse.Namespace, source: StereoSource | None = None
                   ) -> Geometry | None:
    """The rectified geometry from --calib, else from the bag's CameraInfo; None if neither."""
    if args.calib:
        return Calibration.load(args.calib).geometry
    calib = getattr(source, "calibration", None)
    return calib.geometry if calib is not None else None


def source_geometry(args: argparse.Namespace, source: StereoSource | None = None) -> Geometry:
    """known_geometry, else the Minoru's nominal one at --size (said on stderr)."""
    known = known_geometry(args, source)
    return known if known is not None else default_geometry(*parse_size(args.size))


def default_geometry(width: int, height: int) -> Geometry:
    """Geometry.minoru_default, said on stderr (no calibration was given)."""
    g = Geometry.minoru_default(width, height)
    print(f"no --calib: assuming the Minoru's nominal geometry, focal length "
          f"{g.focal_px:.0f} px at {width}x{height} and baseline "
          f"{MINORU_BASELINE_M * 1000:.0f} mm", file=sys.stderr)
    return g
