"""Recording runs as ROS 2 bags in MCAP storage (images, camera info, disparity, marker,
target, phase, drive and link health, in standard message types), and the --record option the
commands share. Needs the `record` extra (rosbags, mcap)."""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from host.errors import HostError
from host.files import check_output


def add_record_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("recording")
    g.add_argument("--record", type=Path, metavar="FILE.mcap",
                   help="record the run as a ROS 2 bag in MCAP storage (ros2 bag, Foxglove and "
                        "rosbags open it; --camera replay:FILE.mcap replays it)")
    g.add_argument("--record-compression", choices=("zstd", "lz4", "none"), default="zstd",
                   help="--record: how the file's chunks are compressed")


def check_record(args: argparse.Namespace) -> None:
    """Refuse a --record that cannot be written, or that would replace a file, before any
    work; and a missing record extra."""
    if getattr(args, "record", None) is None:
        return
    check_output(args.record, "mcap", "--record")
    if args.record.exists():
        raise HostError(f"--record {args.record}: exists already (a recording is never "
                        f"overwritten: name another file)")
    try:
        import mcap  # noqa: F401
        import rosbags  # noqa: F401
    except ImportError as e:
        raise HostError(f"--record needs pip install 'stereo-servo[record]' ({e.name} is "
                        f"missing)") from None


@contextlib.contextmanager
def recording(args: argparse.Namespace, clock: Callable[[], float]) -> Iterator[Any]:
    """The Recorder of args.record (None without --record); closed, and its one-line summary
    printed, at the end whatever happens."""
    if getattr(args, "record", None) is None:
        yield None
        return
    from host.record.writer import QUEUE_ITEMS, Recorder

    rec = Recorder(args.record, clock, args.record_compression,
                   getattr(args, "record_queue", QUEUE_ITEMS))  # tests: room for every item
    try:
        yield rec
    finally:
        rec.close()
        print(f"record: {rec.summary()}", file=sys.stderr)


@contextlib.contextmanager
def record_servo(args: argparse.Namespace, servo: Any, clock: Callable[[], float]
                 ) -> Iterator[Any]:
    """--record for a servo run: its pairs (the source tapped) and its steps (an observer)."""
    with recording(args, clock) as rec:
        if rec is not None:
            from host.record.tap import RecordingSource, StepRecorder, servo_range

            tap = RecordingSource(servo.source, rec, servo.geometry)
            servo.source = tap
            servo.observers.append(StepRecorder(rec, tap, servo_range(servo), servo.link))
        yield rec
