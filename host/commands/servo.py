"""host servo: drive the robot along the depth axis until its disparity equals the nearest
object's; on the real robot, with the emulator, or wholly simulated (--sim)."""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
import time
from pathlib import Path

from host.camera.calibration import Calibration, Geometry
from host.camera.open import add_camera_options, open_source, parse_size
from host.commands.options import add_matcher_options, params_from_args
from host.errors import HostError
from host.link.client import RobotLink
from host.servo.controller import ControlConfig
from host.servo.loop import Servo
from host.servo.report import plot_run, write_csv


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("servo", help="servo the robot to the nearest object's depth")
    p.add_argument("--sim", action="store_true",
                   help="simulated camera and world with the emulator on a pty")
    p.add_argument("--port", help="serial port of the robot, or 'emulator'")
    p.add_argument("--log", type=Path, metavar="run.csv", help="write the run's log")
    p.add_argument("--plot", type=Path, metavar="run.png", help="plot trajectory and commands")
    p.add_argument("--duration", type=float, metavar="S", help="stop after S seconds")
    p.add_argument("--settle", type=float, default=1.0, metavar="S",
                   help="end after holding at the target this long (0: run on)")
    p.add_argument("--tolerance-cm", type=float, default=1.0,
                   help="stop within this depth of the target (converted to px there)")
    p.add_argument("--mode", choices=("turn", "reverse"), default="turn",
                   help="to come back: turn round and drive (the paper) or reverse")
    p.add_argument("--turn-s", type=float, help="seconds a turn round takes (default: the "
                                                "simulated robot's, 2 s on a real one)")
    p.add_argument("--max-duty", type=int, default=600)
    p.add_argument("--min-duty", type=int, default=180, help="least duty that moves the robot")
    p.add_argument("--marker", choices=("disc", "aruco"), default="disc")
    p.add_argument("--marker-radius-cm", type=float, default=3.0,
                   help="radius of the marker's dark disc (0: do not check sizes)")
    p.add_argument("--start-depth", type=float, default=1.9, help="sim: robot's start (m)")
    p.add_argument("--fps", type=float, default=30.0, help="sim: frame rate")
    add_camera_options(p, sim=True)
    add_matcher_options(p)
    p.set_defaults(run=run)


class _Status:
    """One live line on a terminal: phase, disparities, error, command, loop rate."""

    def __init__(self) -> None:
        self.tty = sys.stderr.isatty()
        self._last = 0.0

    def show(self, row) -> None:
        now = time.monotonic()
        if not self.tty or now - self._last < 0.1:
            return
        self._last = now
        robot = f"{row.robot_px:6.2f}" if math.isfinite(row.robot_px) else "   ---"
        err = f"{row.error_px:+6.2f}" if math.isfinite(row.error_px) else "   ---"
        hz = f"{row.loop_hz:5.1f}" if math.isfinite(row.loop_hz) else "  ---"
        sys.stderr.write(f"\r{row.t:7.2f} s  {row.phase:<5}  target {row.target_px:6.2f} px  "
                         f"robot {robot} px  error {err}  cmd {row.left:5d} {row.right:5d}  "
                         f"{hz} Hz ")
        sys.stderr.flush()

    def done(self) -> None:
        if self.tty:
            sys.stderr.write("\n")


def run(args: argparse.Namespace) -> int:
    if args.sim:
        args.camera, args.port = "sim", args.port or "emulator"
    if not args.port:
        raise HostError("--port is needed (a serial port, or 'emulator'); --sim runs it all "
                        "simulated")
    params = params_from_args(args)
    with contextlib.ExitStack() as stack:
        emulator, service = None, None
        if args.port == "emulator":
            from host.emulator.emulator import Emulator, PtyService

            emulator = Emulator(line_rate=args.camera != "sim")
            service = stack.enter_context(PtyService(emulator, realtime=args.camera != "sim"))
        if args.camera == "sim":
            if emulator is None:
                raise HostError("--camera sim needs --port emulator (the simulated robot)")
            source, world, geometry, clock = _sim(args, emulator)
        else:
            source = stack.enter_context(open_source(args))
            world, clock = None, time.monotonic
            geometry = (Calibration.load(args.calib).geometry if args.calib
                        else Geometry.minoru_default(*parse_size(args.size)))
        link = stack.enter_context(RobotLink(service.path if service else args.port))
        return _servo(args, params, source, link, geometry, world, clock)


def _sim(args, emulator):
    from host.sim.source import SimSource
    from host.sim.world import World

    w, h = parse_size(args.size)
    world = World.for_size(w, h)
    world.robot.z_m = args.start_depth
    source = SimSource(world, emulator, args.fps)
    return source, world, world.geometry, source.clock


def _servo(args, params, source, link, geometry, world, clock) -> int:
    turn_s = args.turn_s or (world.motors.turn_seconds(ControlConfig.turn_duty) if world
                             else 2.0)
    servo = Servo(source, link, params, geometry, ControlConfig(
        max_duty=args.max_duty, min_duty=args.min_duty, mode=args.mode, turn_s=turn_s),
        marker=args.marker, clock=clock,
        marker_radius_m=args.marker_radius_cm / 100 if args.marker_radius_cm else None,
        tolerance_m=args.tolerance_cm / 100)
    target = servo.reference()
    z = geometry.depth_m(target.disparity)
    tol = servo.control.tolerance_px
    print(f"target: nearest object at disparity {target.disparity:.2f} px ({z:.3f} m), "
          f"{target.area} px; tolerance {tol:.3f} px = {args.tolerance_cm:g} cm there",
          file=sys.stderr)
    status = _Status()
    t0 = clock()
    try:
        while True:
            row = servo.step(world.robot.z_m if world else math.nan)
            status.show(row)
            if args.duration is not None and clock() - t0 >= args.duration:
                break
            if args.settle and servo.held_for(args.settle):
                break
            if world is not None and args.duration is None and clock() - t0 > 60:
                raise HostError("the simulated robot did not settle within 60 s")
    finally:
        status.done()
        if servo.rows:
            if args.log:
                write_csv(args.log, servo.rows)
            if args.plot:
                plot_run(args.plot, servo.rows, geometry)
    last = servo.rows[-1]
    robot_z = geometry.depth_m(last.robot_px) if last.robot_px > 0 else math.nan
    msg = (f"held at disparity {last.robot_px:.2f} px ({robot_z:.3f} m) against the target's "
           f"{target.disparity:.2f} px after {last.t - t0:.1f} s")
    if world is not None:
        msg += (f"; true robot depth {world.robot.z_m:.3f} m, nearest box "
                f"{world.nearest_box().z_m:.3f} m")
    print(msg, file=sys.stderr)
    return 0
