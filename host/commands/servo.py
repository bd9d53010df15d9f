"""host servo: drive the robot along the depth axis until its disparity equals the nearest
object's; on the real robot, with the emulator, or wholly simulated (--sim)."""

from __future__ import annotations

import argparse
import contextlib
import math
import re
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from host.camera.geometry import Geometry
from host.camera.open import add_camera_options, open_source, parse_size, source_geometry
from host.commands.options import (
    COUNT,
    FRACTION,
    NON_NEGATIVE,
    POSITIVE,
    SEED,
    add_matcher_options,
    float_range,
    int_range,
    params_from_args,
)
from host.commands.servo_outcome import outcome, replay_outcome
from host.commands.swap_check import check_recorded
from host.commands.view import add_view_option, hold_view, open_view
from host.errors import HostError, NotReached, RecordingEnded
from host.files import check_folder, check_output
from host.link.client import SERVO_DRIVE_BUDGET_S, RobotLink
from host.record import add_record_options, check_record, record_servo
from host.servo.controller import ControlConfig
from host.servo.loop import LogRow, Servo
from host.servo.report import plot_run, write_csv
from host.servo_run import ENDED, NOT_SETTLED, Rules, run_servo
from host.signals import signals_held

if TYPE_CHECKING:
    from host.emulator.emulator import Faults
    from host.emulator.simavr import SimavrPty
    from host.emulator.uno import SimulatedUno
    from host.sim.world import World

UNO_FLASH = Path("uno-flash.bin")  # --robot uno's flash file when --flash is not given


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--sim", action="store_true",
                   help="simulated camera and world with the emulator on a pty")
    p.add_argument("--port", help="serial port of the robot, or 'emulator'")
    p.add_argument("--robot", choices=("emulator", "simavr", "uno"), default="emulator",
                   help="--sim: the robot in the simulated world: the firmware's core built "
                        "natively (in lockstep), its AVR binary in simavr, or a simulated Uno "
                        "running what was flashed into --flash (both in real time)")
    p.add_argument("--flash", type=Path, metavar="FILE",
                   help="--robot uno: the board's flash, as `host emulate --uno --flash FILE` "
                        f"and an upload left it (default {UNO_FLASH})")
    p.add_argument("--log", type=Path, metavar="run.csv",
                   help="write the run's log (with --trials: of the one --trial-index)")
    p.add_argument("--plot", type=Path, metavar="run.png",
                   help="plot trajectory and commands (with --trials: the campaign's summary)")
    p.add_argument("--duration", type=POSITIVE, metavar="S", help="stop after S seconds")
    p.add_argument("--settle", type=NON_NEGATIVE, default=1.0, metavar="S",
                   help="end after holding at the target this long (0: run on)")
    p.add_argument("--tolerance-cm", type=POSITIVE, default=1.0,
                   help="hold within this depth of the target (widened, and said so, when below "
                        "the depth noise measured there)")
    p.add_argument("--mode", choices=("turn", "reverse"), default="turn",
                   help="to come back: turn round and drive (the paper) or reverse")
    p.add_argument("--max-duty", type=int_range(1, 1000), default=600,
                   help="largest duty while driving (permille)")
    p.add_argument("--min-duty", type=int_range(0, 1000), default=180,
                   help="least duty that moves the robot (permille)")
    p.add_argument("--marker", dest="marker_kind", choices=("disc", "aruco"), default="disc",
                   help="the robot's marker: a dark disc, or an ArUco tag")
    p.add_argument("--marker-radius-cm", type=NON_NEGATIVE, default=3.0,
                   help="radius of the marker's dark disc (0: do not check sizes)")
    p.add_argument("--start-depth", type=float_range(0.3, 3.0), default=1.9,
                   help="sim: robot's start (m)")
    p.add_argument("--fps", type=float_range(1, 1000), default=30.0, help="sim: frame rate")
    p.add_argument("--faults", action="store_true",
                   help="sim: a world that fails like hardware (random faults from --seed)")
    p.add_argument("--seed", type=SEED, default=0, help="sim: seed of the world and its faults")
    p.add_argument("--trials", type=COUNT, metavar="N",
                   help="sim: N randomized runs of the faulty world, then their summary")
    add_trial_options(p)
    p.add_argument("--drop", type=FRACTION, default=0.0, help="sim: byte drop probability")
    p.add_argument("--corrupt", type=FRACTION, default=0.0,
                   help="sim: byte corruption probability")
    p.add_argument("--delay-ms", type=NON_NEGATIVE, default=0.0, help="sim: line delay (ms)")
    p.add_argument("--silent-after", type=NON_NEGATIVE, metavar="MS",
                   help="sim: the robot goes silent after MS ms")
    add_camera_options(p, sim=True)
    add_matcher_options(p)
    add_view_option(p, servo=True)
    add_record_options(p)
    p.set_defaults(run=run)


