"""host bag: what a recording (--record FILE.mcap) holds, without ROS; --repair makes a closed
copy of one that a killed run cut off."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from host.errors import HostError
from host.files import check_output

EXAMPLES = ["host bag run.mcap                     # topics, types, counts, duration",
            "host bag killed.mcap --repair fixed.mcap"]


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", type=Path, metavar="FILE.mcap", help="a recording (--record)")
    p.add_argument("--repair", type=Path, metavar="OUT.mcap",
                   help="write the file's complete messages to OUT.mcap, closed with a summary "
                        "(for readers that need one, such as rosbags)")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    try:
        from host.record.inspect import repair, scan
    except ImportError as e:
        raise HostError(f"host bag needs pip install 'stereo-servo[record]' ({e.name} is "
                        f"missing)") from None
    if args.repair is not None:
        check_output(args.repair, "mcap", "--repair")
        if args.repair.exists():
            raise HostError(f"--repair {args.repair}: exists already (name another file)")
        info = repair(args.file, args.repair)
    else:
        info = scan(args.file)
    seconds = (info.last_ns - info.first_ns) / 1e9 if info.first_ns is not None else 0.0
    width = max((len(t) for t in info.topics), default=0)
    for topic, msgtype in info.topics.items():
        print(f"{topic:<{width}}  {info.counts[topic]:7d}  {msgtype}")
    state = "closed" if info.closed else "cut off (not closed: a killed run?)"
    print(f"{sum(info.counts.values())} messages over {seconds:.2f} s; the file is {state}"
          + (f"; recorder: {info.recorder}" if info.recorder else ""))
    if args.repair is not None:
        print(f"wrote {args.repair}: every complete message, closed", file=sys.stderr)
    return 0
