"""host view: look at the camera pair live in the browser (left image, disparity, markers)
without driving anything; and the --view option that host servo shares."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import sys
import time
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING

from host.camera.geometry import Geometry
from host.camera.open import add_camera_options, open_source, parse_size, source_geometry
from host.camera.source import StereoSource
from host.commands.options import POSITIVE, add_matcher_options, params_from_args
from host.commands.swap_check import check_recorded
from host.errors import HostError
from host.record import add_record_options, check_record, recording
from host.servo.marker import find_marker
from host.servo.phase import Phase
from host.servo.snapshot import Snapshot
from host.stereo.matcher import compute_disparity

if TYPE_CHECKING:  # the web stack is optional (stereo-servo[view])
    from host.servo.loop import Servo
    from host.view import ViewServer


def add_view_option(p: argparse.ArgumentParser, default: str | None = None,
                    servo: bool = False) -> None:
    p.add_argument("--view", nargs="?", const="127.0.0.1:0", default=default,
                   metavar="[HOST:]PORT",
                   help="serve a live view on this address (default 127.0.0.1 and a free port; "
                        "another address than loopback needs the token printed at start)"
                        + ("; with --sim the simulation then runs in real time (--speed) and "
                           "the page stays up after the run until Ctrl-C" if servo else ""))
    p.add_argument("--view-wait", action="store_true",
                   help="--view: start only once a page is open (so none of the run is missed)")


def wait_for_page(server: ViewServer, poll_s: float = 0.05) -> None:
    """Until a page has connected to server (Ctrl-C ends the wait, and the command)."""
    print("live view: waiting for a page to open (--view-wait; Ctrl-C to quit)",
          file=sys.stderr, flush=True)
    while not server.connections:
        time.sleep(poll_s)


def hold_view(server: ViewServer, reason: str) -> None:
    """After the run: the page says it has ended (reason) and stays up until Ctrl-C, which
    then ends the command as the run did (not as an interrupt)."""
    try:  # from before the line is printed: a Ctrl-C as soon as it is seen ends the wait
        server.feed.end(reason)
        print("live view: the run has ended; the page stays up until Ctrl-C", file=sys.stderr,
              flush=True)
        while True:
            time.sleep(0.2)
    except KeyboardInterrupt:
        print("", file=sys.stderr)


@contextlib.contextmanager
def open_view(address: str | None, servo: Servo | None = None, wait: bool = False
              ) -> Iterator[ViewServer | None]:
    """The live view on address ([HOST:]PORT), fed by servo's steps, its STOP button stopping
    servo (no servo: no STOP); nothing when address is None. Prints the page's address; with
    wait, returns once a page has connected."""
    if address is None:
        yield None
        return
    try:
        from host.view import ViewFeed, ViewServer, parse_address
    except ImportError as e:
        raise HostError(f"--view needs the web stack: pip install 'stereo-servo[view]' "
                        f"({e.name} is missing)") from None

    host, port = parse_address(address)
    feed = ViewFeed(can_stop=servo is not None)
    try:
        with ViewServer(feed, host, port, servo.request_stop if servo else None) as server:
            if servo is not None:
                servo.observers.append(feed)
            note = "" if server.token is None else " (the token is needed: keep it private)"
            print(f"live view: {server.url}{note}", file=sys.stderr, flush=True)
            if wait:
                wait_for_page(server)
            yield server
    finally:
        feed.close()


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_view_option(p, default="127.0.0.1:0")
    p.add_argument("--duration", type=POSITIVE, metavar="S", help="stop after S seconds")
    add_camera_options(p)
    camera = next(a for a in p._actions if a.dest == "camera")
    camera.help = (camera.help or "") + "; or sim: the simulated world, as host servo --sim sees it"
    add_matcher_options(p)
    add_record_options(p)
    p.set_defaults(run=run)


@contextlib.contextmanager
def _sim(args: argparse.Namespace) -> Iterator[tuple[StereoSource, Geometry]]:
    """--camera sim: the simulated world's camera (the robot standing at its start) at --speed
    times real time (default 1, 0 as fast as it goes), and its geometry."""
    from host.camera.paced import PacedSource
    from host.sim.run import Setup, simulation

    if args.calib:
        raise HostError("--camera sim is the simulated camera, rectified already: no --calib")
    with simulation(Setup(parse_size(args.size)), reference=False) as sim:
        speed = 1.0 if args.speed is None else args.speed
        source = PacedSource(sim.source, speed) if speed > 0 else sim.source
        yield source, sim.servo.geometry


def run(args: argparse.Namespace) -> int:
    params = params_from_args(args)
    check_record(args)
    with contextlib.ExitStack() as stack:
        if args.camera == "sim":
            source, geometry = stack.enter_context(_sim(args))
        else:
            source = check_recorded(args, stack.enter_context(open_source(args)))
            geometry = source_geometry(args, source)
        view = stack.enter_context(open_view(args.view, wait=args.view_wait))
        assert view is not None  # host view always serves the page (--view has a default)
        observers: list[Callable[[Snapshot], None]] = [view.feed]
        rec = stack.enter_context(recording(args, time.monotonic))
        if rec is not None:
            from host.record.tap import RecordingSource, StepRecorder, map_range

            source = RecordingSource(source, rec, geometry)
            observers.append(StepRecorder(rec, source, map_range(params)))
        t0 = time.monotonic()

        def time_left() -> bool:
            return args.duration is None or time.monotonic() - t0 < args.duration

        last, snap = None, None
        for frame in source:
            disp = compute_disparity(frame.left, frame.right, params)
            last = find_marker(frame.left, frame.right, "disc", None, geometry.baseline_m, last)
            snap = Snapshot(time.monotonic() - t0, Phase.VIEW, "no robot: looking only", frame.left,
                            disp, 0, None, last, None, None, geometry)
            for observer in observers:
                observer(snap)
            if not time_left():
                return 0
        ended = getattr(source, "ended", None)
        how = ended() if callable(ended) else "the camera ended"
        if snap is not None:  # the page says so too, over the last frame
            view.feed(dataclasses.replace(snap, t=time.monotonic() - t0, phase=Phase.ENDED,
                                          reason=f"{how}: the last frame is shown"))
        print(f"host view: {how}; the page shows its last frame (Ctrl-C to quit)",
              file=sys.stderr, flush=True)
        while time_left():
            time.sleep(0.1)
    return 0