TRIAL_OPTIONS = ("json", "csv", "nominal", "trial_index", "ray", "resume")


def add_trial_options(p: argparse.ArgumentParser) -> None:
    """The options that go with --trials (checked in run: without --trials each is refused)."""
    p.add_argument("--json", type=Path, metavar="trials.json",
                   help="with --trials: every trial and the summary, written as they finish")
    p.add_argument("--csv", type=Path, metavar="trials.csv",
                   help="with --trials: a row per trial, appended as each finishes")
    p.add_argument("--resume", action="store_true",
                   help="with --trials and --json: keep the trials that file has, run the rest")
    p.add_argument("--nominal", action="store_true",
                   help="with --trials: the world without faults")
    p.add_argument("--workers", type=COUNT, default=2,
                   help="with --trials: processes (or --ray's local CPUs)")
    p.add_argument("--ray", nargs="?", const="local", metavar="ADDRESS",
                   help="with --trials: run them as Ray tasks, on a local cluster bound to "
                        "127.0.0.1 or on the one at ADDRESS (host:port, ray://host:port, auto)")
    p.add_argument("--trial-index", type=int_range(0, 1_000_000), action="append",
                   metavar="I", help="with --trials: run only trial I of them (repeatable), "
                   "to reproduce one; the same whichever backend ran it")


class _Status:
    """One live line on a terminal: phase, disparities, error, command, loop rate."""

    def __init__(self) -> None:
        self.tty = sys.stderr.isatty()
        self._last = 0.0

    def show(self, row: LogRow) -> None:
        now = time.monotonic()
        if not self.tty or now - self._last < 0.1:
            return
        self._last = now
        robot = f"{row.depth_m:6.3f}" if math.isfinite(row.depth_m) else "   ---"
        err = f"{row.error_m * 100:+6.1f}" if math.isfinite(row.error_m) else "   ---"
        hz = f"{row.loop_hz:5.1f}" if math.isfinite(row.loop_hz) else "  ---"
        sys.stderr.write(f"\r{row.t:7.2f} s  {row.phase:<7}  target {row.target_m:6.3f} m  "
                         f"robot {robot} m  error {err} cm  cmd {row.left:5d} {row.right:5d}  "
                         f"{hz} Hz ")
        sys.stderr.flush()

    def done(self) -> None:
        if self.tty:
            sys.stderr.write("\n")


def run(args: argparse.Namespace) -> int:
    if args.flash is not None and args.robot != "uno":
        raise HostError("--flash is the simulated Uno's flash: it goes with --robot uno")
    if args.robot != "emulator" and not args.sim:
        raise HostError(f"--robot {args.robot} puts a simulated board in the simulated world: "
                        f"it needs --sim")
    if args.log and args.trials and len(args.trial_index or ()) != 1:
        raise HostError("--log writes one run's log: with --trials, give one --trial-index to "
                        "trace that trial (a row a trial goes to --csv, every trial to --json)")
    if args.log:
        check_output(args.log, "csv", "--log")
    if args.plot:
        check_output(args.plot, "png", "--plot")
    check_record(args)
    if args.record and args.trials:
        raise HostError("--record records one run: not with --trials")
    if args.view_wait and not args.view:
        raise HostError("--view-wait waits for the page of --view: give --view too")
    if args.min_duty > args.max_duty:
        raise HostError(f"--min-duty {args.min_duty} exceeds --max-duty {args.max_duty}")
    trial_only = ["--" + o.replace("_", "-") for o in TRIAL_OPTIONS if getattr(args, o)]
    if trial_only and not args.trials:
        raise HostError(f"{trial_only[0]} goes with --trials N: without it nothing reads it")
    if args.trials:
        _check_trial_args(args)
    if args.sim or args.camera == "sim":
        if args.marker_kind != "disc" or args.marker_radius_cm != 3.0:
            raise HostError("--marker and --marker-radius-cm describe the real robot's card: "
                            "the simulated world draws its own (a 3 cm disc)")
        if args.port not in (None, "emulator"):
            raise HostError("--camera sim needs --port emulator (the simulated robot)")
        return _run_sim(args)
    if args.trials or args.faults:
        raise HostError("--trials and --faults need --sim")
    if not args.port:
        raise HostError("--port is needed (a serial port, or 'emulator'); --sim runs it all "
                        "simulated")
    params = params_from_args(args)
    with contextlib.ExitStack() as stack:
        service = None
        if args.port == "emulator":
            from host.emulator.emulator import Emulator, PtyService

            service = stack.enter_context(PtyService(Emulator(_link_faults(args))))
        # the port first: a wrong one fails before a camera is opened
        link = stack.enter_context(RobotLink(service.path if service else args.port,
                                             drive_budget_s=SERVO_DRIVE_BUDGET_S))
        source = check_recorded(args, stack.enter_context(open_source(args)))
        geometry = source_geometry(args, source)
        clock = getattr(source, "clock", time.monotonic)  # a bag's own clock (its stamps)
        servo = Servo(source, link, params, geometry, _control(args), marker_kind=args.marker_kind,
                      marker_radius_m=args.marker_radius_cm / 100 if args.marker_radius_cm
                      else None, clock=clock)
        return _servo(args, servo, geometry, None, clock)


def _check_trial_args(args: argparse.Namespace) -> None:
    if args.json:
        if args.json.is_dir():
            raise HostError(f"--json {args.json}: is a folder (name a file)")
        check_folder(args.json.parent, "--json", target=args.json)
    if args.csv:
        check_output(args.csv, "csv", "--csv")
    if args.resume and not args.json:
        raise HostError("--resume needs --json FILE: the trials finished are read from it")
    if args.ray is not None and not (args.ray in ("local", "auto")
                                     or args.ray.startswith("ray://")
                                     or re.fullmatch(r"[\w.\-]+:\d+", args.ray)):
        raise HostError(f"--ray ADDRESS must be host:port, ray://host:port or auto, got "
                        f"{args.ray!r}")


def _link_faults(args: argparse.Namespace) -> Faults:
    from host.emulator.emulator import Faults

    return Faults(drop=args.drop, corrupt=args.corrupt, delay_ms=args.delay_ms,
                  silent_after_ms=args.silent_after, seed=args.seed)


def _control(args: argparse.Namespace) -> ControlConfig:
    return ControlConfig(tolerance_m=args.tolerance_cm / 100, max_duty=args.max_duty,
                         min_duty=args.min_duty, mode=args.mode)


def _run_sim(args: argparse.Namespace) -> int:
    import dataclasses

    import numpy as np

    from host.sim.faults import WorldFaults, random_faults
    from host.sim.run import Setup, simulation

    params = params_from_args(args)
    if args.trials:
        from host.sim.campaign import run_trials

        ray = None if args.ray is None else True if args.ray == "local" else args.ray
        status = run_trials(args.trials, args.seed, parse_size(args.size), params, args.json,
                            workers=args.workers, nominal=args.nominal,
                            indices=args.trial_index, csv_path=args.csv, ray=ray,
                            resume=args.resume, plot_path=args.plot)
        if args.log:  # the one trial again in this process, for its log: the same run
            from host.sim.trials import traced_trial

            _, rows = traced_trial((args.seed, args.trial_index[0], parse_size(args.size),
                                    params, args.nominal))
            with signals_held():
                write_csv(args.log, rows)
            print(f"log: {args.log}")
        return status
    faults = WorldFaults()
    if args.faults:
        faults = random_faults(np.random.default_rng(args.seed), 1.2)
    link = _link_faults(args)
    if link != type(link)(seed=args.seed):
        faults = dataclasses.replace(faults, link=link)
    with contextlib.ExitStack() as stack:
        board = None if args.robot == "emulator" else stack.enter_context(_avr_board(args))
        setup = Setup(parse_size(args.size), args.start_depth, faults=faults, seed=args.seed,
                      fps=args.fps, params=params, control=_control(args), board=board)
        sim = stack.enter_context(simulation(setup, reference=False))
        speed = args.speed if args.speed is not None else 1.0 if args.view else 0.0
        if speed > 0:  # to be watched: in real time (or --speed times it)
            from host.camera.paced import PacedSource

            sim.servo.source = PacedSource(sim.servo.source, speed)
        return _servo(args, sim.servo, sim.servo.geometry, sim.world, sim.source.clock)


def _avr_board(args: argparse.Namespace) -> SimulatedUno | SimavrPty:
    """The real AVR firmware on a simulated board, for the simulated world to drive."""
    from host.emulator import build

    if args.robot == "uno":
        from host.emulator.uno import SimulatedUno

        flash = args.flash or UNO_FLASH
        if not flash.is_file():
            raise HostError(f"--flash {flash} not found: flash the Uno first (host emulate "
                            f"--uno --flash {flash}, then make flash PORT=...)")
        return SimulatedUno(flash)
    from host.emulator.simavr import SimavrPty

    out = build.ROOT / "build" / "simavr"
    out.mkdir(parents=True, exist_ok=True)
    return SimavrPty(build.simavr_harness(out), build.firmware_elf())


def _servo(args: argparse.Namespace, servo: Servo, geometry: Geometry, world: World | None,
           clock: Callable[[], float]) -> int:
    with open_view(args.view, servo, args.view_wait) as view:
        # a simulated run's page stays up after the run has ended (not when its STOP ended it)
        hold = view if world is not None else None
        try:
            with record_servo(args, servo, clock):
                status = _run_servo(args, servo, geometry, world, clock)
        except NotReached as e:
            if hold is not None and not servo.requested_stop:
                hold_view(hold, str(e))
            raise
        if hold is not None and not servo.requested_stop:
            hold_view(hold, outcome(servo)[1])
        return status


SIM_LIMIT_S = 60.0  # a simulated run without --duration that has not settled by then failed


def _run_servo(args: argparse.Namespace, servo: Servo, geometry: Geometry,
               world: World | None, clock: Callable[[], float]) -> int:
    target = servo.reference()
    z = geometry.depth_m(target.disparity)
    print(f"target: nearest object at disparity {target.disparity:.2f} px ({z:.3f} m), "
          f"{target.area} px; tolerance {servo.tolerance_m * 100:g} cm", file=sys.stderr)
    status = _Status()

    def each(row: LogRow) -> None:
        for note in servo.notes + servo.link.notes:
            print(f"note: {note}", file=sys.stderr)
        servo.notes.clear()
        servo.link.notes.clear()
        status.show(row)

    rules = Rules(settle_s=args.settle, duration_s=args.duration,
                  limit_s=SIM_LIMIT_S if world is not None and args.duration is None else None,
                  camera_end_ok=args.camera.startswith("replay:"))
    try:
        # ends at the servo's own safe stop, STOP pressed in the view, --duration, --settle,
        # a replay's end (outcome() tells how it went) or, simulated, the time limit
        end = run_servo(servo, rules, clock, (lambda: world.robot.z_m) if world else
                        (lambda: math.nan), each=each)
        if end.how == NOT_SETTLED:
            raise NotReached(f"the simulated robot did not settle within {SIM_LIMIT_S:g} s")
    finally:
        status.done()
        if servo.rows:
            with signals_held():  # a second Ctrl-C does not cut the log or the plot short
                if args.log:
                    write_csv(args.log, servo.rows)
                if args.plot:
                    plot_run(args.plot, servo.rows, geometry)
    ended = end.how == ENDED
    exit_status, msg = replay_outcome(servo, servo.source) if ended else outcome(servo)
    if world is not None:
        msg += (f"; true robot depth {world.robot.z_m:.3f} m, nearest box "
                f"{world.nearest_box().z_m:.3f} m")
    if exit_status != 0:  # NOT_REACHED or RECORDING_ENDED: the error that carries it
        raise (RecordingEnded if exit_status == RecordingEnded.status else NotReached)(msg)
    print(msg, file=sys.stderr)
    if servo.requested_stop:
        robot = servo.link.status()
        print(f"the robot reports duty {robot.left} {robot.right} after STOP", file=sys.stderr)
    return 0
